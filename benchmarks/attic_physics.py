"""Which roof physics an unheated attic needs: candidate inputs on the tuning attics.

Each TRH-1 attic through ``hbayes init`` (as ``real_rooms.py`` does), then the MAP of
``thermal_1c`` (the model the screen keeps on these attics) and its validation FIT of
Ti [%], with the FMI weather as published and without its radiation columns, for each
variant of the roof planes' irradiance input:

- ``none``: the irradiance as transposed, without the wind weight (init's config with
  ``weather.columns.wind`` removed);
- ``wind``: the package's default for a weather with wind: each slope's irradiance
  times :func:`heritage_bayes.climate.solair.roof_wind_weight`; ``wind_u0``,
  ``wind_u12``: the same with the cover's inner conductance 0 and 12 W/(m² K);
- ``sky``, ``snow``: on top of the wind weight (does either add to it?);
- ``sky``: long-wave loss to the sky subtracted from each slope's irradiance,
  :math:`I - F_{sky} \\Delta R`, :math:`\\Delta R = \\sigma (1 - \\varepsilon_{sky})
  T_e^4` with the clear sky's emissivity from the dew point (Berdahl and Martin 1984),
  raised by the cloud fraction 1 - the day's clearness (Crawford and Duchon 1999);
  ε/α = 1 (the long-wave loss through the solar aperture);
- ``snow``: each slope's irradiance times 1 - 2/3 c, c the snow cover from a
  degree-day snowpack on FMI's precipitation (snow below +1 °C, melt 3 mm/(K d), a
  roof covered from 5 mm water equivalent; snow absorbs a third of what the roof does).

- ``horizon<N>``: the roof's skyline ``data.roof.horizon`` set to N° (the package's
  default 20°; ``horizon0``: none, the package before it).
- ``ridge<deg>``, ``pitch<deg>``: the roof's answers to init's CHECK written into its
  config (``data.roof.ridge_azimuth``, ``pitch``), alone or joined to another variant by
  ``+`` (``ridge45+pitch30``);
- ``snow0``: as ``snow`` but no sun through a covered roof (the absorbed sun melts the
  snow), and a record starting in frost (first week's mean Te below 0 °C) starts under
  20 mm of snow water;
- ``nosnow``: init's config without ``weather.columns.precip``: the roof planes
  without the package's snow (:mod:`heritage_bayes.climate.snow`; ``wind`` is the
  package's default, with it);
- ``snowsun``, ``snowswing``, ``snowcap``, ``snowyear``: the package's snowpack and
  cover c, one part of its roof term at a time: the sun blocked only, (1 - c) I; the
  daily swing only, I + c (h_e/α)(T_b - T_e); both with T_b capped at 0 °C (a melting
  base); the swing term all year (c = 1, the sun kept: is it the snow?);
- ``melt<a>``: the package's snow with the degree-day factor a [mm/(K d)];
- ``phi<cap>``: the AR(1) model error's coefficient ``phi_Ti`` uniform on [0, cap]
  (default cap 0.96 at hourly steps): a likelihood that leaves less of the slow misfit
  to the error;
- ``phifix<v>``: ``phi_Ti`` fixed at v (``phifix0``: a model error without memory,
  the MAP an output-error fit of the free run); ``noise<name>``: the thermal section's
  ``noise:`` set to a registered noise model (``noiseiid``: independent errors,
  ``noisear1``: AR(1) without the sensor's white part);
- ``lag<h>``: the roof planes' columns (as the package builds them: shaded, weighted
  by the wind, under the snow) through a first-order store of time constant ``h`` [h]
  (a roof deck whose capacity delays the sun's heat on its way to the attic air);
- ``snowbase<h>``: the package's snow with the snow base at the air's trailing mean
  over ``h`` hours (24 in the package: a deeper pack's longer memory), not drawn
  towards 0 °C; ``snowwarm<w>``: the base ``w`` of the way from the air's 24-hour mean
  to 0 °C (the package's ``BASE_WARMTH``; 0: the package before it, a melting base
  over a warm attic: 1);
- ``lw``: the long-wave loss to the sky as ``sky``, but the night's cloud from the
  clearness of the two days around it (each day's at its solar noon, interpolated in
  time), subtracted before the wind's weight and the snow (the loss leaves the cover
  as its absorbed sun does; no loss reaches the attic through a snow cover);
  ``lwc``: the same loss less its mean over the record (its variation only);
  ``lwd``, ``lwdc``: ``lw``, ``lwc`` with the cover no colder than the dew point (the
  latent heat of the vapour condensing on it): the loss at most
  :math:`h_e (T_e - T_d)/\\alpha`;
- ``lwo``, ``lwdo``: the package's roof columns unchanged, and beside them the loss of
  ``lw``, ``lwd`` (as it reaches the attic: the wind's weight, none through the snow)
  as its own column ``L_<plane>``, for the models ``sky`` and ``sky_below20`` (other
  models ignore it); ``lwdon``: ``lwdo`` at night only (the cloudless sky's global
  irradiance 0);
- ``from<date>``: the calibration starts at the date (e.g. ``from2011-04-20``: after the
  snow), its end and the validation as init chose them.

Candidate models (``--models``; none of them is in the package, see
``docs/science/real_rooms.md``, "The sun on the roof and the house below"), registered
here for the run:

- ``thermal_1c``: the catalogue's (the default); ``thermal_2c``, ``thermal_4a``: the
  catalogue's (``thermal_4a`` splits the sun between the air and its interior mass by
  ``fsol``);
- ``deck``: a light roof deck ``Tr`` (capacity ``Cr``, prior log-uniform 1e4-1e7 J/K:
  tiles, battens and underlay) between the sun on the slopes and the attic air ``Ti``:
  ``Gr`` deck - outdoor air, ``Gri`` deck - attic air, ``Gfast`` attic air - outdoor
  air, ``Gf`` to ``Tf``; the slopes' apertures heat the deck;
- ``deck_heavy``: ``deck`` with a heavy node ``Tint`` (``Cint``, ``Gint``) on the air
  (the ceiling's insulation and joists);
- ``air_mass``: ``thermal_1c`` with a heavy node ``Tint`` (``Cint``, ``Gint``) hanging
  on the air (timber, the insulation's top), the sun and the outdoor air on the air:
  a fast response and a slow one;
- ``deck_split``: ``deck`` with the slopes' sun split: ``fsol`` [-] heats the deck, the
  rest the attic air (nests ``thermal_1c`` and ``deck``);
- ``below20``: ``thermal_1c`` plus a conductance ``Gb`` to a heated room below at a
  constant 20 °C (fixed), beside the ground ``Tf``;
- ``below_measured``: the same with the room below's measured temperature
  (``indoor1.csv``) instead of 20 °C, beside the ground (it enters through the
  weather's one free column, ``Ph``, as a temperature);
- ``sky``: ``thermal_1c`` with the sky's long-wave loss (the ``L_<plane>`` columns of
  ``lwo``, ``lwdo``, ``lwdon``) through each slope's solar aperture times a fraction
  ``r_lw`` [-], uniform on [0, 1]: the cover's ratio ε/α = 1.5 ``r_lw`` in [0, 1.5]
  estimated (``lw``, ``lwd`` are ε/α = 1 fixed);
- ``sky_below20``: ``sky`` plus ``below20``'s conductance ``Gb`` to 20 °C (the heat
  that balances the loss's mean); ``sky_below``: the same with the room's constant
  temperature ``Tb`` estimated, uniform on [10, 30] °C;
- ``ground_measured``: ``thermal_1c`` with ``Tf`` = the room below's measured
  temperature, replacing the ground (init's written advice for a room without a floor
  on the ground).
- ``air_feed``: a measured air node on a roof store (Bacher and Madsen 2011: a sensor
  or air node beside a medium node): ``thermal_2c``'s network with the slopes' sun on
  the store ``Tw`` (``Cw``; ``Gw`` to ``Te``, ``Gi`` to the air) and the air ``Ti``
  near massless (``Ci`` fixed at :data:`AIR_MASSLESS`; ``Gfast`` to ``Te``, ``Gf`` to
  ``Tf``): ``Ti = (Gfast Te + Gi Tw + Gf Tf)/(Gfast + Gi + Gf)``, an instantaneous share
  of the outdoor air (the first-order hold makes it exact at the stamps) beside a sun
  lagged by the store; ``air_feed_light``: ``Ci`` fixed at the prior's floor
  :data:`AIR_FLOOR` (its time constant then follows the conductances' scale);
  ``air_feed_free``: ``Ci`` under the default prior (``thermal_2c`` with the sun on
  ``Tw``); ``air_feed_split``: ``air_feed`` with ``fsol`` of the sun on the store, the
  rest on the air (nests ``thermal_1c``'s sun on the air).

The three roof-input candidates are not in the package (only the wind weight paid, see
``docs/science/real_rooms.md``, "The wind on the roof"); they are written here as
changes of the irradiance table before alignment. ``--hours``: the MAP's residual
(measured - simulated Ti) by season and hour of day, calibration and validation, and
the correlation of its daily mean with FMI's daily mean wind speed; ``--theta``: the
MAP's parameters and log posterior (``--hours`` prints them too).

Usage (from the repository root)::

    python benchmarks/attic_physics.py [ROOM ...] [--variants none wind sky snow horizon0]
        [--models thermal_1c deck below20 ...] [--hours] [--measured]
    python benchmarks/attic_physics.py R2 R4 R6 --variants ridge0 ridge45 snow0 phi0.8 \
        from2011-04-20 --measured

ROOM: R2 R4 R6 (the tuning attics, the default); the held-out ones are refused.
"""

from __future__ import annotations

import argparse
import functools
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from _common import config_map  # noqa: E402
from real_rooms import ROOMS, run_init  # noqa: E402

TUNING = ["R2", "R4", "R6"]
SEED = None  # the MAP's seed when not init's (--seed)
BUDGET = {"maxiter": 100, "starts": 2}  # the MAP's generations and starts (--maxiter, --starts)
THETA = False  # print the MAP's parameters (--theta; --hours prints them too)
CAL_FITS: list[float] = []  # the calibration FIT [%] of each run, in order
SIGMA = 5.670374419e-8  # Stefan-Boltzmann [W/(m² K⁴)]
AIR_FLOOR = 1e4  # [J/K]: the thermal capacity prior's floor, a few m³ of air
#: [J/K] the air node of ``air_feed``: quasi-steady, its time constant under 100 s at
#: any conductances the prior allows (each ≥ 0.01 W/K), under 1 s above 1 W/K
AIR_MASSLESS = 1.0
DECK_PRIOR = {"Cr": {"dist": "loguniform", "lower": 1e4, "upper": 1e7}}  # [J/K]
#: candidate -> catalogue name, options, priors (see the module docstring)
MODELS = {
    "thermal_1c": ("thermal_1c", {}, {}),
    "thermal_2c": ("thermal_2c", {}, {}),
    "thermal_4a": ("thermal_4a", {}, {}),
    "deck": ("x_deck", {}, DECK_PRIOR),
    "deck_heavy": ("x_deck_heavy", {}, DECK_PRIOR),
    "deck_split": ("x_deck_split", {}, DECK_PRIOR),
    "air_mass": ("x_air_mass", {}, {}),
    "below20": ("x_below_constant", {}, {"Tb": {"fixed": 20.0}}),
    "below_measured": ("x_below_column", {}, {}),
    "ground_measured": ("thermal_1c", {}, {}),
    "air_feed": ("x_air_feed", {}, {"Ci": {"fixed": AIR_MASSLESS}}),
    "air_feed_light": ("x_air_feed", {}, {"Ci": {"fixed": AIR_FLOOR}}),
    "air_feed_free": ("x_air_feed", {}, {}),
    "air_feed_split": ("x_air_feed_split", {}, {"Ci": {"fixed": AIR_MASSLESS}}),
    "sky": ("x_sky", {}, {"r_lw": {"dist": "uniform", "lower": 0.0, "upper": 1.0}}),
    "sky_below20": (
        "x_sky_below",
        {},
        {"r_lw": {"dist": "uniform", "lower": 0.0, "upper": 1.0}, "Tb": {"fixed": 20.0}},
    ),
    "sky_below": (
        "x_sky_below",
        {},
        {
            "r_lw": {"dist": "uniform", "lower": 0.0, "upper": 1.0},
            "Tb": {"dist": "uniform", "lower": 10.0, "upper": 30.0},
        },
    ),
}
#: ε/α of the roof's long-wave aperture at ``r_lw`` = 1: the ``L_<plane>`` columns are
#: this times the loss (``r_lw`` a fraction in [0, 1], so ε/α in [0, 1.5])
LW_CAP = 1.5


def _candidate(
    name, surfaces=None, ground=True, deck=True, heavy=False, below=None, split=False, sky=False
):
    """The candidates' networks: [°C], [J/K], [W/K], apertures [m²]."""
    from heritage_bayes.rc.network import Link, Network, Node, Source

    nodes = [Node("Tr", "Cr")] * deck + [Node("Ti", "Ci")] + [Node("Tint", "Cint")] * heavy
    links = [Link("Tr", "Te", "Gr"), Link("Tr", "Ti", "Gri")] * deck
    links += [Link("Ti", "Te", "Gfast" if deck else "Ge")] + [Link("Ti", "Tint", "Gint")] * heavy
    links += [Link("Ti", "Tf", "Gf")] * bool(ground)
    inputs = ["Te", *(f"I_{s}" for s in surfaces or ()), *["Tf"] * bool(ground)]
    if below:  # the room below: a fixed constant Tb or the measured column (as Ph)
        links.append(Link("Ti", "Tb" if below == "constant" else "Ph", "Gb"))
        inputs += ["Ph"] * (below == "column")
    sources = [Source(f"I_{s}", "Tr" if deck else "Ti", f"fI_{s}", "fsol" if split else None)
               for s in surfaces or ()]  # fmt: skip
    sources += [Source(f"I_{s}", "Ti", f"fI_{s}", "1-fsol") for s in surfaces or ()] * split
    # the sky's long-wave loss through each slope's aperture times r_lw (ε/α = LW_CAP r_lw)
    roofs = [s for s in surfaces or () if s.startswith("roof")] if sky else []
    sources += [Source(f"L_{s}", "Ti", f"fI_{s}", "r_lw") for s in roofs]
    inputs += [f"L_{s}" for s in roofs]
    return Network(name=name, domain="thermal", nodes=tuple(nodes), links=tuple(links),
                   inputs=tuple(inputs), outputs=("Ti",), sources=tuple(sources),
                   constants=("Tb",) * (below == "constant"))  # fmt: skip


def _air_feed(name, surfaces=None, ground=True, split=False):
    """A measured air node on a roof store: ``thermal_2c``'s network (``Tw``: ``Cw``,
    ``Gw`` to ``Te``, ``Gi`` to the air; the air ``Ti``: ``Ci``, ``Gfast`` to ``Te``,
    ``Gf`` to ``Tf``) with the slopes' sun on the store ``Tw`` (``split``: ``fsol`` on
    the store, ``1 - fsol`` on the air). With ``Ci`` at :data:`AIR_MASSLESS` the air is
    quasi-steady, ``Ti = (Gfast Te + Gi Tw + Gf Tf)/(Gfast + Gi + Gf)``: an instantaneous
    share of the outdoor air beside a lagged sun (Bacher and Madsen 2011)."""
    from heritage_bayes.rc.network import Link, Network, Node, Source

    links = [Link("Tw", "Te", "Gw"), Link("Tw", "Ti", "Gi"), Link("Ti", "Te", "Gfast")]
    links += [Link("Ti", "Tf", "Gf")] * bool(ground)
    surfaces = tuple(surfaces or ())
    sources = [Source(f"I_{s}", "Tw", f"fI_{s}", "fsol" if split else None) for s in surfaces]
    sources += [Source(f"I_{s}", "Ti", f"fI_{s}", "1-fsol") for s in surfaces] * split
    inputs = ("Te", *(f"I_{s}" for s in surfaces), *["Tf"] * bool(ground))
    nodes = (Node("Tw", "Cw"), Node("Ti", "Ci"))
    return Network(name=name, domain="thermal", nodes=nodes, links=tuple(links),
                   inputs=inputs, outputs=("Ti",), sources=tuple(sources))  # fmt: skip


def _register() -> None:
    from heritage_bayes.rc.catalog import CATALOG, CatalogModel, register

    for name, fixed in (("x_deck", {}), ("x_deck_heavy", {"heavy": True}),
                        ("x_deck_split", {"split": True}),
                        ("x_air_mass", {"deck": False, "heavy": True}),
                        ("x_below_constant", {"deck": False, "below": "constant"}),
                        ("x_below_column", {"deck": False, "below": "column"}),
                        ("x_sky", {"deck": False, "sky": True}),
                        ("x_sky_below", {"deck": False, "below": "constant",
                                         "sky": True})):  # fmt: skip
        if name in CATALOG:
            continue

        def build(surfaces=None, ground=True, heating=False, _n=name, _f=fixed):
            return _candidate(_n, surfaces, ground, **_f)

        register(name, CatalogModel(build, "a candidate of attic_physics.py", "thermal", True))
    for name, split in (("x_air_feed", False), ("x_air_feed_split", True)):
        if name not in CATALOG:

            def build(surfaces=None, ground=True, heating=False, _n=name, _s=split):
                return _air_feed(_n, surfaces, ground, _s)

            register(name, CatalogModel(build, "a candidate of attic_physics.py", "thermal", True))


def _fmi(room: str, data: Path) -> pd.DataFrame:
    raw = pd.read_csv(data / ROOMS[room][1], parse_dates=[0], index_col=0)
    raw.index = raw.index.tz_localize("UTC+02:00").tz_convert("UTC")
    return raw


def _sky_loss(irr, weather, site, surfaces, table):
    """Each slope's irradiance less its long-wave loss to the sky [W/m²]."""
    from heritage_bayes.climate.psychro import dew_point
    from heritage_bayes.climate.solar import clear_sky_weather

    idx = irr.index
    te = weather["Te"].reindex(idx).interpolate(limit_direction="both").to_numpy(float)
    rhe = weather["RHe"].reindex(idx).interpolate(limit_direction="both").to_numpy(float)
    tdp = dew_point(te, rhe) / 100.0
    eps_clear = 0.711 + 0.56 * tdp + 0.73 * tdp**2
    cs = clear_sky_weather(idx, site, interval=irr.attrs.get("interval"))["ghi"].to_numpy()
    day = (idx + pd.Timedelta(hours=site["longitude"] / 15.0)).floor("D")
    g = pd.DataFrame({"g": table["ghi"].reindex(idx).to_numpy(float), "c": cs}, index=day)
    sums = g.groupby(level=0).sum()
    ok = sums["c"] > 150.0  # W/m² summed over the day's hours: enough sun to judge
    clear = (sums["g"] / sums["c"]).clip(0, 1).where(ok).interpolate(limit_direction="both")
    cloud = 1.0 - clear.reindex(day).to_numpy()
    eps = cloud + (1.0 - cloud) * eps_clear
    loss = SIGMA * (1.0 - eps) * (te + 273.15) ** 4
    out = irr.copy()
    for name, (tilt, _) in surfaces.items():
        out[name] = irr[name] - (1 + np.cos(np.radians(tilt))) / 2 * loss
    return out


def _clearness(idx, site, table) -> np.ndarray:
    """Each step's clearness [-]: the solar day's global radiation over a cloudless
    sky's (days whose cloudless sky sums under 150 W/m² over their steps left out),
    placed at solar noon and interpolated in time (a night: between its two days)."""
    from heritage_bayes.climate.solar import clear_sky_weather

    cs = clear_sky_weather(idx, site, interval=table.attrs.get("interval"))["ghi"].to_numpy()
    shift = pd.Timedelta(hours=site["longitude"] / 15.0)
    day = (idx + shift).floor("D")
    g = pd.DataFrame({"g": table["ghi"].reindex(idx).to_numpy(float), "c": cs}, index=day)
    sums = g.groupby(level=0).sum()
    k = (sums["g"] / sums["c"]).clip(0, 1).where(sums["c"] > 150.0).dropna()
    k.index = k.index + pd.Timedelta(hours=12) - shift
    on = k.reindex(k.index.union(idx)).interpolate("time", limit_direction="both")
    return on.reindex(idx).to_numpy(float)


def _long_wave(out, weather, site, planes, surfaces, table, centred=False, dew=False):
    """The roof planes' columns less their long-wave loss to the sky, in the sun's
    units (ε/α = 1): :math:`F_{sky}\\,\\sigma(1 - \\varepsilon_{sky})T_e^4`, the sky's
    emissivity the clear sky's from the dew point (Berdahl and Martin 1984) raised by
    the cloud fraction 1 - clearness (Crawford and Duchon 1999); ``centred``: less its
    mean over the record (the loss's variation only); ``dew``: at most
    :math:`h_e (T_e - T_d)/\\alpha` (the cover no colder than the dew point)."""
    from heritage_bayes.climate.psychro import dew_point
    from heritage_bayes.climate.snow import ROOF_ABSORPTANCE
    from heritage_bayes.climate.solair import REFERENCE_WIND, exterior_surface_coefficient

    idx = out.index
    te = weather["Te"].reindex(idx).interpolate(limit_direction="both").to_numpy(float)
    rhe = weather["RHe"].reindex(idx).interpolate(limit_direction="both").to_numpy(float)
    td = dew_point(te, rhe)
    clear = _clearness(idx, site, table)
    eps = (1.0 - clear) + clear * (0.711 + 0.56 * td / 100 + 0.73 * (td / 100) ** 2)
    loss = SIGMA * (1.0 - eps) * (te + 273.15) ** 4
    # dew: the cover no lower than the dew point (condensing vapour's latent heat)
    cap = exterior_surface_coefficient(REFERENCE_WIND) / ROOF_ABSORPTANCE * np.maximum(te - td, 0)
    res = out.copy()
    for k in planes:
        lw = (1 + np.cos(np.radians(surfaces[k][0]))) / 2 * loss
        lw = np.minimum(lw, cap) if dew else lw
        res[f"I_{k}"] = out[f"I_{k}"] - (lw - np.nanmean(lw) if centred else lw)
    res.attrs = dict(out.attrs)
    return res


def _lw_variant(orig, weather, site, surfaces, mode, where, roof, kw, variant):
    """The package's roof columns with the long-wave loss subtracted before the wind's
    weight and the snow (the loss leaves the cover as its absorbed sun does)."""
    from heritage_bayes import inputs
    from heritage_bayes.climate import snow

    bare = weather.drop(columns=[c for c in ("wind", "precip") if c in weather])
    out, label, detail = orig(bare, site, surfaces, mode, where=where, roof=roof, **kw)
    table = weather if "ghi" in weather else _estimated(weather, site)
    out = _long_wave(out, weather, dict(site), roof, surfaces, table, variant.endswith("c"),
                     variant.startswith("lwd"))  # fmt: skip
    planes = [f"I_{k}" for k in roof]
    if "wind" in weather:
        out = inputs._wind_weighted(out, weather["wind"], planes, where)
    if "precip" in weather:
        out = snow.roof_snow_columns(out, weather["Te"], weather["precip"], planes)[0]
    return out, label, detail


def _lw_own(orig, weather, site, surfaces, mode, where, roof, kw, variant):
    """The package's roof columns and beside them each slope's long-wave loss to the sky
    as it reaches the attic (``_lw_variant``'s change: the wind's weight, none through
    the snow), times -:data:`LW_CAP`, as its own column ``L_<plane>`` [W/m²] for the
    candidates ``sky`` and ``sky_below20``; a variant ending in ``n``: at night only
    (the cloudless sky's global irradiance 0)."""
    from heritage_bayes.climate.solar import clear_sky_weather

    out, label, detail = orig(weather, site, surfaces, mode, where=where, roof=roof, **kw)
    base = "lwd" if variant.startswith("lwd") else "lw"
    lw = _lw_variant(orig, weather, site, surfaces, mode, where, roof, kw, base)[0]
    night = np.ones(len(out))
    if variant.endswith("n"):
        cs = clear_sky_weather(out.index, dict(site), interval=weather.attrs.get("interval"))
        night = (cs["ghi"].to_numpy() <= 0.0).astype(float)
    attrs = dict(out.attrs)
    for k in roof:
        out[f"L_{k}"] = LW_CAP * night * (lw[f"I_{k}"] - out[f"I_{k}"]).to_numpy(float)
    attrs["units"] = {**attrs.get("units", {}), **{f"L_{k}": "W/m²" for k in roof}}
    # held in time as its plane's column is (nested: lwd is r_lw = 1/LW_CAP exactly)
    averaged = tuple(attrs.get("averaged", ()))
    attrs["averaged"] = averaged + tuple(f"L_{k}" for k in roof if f"I_{k}" in averaged)
    out.attrs = attrs
    return out, label, detail


def _snow_factor(raw: pd.DataFrame, index, keep: float = 1 / 3, start: bool = False):
    """1 - (1 - keep) of the roof's snow cover [-] from a degree-day snowpack; ``start``:
    a record starting in frost (its first week's mean Te below 0 °C) starts under 20 mm
    of snow water (a winter's snow already on the roof)."""
    te, p = raw["Te"].to_numpy(float), np.nan_to_num(raw["precip"].to_numpy(float))
    swe = 20.0 if start and np.nanmean(te[:168]) < 0.0 else 0.0
    cover = np.empty(len(te))
    for k in range(len(te)):
        t = te[k] if np.isfinite(te[k]) else 0.0
        swe = max(0.0, swe + (p[k] if t < 1.0 else 0.0) - 3.0 / 24.0 * max(t, 0.0))
        cover[k] = min(1.0, swe / 5.0)
    c = pd.Series(cover, index=raw.index).reindex(index).ffill().fillna(0.0).to_numpy()
    return 1.0 - (1.0 - keep) * c


def _snow_variant(out: pd.DataFrame, weather: pd.DataFrame, roof, variant: str):
    """The roof columns ``I_<plane>`` of the snow-free ``out`` under the variant's snow
    (:mod:`heritage_bayes.climate.snow`; see the module docstring)."""
    from heritage_bayes.climate import snow

    cols = [f"I_{k}" for k in roof]
    if variant.startswith("melt"):  # the package's snow at another degree-day factor
        keep, snow.MELT_FACTOR = snow.MELT_FACTOR, float(variant[4:])
        try:
            return snow.roof_snow_columns(out, weather["Te"], weather["precip"], cols)[0]
        finally:
            snow.MELT_FACTOR = keep
    te = weather["Te"]
    c = snow.snow_cover(snow.snowpack(te.to_numpy(float), weather["precip"].to_numpy(float), 1.0))
    base = te.rolling("24h", min_periods=1).mean()
    if variant == "snowcap":
        base = base.clip(upper=0.0)
    on = pd.DataFrame({"c": c, "te": te, "tb": base}).reindex(out.index, method="nearest")
    c, te, tb = (on[k].to_numpy() for k in ("c", "te", "tb"))
    res = out.copy()
    for k in cols:
        i = out[k].to_numpy(float)
        res[k] = {
            "snowsun": (1 - c) * i,
            "snowswing": snow.roof_under_snow(i, te, tb, c) + c * i,
            "snowcap": snow.roof_under_snow(i, te, tb, c),
            "snowyear": snow.roof_under_snow(i, te, tb, np.ones_like(c)) + i,
        }[variant]
    res.attrs = dict(out.attrs)
    return res


SNOW_VARIANTS = ("snowsun", "snowswing", "snowcap", "snowyear")


def patched(variant: str, raw: pd.DataFrame):
    """The package's ``solar_inputs`` with the variant's change of the irradiance."""
    import heritage_bayes.inputs as inputs
    from heritage_bayes.climate import solair

    orig = inputs.solar_inputs

    def solar_inputs(weather, site, surfaces, mode, *, where="data.weather", roof=(), **kw):
        if variant.startswith("wind_u"):
            u = float(variant[6:])
            w = solair.roof_wind_weight(
                weather["wind"].interpolate(limit_direction="both").to_numpy(), u
            )
            out, label, detail = orig(weather.drop(columns="wind"), site, surfaces, mode,
                                      where=where, roof=roof, **kw)  # fmt: skip
            for k in roof:
                out[f"I_{k}"] = out[f"I_{k}"].to_numpy() * w
            return out, label, detail
        if variant in ("lwo", "lwdo", "lwdon"):  # the loss as its own column
            return _lw_own(orig, weather, site, surfaces, mode, where, roof, kw, variant)
        if variant in ("lw", "lwc", "lwd", "lwdc"):
            return _lw_variant(orig, weather, site, surfaces, mode, where, roof, kw, variant)
        if variant in SNOW_VARIANTS or variant.startswith("melt"):
            out, label, detail = orig(weather.drop(columns="precip"), site, surfaces, mode,
                                      where=where, roof=roof, **kw)  # fmt: skip
            return _snow_variant(out, weather, roof, variant), label, detail
        out, label, detail = orig(weather, site, surfaces, mode, where=where, roof=roof, **kw)
        if variant.startswith("lag"):  # the roof's columns through a store of tau [h]
            out = _lagged(out, [f"I_{k}" for k in roof], float(variant[3:]))
        elif variant == "sky":
            table = weather if "ghi" in weather else _estimated(weather, site)
            cols = {f"I_{k}": v for k, v in surfaces.items()}
            out = _sky_loss(out, weather, dict(site), cols, table)
        elif variant == "snow":
            out = out.mul(_snow_factor(raw, out.index), axis=0)
        elif variant == "snow0":  # no sun through a snow-covered roof, snow from the start
            out = out.mul(_snow_factor(raw, out.index, keep=0.0, start=True), axis=0)
        return out, label, detail

    if variant.startswith("snowbase"):  # the snow base: the air's mean over N hours
        return _snow_base(int(variant[8:]))
    if variant.startswith("snowwarm"):  # the snow base w of the way to 0 °C
        return _snow_base(24, float(variant[8:]))
    inputs.solar_inputs = solar_inputs
    return functools.partial(setattr, inputs, "solar_inputs", orig)


def _snow_base(window_hours: int, warm: float = 0.0):
    """The package's snow with the base at ``1 - warm`` times the air's trailing mean
    over ``window_hours`` (:func:`heritage_bayes.climate.snow.roof_snow_columns`, its
    only rolling mean; 24 h and :data:`~heritage_bayes.climate.snow.BASE_WARMTH` in the
    package): ``warm`` of the way to a melting base at 0 °C; returns the undo."""
    from heritage_bayes.climate import snow

    orig, keep = pd.Series.rolling, snow.BASE_WARMTH

    def rolling(self, window, *a, **kw):
        return orig(self, f"{window_hours}h" if window == "24h" else window, *a, **kw)

    def undo():
        pd.Series.rolling, snow.BASE_WARMTH = orig, keep

    pd.Series.rolling, snow.BASE_WARMTH = rolling, warm
    return undo


def _lagged(out: pd.DataFrame, cols, tau_hours: float) -> pd.DataFrame:
    """``out`` with ``cols`` through a first-order store of time constant ``tau_hours``
    (unit steady gain, exact for a piecewise-constant input at the table's step)."""
    from scipy.signal import lfilter

    step = out.index.to_series().diff().median() / pd.Timedelta(hours=1)
    a = np.exp(-step / tau_hours)
    res = out.copy()
    for k in cols:
        x = res[k].interpolate(limit_direction="both").to_numpy(float)
        res[k] = lfilter([1 - a], [1, -a], x, zi=[a * x[0]])[0]
    res.attrs = dict(out.attrs)
    return res


def _estimated(weather, site):
    from heritage_bayes.climate.solar import temperature_range_weather

    return temperature_range_weather(weather["Te"], dict(site))


def _weather(room, data, w, bare, below) -> Path | None:
    """The FMI file as published, or a copy without its radiation and/or with the room
    below's measured temperature as column ``Tb`` (mapped to ``Ph`` after init)."""
    if not bare and not below:
        return None
    fmi = pd.read_csv(data / ROOMS[room][1])
    if bare:
        fmi = fmi.drop(columns=["Rglob", "Rdif"])
    if below:
        house = pd.read_csv(data / Path(ROOMS[room][0]).parent / "indoor1.csv")
        fmi = fmi.merge(house[["t_UTC+2", "T"]].rename(columns={"T": "Tb"}), "left", "t_UTC+2")
    fmi.to_csv(w / "wx" / "fmi.csv", index=False)
    return w / "wx" / "fmi.csv"


def _roof_answers(variant: str) -> tuple[dict, str]:
    """The roof's answers in a variant (``ridge<deg>``, ``pitch<deg>``, joined to another
    variant by ``+``: ``ridge0+pitch30``, what a user answering init's roof CHECK
    writes) as ``data.roof`` keys, and the variant left (``wind``: the default)."""
    keys = {"ridge": "ridge_azimuth", "pitch": "pitch"}
    parts = variant.split("+")
    edits = {keys[k]: float(p[len(k) :]) for p in parts for k in keys if p.startswith(k)}
    rest = [p for p in parts if not any(p.startswith(k) for k in keys)]
    return edits, "+".join(rest) or "wind"


def _aperture_cap(variant: str) -> tuple[float | None, str]:
    """The roof apertures' prior cap [m²] of a variant joined by ``+cap<N>`` (the
    package's: 200), and the variant left."""
    parts = variant.split("+")
    caps = [float(p[3:]) for p in parts if p.startswith("cap")]
    rest = "+".join(p for p in parts if not p.startswith("cap")) or "wind"
    return (caps[0] if caps else None), rest


def _roof_edit(config: Path, variant: str) -> tuple[Path, str]:
    """init's config with the variant's roof answers written in, and the variant left."""
    import yaml

    edits, rest = _roof_answers(variant)
    if not edits:
        return config, rest
    raw = yaml.safe_load(config.read_text(encoding="utf-8"))
    raw["data"]["roof"].update(edits)
    out = config.with_name("config_roof.yaml")
    out.write_text(yaml.safe_dump(raw, sort_keys=False, allow_unicode=True), encoding="utf-8")
    return out, rest


def _config(room, variant, model, bare, data, w):
    """init's config for the variant and the candidate model (MAP at 100 generations,
    2 starts, thermal section only)."""
    from heritage_bayes.config import load_config
    from real_rooms import room_below

    config = run_init(room, data, w, _weather(room, data, w, bare, model == "below_measured"))[0]
    if model == "ground_measured":
        config = room_below(config, data / ROOMS[room][0])
    cap, variant = _aperture_cap(variant)
    config, variant = _roof_edit(config, variant)
    cfg = load_config(config)
    d = cfg.data
    if variant in ("none", "nosnow"):  # without the wind weight / the snow on the roof
        drop = {"none": "wind", "nosnow": "precip"}[variant]
        cols = {k: v for k, v in d.weather.columns.items() if k != drop}
        d = d.model_copy(update={"weather": d.weather.model_copy(update={"columns": cols})})
    if variant.startswith("horizon"):
        roof = d.roof.model_copy(update={"horizon": float(variant[7:])})
        d = d.model_copy(update={"roof": roof})
    if model == "below_measured":
        cols = {**d.weather.columns, "Ph": "Tb"}
        d = d.model_copy(update={"weather": d.weather.model_copy(update={"columns": cols})})
    from heritage_bayes.config.options import ModelOptions
    from heritage_bayes.config.priors import PriorSpec

    name, options, priors = MODELS[model]
    if cap is not None:
        roof = {
            f"fI_{k}": {"dist": "loguniform", "lower": 1e-3, "upper": cap} for k in d.roof.planes()
        }
        priors = {**priors, **roof}
    typed = {k: PriorSpec.model_validate(v) for k, v in priors.items()}
    th = cfg.thermal.model_copy(
        update={"model": name, "options": ModelOptions.model_validate(options), "priors": typed}
    )
    th = likelihood(th, variant)
    periods = cfg.periods
    if variant.startswith("from"):  # the calibration from a later date (e.g. after the snow)
        cal = periods.calibration.model_copy(update={"start": variant[4:]})
        periods = periods.model_copy(update={"calibration": cal})
    opt = cfg.optimizer.model_copy(update=BUDGET)
    seed = cfg.seed if SEED is None else SEED
    return cfg.model_copy(update={"data": d, "optimizer": opt, "thermal": th, "hygric": None,
                                  "seed": seed,
                                  "periods": periods})  # fmt: skip


def likelihood(th, variant: str):
    """The thermal section ``th`` under the variant's likelihood: ``phi<cap>``, the AR(1)
    model error's coefficient ``phi_Ti`` uniform on [0, cap]; ``phifix<v>``, fixed at v
    (0: the free-run error, white); ``noise<name>``, the section's ``noise:`` (``iid``,
    ``ar1``, ...; priors on noise parameters it lacks dropped). Other
    variants: ``th`` unchanged."""
    from heritage_bayes.config.priors import PriorSpec

    if variant.startswith("noise"):  # priors on noise parameters the model lacks dropped
        from heritage_bayes.names import NOISE_MODELS

        kinds = NOISE_MODELS[variant[5:]].kinds
        gone = [k for k in ("phi", "sigma_meas") if k not in kinds]
        priors = {k: v for k, v in th.priors.items() if k.rsplit("_", 1)[0] not in gone}
        return th.model_copy(update={"noise": variant[5:], "priors": priors})
    if variant.startswith("phifix"):  # the AR(1) error's coefficient held at a value
        spec = {"fixed": float(variant[6:])}
    elif variant.startswith("phi"):  # the AR(1) error's coefficient capped lower
        spec = {"dist": "uniform", "lower": 0.0, "upper": float(variant[3:])}
    else:
        return th
    return th.model_copy(update={"priors": {**th.priors, "phi_Ti": PriorSpec.model_validate(spec)}})


def simulated(room, variant, bare, data, work, model="thermal_1c"):
    """The variant's MAP: its config, prepared data, model, log-posterior, MAP, and
    the observed and simulated Ti [°C] on the prepared frame."""
    w = work / room / ("bare" if bare else "meas") / model / variant
    (w / "wx").mkdir(parents=True, exist_ok=True)
    cfg = _config(room, variant, model, bare, data, w)
    return (cfg, *thermal_map(cfg, room, data, _roof_answers(_aperture_cap(variant)[1])[1]))


def thermal_map(cfg, room, data, variant="wind"):
    """The thermal MAP of ``cfg`` with the variant's roof columns: prepared data, model,
    log-posterior, MAP, and the observed and simulated Ti [°C] on the prepared frame."""
    undo = patched(variant, _fmi(room, data))
    try:
        prep, m, lp, mp = config_map(cfg, "thermal")
    finally:
        undo()
    u = prep.model_inputs("thermal", m)
    y = lp.simulate_frame(mp.theta[None], u, prep.calibration.start)[0][0][:, 0]
    return prep, m, lp, mp, prep.observed("thermal", m)[:, 0], y


def run(room, variant, bare, data, work, hours, model="thermal_1c"):
    from heritage_bayes.inference.results import fit_metrics

    _, prep, m, lp, mp, obs, y = simulated(room, variant, bare, data, work, model)
    v, cal = prep.validation, prep.fitted_rows()
    fit = fit_metrics(obs[v], y[v])["FIT"]
    CAL_FITS.append(fit_metrics(obs[cal], y[cal])["FIT"])
    if hours or THETA:
        print(
            " ".join(f"{k}={x:.3g}" for k, x in zip(lp.params.names, mp.theta, strict=True)),
            f"log_post={mp.log_post:.1f} (starts agreed {mp.n_agreed}/{mp.n_starts})",
        )
    if hours:
        sl = slice(prep.calibration.start, v.stop)
        e = pd.Series(obs[sl] - y[sl], index=prep.frame.index[sl] + pd.Timedelta(hours=2))
        season = np.array(["DJF", "DJF", "MAM", "MAM", "MAM", "JJA", "JJA", "JJA", "SON",
                           "SON", "SON", "DJF"])[e.index.month - 1]  # fmt: skip
        print(e.groupby([season, e.index.hour]).mean().unstack(0).iloc[::6].round(2))
        ws = _fmi(room, data)["ws"].reindex(e.index - pd.Timedelta(hours=2))
        daily = pd.DataFrame({"e": e.to_numpy(), "ws": ws.to_numpy()}).groupby(
            np.asarray(e.index.floor("D"))
        )
        r = daily.mean().corr().loc["e", "ws"]
        print(f"correlation of the daily mean residual with the daily mean wind: {r:.2f}")
    return fit


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rooms", nargs="*", default=TUNING)
    ap.add_argument("--variants", nargs="+", default=["none", "wind", "sky", "snow"])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--models", nargs="+", default=["thermal_1c"], choices=list(MODELS))
    ap.add_argument("--hours", action="store_true", help="residual by season and hour")
    ap.add_argument("--measured", action="store_true", help="measured radiation only")
    ap.add_argument("--theta", action="store_true", help="print the MAP's parameters")
    ap.add_argument("--seed", type=int, default=None, help="the MAP's seed (init's: 1)")
    ap.add_argument("--maxiter", type=int, default=100, help="the MAP's generations")
    ap.add_argument("--starts", type=int, default=2, help="the MAP's starts")
    args = ap.parse_args(argv)
    global SEED, THETA
    SEED, THETA = args.seed, args.theta
    BUDGET.update(maxiter=args.maxiter, starts=args.starts)
    if set(args.rooms) - set(TUNING):
        ap.error(f"tuning attics only: {TUNING} (the others are held out)")
    work = Path(tempfile.mkdtemp(prefix="attic_physics_"))
    _register()
    print(f"validation FIT of Ti [%] (calibration FIT), MAP ({args.maxiter} generations, "
          f"{args.starts} starts)")  # fmt: skip
    print("| room | variant | model | measured radiation | estimated |")
    for room in args.rooms:
        for model in args.models:
            for variant in args.variants:
                modes = (0,) if args.measured else (0, 1)
                fits = [run(room, variant, b, args.data, work, args.hours, model) for b in modes]
                cal = CAL_FITS[-len(fits) :]
                cells = " | ".join(f"{f:.1f} (cal {c:.1f})" for f, c in zip(fits, cal, strict=True))
                cells += " | -" * args.measured
                print(f"| {room} | {variant} | {model} | {cells} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
