"""The attic benchmarks' checks on synthetic data: a known stamp shift, phase and gain
are found (benchmarks/attic_diagnostics.py), the roof's answers are parsed and the sky's
loss with its own weight nests the fixed one (benchmarks/attic_physics.py), a slow sun
path is found (benchmarks/attic_response.py), the sorbing buffer's path and uptake heat
(benchmarks/attic_sorption.py), the massless air node on a roof store is the quasi-steady
mix (benchmarks/attic_physics.py)."""

import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import attic_diagnostics as ad
import attic_physics as ap
import attic_sorption as aso

SITE = (60.21, 24.66)


@pytest.fixture(scope="module")
def sky():
    index = pd.date_range("2011-06-01", "2011-06-04", freq="1h", tz="UTC", inclusive="left")
    return index, ad.clear_sky_minutes(index, SITE)


@pytest.mark.parametrize(("convention", "shift"), [("mean of the hour ending", 30),
                                                   ("value at the stamp", 0)])  # fmt: skip
def test_best_shift_finds_the_stamp_convention(sky, convention, shift):
    """Hourly means of the hour ending read as values at the stamp are 30 min late."""
    index, cs = sky
    measured = 0.9 * ad.sky_as_read(cs, index, ad.CONVENTIONS[convention])
    found, rms, scale = ad.best_shift(measured, lambda k: ad.sky_as_read(cs, index, None, k))
    assert found == -shift
    assert scale == pytest.approx(0.9, abs=0.02) and rms < 5.0


def test_clear_days_keep_a_clear_sky_and_drop_a_cloudy_one(sky):
    index, cs = sky
    at = ad.sky_as_read(cs, index, None)
    g = pd.Series(at.copy(), index=index)
    g.iloc[30:48] *= np.linspace(0.1, 1.0, 18)  # a cloudy second day
    mask = ad.clear_days(g, at, SITE[1])
    days = set((index[mask] + pd.Timedelta(hours=SITE[1] / 15)).floor("D").day)
    assert 1 in days and 2 not in days


def test_season_table_gain_and_phase():
    """A measured swing half the simulated one and peaking an hour earlier."""
    index = pd.date_range("2011-05-01", "2011-07-01", freq="1h", inclusive="left")
    h = index.hour.to_numpy()
    sim = 10 + 4 * np.cos(2 * np.pi * (h - 15) / 24)
    obs = 10 + 2 * np.cos(2 * np.pi * (h - 14) / 24)
    f = pd.DataFrame({"obs": obs, "sim": sim, "I": 0.0}, index=index)
    t = ad.season_table(f)
    assert t.phase_h.tolist() == pytest.approx([-1.0, -1.0], abs=0.01)
    assert t.gain.tolist() == pytest.approx([np.cos(2 * np.pi / 24) / 2] * 2, abs=0.01)


@pytest.mark.parametrize(
    ("variant", "noise", "phi"),
    [("phifix0.5", "ar1_white", 0.5), ("phifix0", "ar1_white", 0.0), ("noiseiid", "iid", None)],
)
def test_likelihood_variants_reach_the_parameter_set(variant, noise, phi):
    """``phifix<v>`` holds ``phi_Ti`` at v in the section's parameters (not free);
    ``noise<name>`` sets the noise model (``iid``: no ``phi_Ti`` at all); ``phi<cap>``
    caps its prior; the roof's variants leave the section as it was."""
    from heritage_bayes.config import load_config
    from heritage_bayes.models import models_of
    from heritage_bayes.run import section_parameters

    root = Path(__file__).resolve().parents[1]
    cfg = load_config(root / "configs" / "trh1_attic.yaml")
    assert ap.likelihood(cfg.thermal, "wind") is cfg.thermal
    assert ap.likelihood(cfg.thermal, "phi0.8").priors["phi_Ti"].upper == 0.8
    cfg = cfg.model_copy(update={"thermal": ap.likelihood(cfg.thermal, variant)})
    model = models_of(cfg)[0]["thermal"]
    used, params = section_parameters(cfg, "thermal", model, cfg.thermal.priors)
    assert used.name == noise
    found = {p.name: p for p in params.parameters}
    if phi is None:
        assert "phi_Ti" not in found
    else:
        assert found["phi_Ti"].fixed == phi and not found["phi_Ti"].free


def test_roof_answers_parse():
    assert ap._roof_answers("ridge45+pitch30") == ({"ridge_azimuth": 45.0, "pitch": 30.0}, "wind")
    assert ap._roof_answers("ridge0+snow0") == ({"ridge_azimuth": 0.0}, "snow0")
    assert ap._roof_answers("phi0.8") == ({}, "phi0.8")


def test_sky_loss_with_its_own_weight_nests_the_fixed_one():
    """The candidate ``sky``: each slope's loss column ``L_<plane>`` (LW_CAP times the
    loss, negative) enters through the slope's aperture times ``r_lw``; at r_lw =
    1/LW_CAP it is ``lwd``'s I - loss through the aperture, at 0 ``thermal_1c``."""
    from heritage_bayes.rc.model import RCModel

    planes = ["roof_N", "roof_S"]
    m = RCModel(ap._candidate("x_sky", planes, deck=False, sky=True))
    assert "r_lw" in m.parameter_names and m.input_names[-2:] == ("L_roof_N", "L_roof_S")
    p = {"Ci": ap.AIR_MASSLESS, "Ge": 100.0, "Gf": 5.0, "fI_roof_N": 3.0, "fI_roof_S": 7.0}
    for r in (0.0, 1.0 / ap.LW_CAP, 1.0):
        B = m.state_space({**p, "r_lw": r})[1]
        col = {k: B[:, m.input_names.index(k)] for k in m.input_names}
        for k in planes:
            np.testing.assert_allclose(col[f"L_{k}"], r * col[f"I_{k}"], rtol=1e-12)


def test_attic_response_finds_a_slow_sun_beside_a_fast_air():
    """A synthetic attic whose sun passes a store of 2.5 h before the air (τ 1 h): the
    cascade finds both time constants and fits better than one node
    (benchmarks/attic_response.py)."""
    import attic_response as ar

    rng = np.random.default_rng(1)
    hours = np.arange(24 * 15)
    te = 5 * np.sin(2 * np.pi * (hours - 9) / 24) + np.cumsum(rng.normal(0, 0.3, hours.size))
    noon = np.clip(np.sin(2 * np.pi * (hours - 6) / 24), 0, None)
    sun = np.column_stack([300 * noon, 500 * noon * rng.uniform(0.3, 1, hours.size)])
    truth = [np.log(1.0), 8.0, 4.0, 0.5, np.log(2.5)]
    obs = ar.simulate(truth, "cascade", te, sun) + rng.normal(0, 0.05, hours.size)
    mask = np.ones(hours.size, bool)
    p, fit = ar.best("cascade", te, sun, obs, mask)
    assert np.exp(p[0]) == pytest.approx(1.0, rel=0.1)
    assert np.exp(p[4]) == pytest.approx(2.5, rel=0.1)
    assert fit > ar.best("1c", te, sun, obs, mask)[1] + 1.0


def test_buffer_path_is_the_package_recursion_and_its_uptake_heats():
    """The buffer path's Pi is the model's own output; a step up of the outdoor vapour
    pressure fills the buffer (uptake heat > 0), and the heat is L Cm dPw/dt / psat."""
    import heritage_bayes as hb
    from heritage_bayes.rc.sorption import P_REF

    m = hb.model("hygric_2c_sorption")
    theta = np.array([50.0, 3e-3, 1e-6, 2e-6])  # Cm [kg], Ci [kg/Pa], Gi, Gfast [kg/(s Pa)]
    n, dt = 200, 3600.0
    pe = np.where(np.arange(n) < 50, 800.0, 1200.0)
    ti = 12.0 + 4.0 * np.sin(np.arange(n) * 2 * np.pi / 24)
    U = np.column_stack([pe, ti])
    x0 = np.array([800.0, 800.0])
    pw, pi = aso.buffer_path(m, theta, U, dt, x0)
    ref = m.forward(theta[None], U, dt, x0=x0)[0][0, :, 0]
    np.testing.assert_allclose(pi, ref, rtol=1e-12)
    q = aso.uptake_heat(pw, theta[0], dt)
    assert q[55:80].mean() > 0.0 and abs(q[:45].mean()) < q[55:80].mean()
    ramp = aso.uptake_heat(np.linspace(0.0, 10.0, 11), 2.0, 10.0)
    np.testing.assert_allclose(ramp, aso.HEAT_OF_SORPTION * 2.0 / P_REF * 0.1)  # 0.1 Pa/s


def test_air_feed_is_a_store_seen_through_a_massless_air_node():
    """The candidate ``air_feed`` (benchmarks/attic_physics.py) with its air node at
    AIR_MASSLESS, under the package's first-order hold: the simulated air is the
    quasi-steady mix (Gfast Te + Gi Tw + Gf Tf)/(Gfast + Gi + Gf) of the outdoor air at
    the stamp and a one-node store Tw (conductance Gw + Gi Gfast/S to Te, Gi Gf/S to Tf,
    the sun on it): an instantaneous share of Te, the sun only through the store."""
    from heritage_bayes.rc import simulate
    from heritage_bayes.rc.catalog import model
    from heritage_bayes.rc.model import RCModel

    rng = np.random.default_rng(3)
    n = 24 * 10
    hours = np.arange(n + 1)
    te = 8 * np.sin(2 * np.pi * (hours - 9) / 24) + np.cumsum(rng.normal(0, 0.5, n + 1))
    sun = 400 * np.clip(np.sin(2 * np.pi * (hours - 6) / 24), 0, None)
    tf = np.full(n + 1, 5.0)
    p = {"Cw": 5e6, "Ci": ap.AIR_MASSLESS, "Gw": 200.0, "Gi": 1500.0, "Gfast": 1200.0,
         "Gf": 3.0, "fI_roof_N": 10.0, "fI_roof_S": 6.0}  # fmt: skip

    def frame(cols):  # the interval means and the steps' changes (first-order hold)
        out = {k: (v[:-1] + v[1:]) / 2 for k, v in cols.items()}
        return pd.DataFrame({**out, **{f"{k}_slope": np.diff(v) for k, v in cols.items()}})

    cols = {"Te": te, "I_roof_N": sun, "I_roof_S": 0.5 * sun, "Tf": tf}
    feed = RCModel(ap._air_feed("x", ["roof_N", "roof_S"])).with_slopes(tuple(cols))
    ti = simulate(feed, p, frame(cols))[:, 0]
    s = p["Gfast"] + p["Gi"] + p["Gf"]
    one = model("thermal_1c", surfaces=["roof_N", "roof_S"]).with_slopes(tuple(cols))
    q = {"Ci": p["Cw"], "Ge": p["Gw"] + p["Gi"] * p["Gfast"] / s, "Gf": p["Gi"] * p["Gf"] / s,
         "fI_roof_N": 10.0, "fI_roof_S": 6.0}  # fmt: skip
    tw = simulate(one, q, frame(cols))[:, 0]
    mix = (p["Gfast"] * te[:-1] + p["Gi"] * tw + p["Gf"] * tf[:-1]) / s
    np.testing.assert_allclose(ti[24:], mix[24:], atol=1e-4)
