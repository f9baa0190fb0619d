"""What Ørholm's indoor temperature needs, one change at a time: thermal MAP validation
FIT [%] (benchmarks/real_rooms.py's budget: 100 generations, 2 local starts).

Two families: the hand-written ``configs/orholm.yaml`` on its periods (2015 / 2016) as
shipped, without its constant gain, and with each of init's choices in turn (two nodes,
the seasonal ground, the estimated sun on one horizontal aperture); and init's config
from the raw files (written to a temporary folder): as written (2019-07 to 2020-07 / to
2021-03, the most recent stretch the store was run one way: its dehumidifier and its
heat gone from 2018, its heating level moved by hand between the winters 2018/19 and
2019/20), with the estimated sun put back, without the constant gain, and on other
periods: 2012 split 8/4 months without the constant gain (what init proposed when it
took the first year), 2014 split 8/4, and 2014 / 2015 (the dehumidified years); and on
init's periods each thermal model, the ground as the running annual mean, and the
seasonal ground at fixed depths (1 m, 2.24 m: a clay/silt soil's periodic penetration
depth, 3 m) and at the depth the calibration estimates (the default).

Usage (from the repository root)::

    python benchmarks/orholm_ablation.py [VARIANT ...] [--data ../shared/data]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from heritage_bayes.config import load_config  # noqa: E402
from heritage_bayes.config.data import GroundTemperature  # noqa: E402
from heritage_bayes.config.periods import Period  # noqa: E402
from real_rooms import map_fits, run_init  # noqa: E402


def _with(cfg, *, data=None, thermal=None, periods=None):
    u = {"hygric": None}
    if data:
        u["data"] = cfg.data.model_copy(update=data)
    if thermal:
        u["thermal"] = cfg.thermal.model_copy(update=thermal)
    if periods:
        s, m, e = periods
        u["periods"] = cfg.periods.model_copy(
            update={"calibration": Period(start=s, end=m), "validation": Period(start=m, end=e)}
        )
    return cfg.model_copy(update=u)


def variants(init_cfg):
    hand = load_config(ROOT / "configs" / "orholm.yaml")
    opts = dict(hand.thermal.options)
    iopts = dict(init_cfg.thermal.options)
    no_gain = {k: v for k, v in iopts.items() if k != "source"}
    annual = GroundTemperature(mode="annual_mean")
    seasonal = GroundTemperature(mode="seasonal")

    def deep(depth):
        return GroundTemperature(mode="seasonal", depth=depth)

    return {
        "hand": lambda: _with(hand),
        "hand without source": lambda: _with(
            hand, thermal={"options": {k: v for k, v in opts.items() if k != "source"}}
        ),
        "hand + thermal_2c": lambda: _with(hand, thermal={"model": "thermal_2c"}),
        "hand + seasonal Tf": lambda: _with(
            hand, data={"ground_temperature": GroundTemperature(mode="seasonal")}
        ),
        "hand + estimated sun": lambda: _with(
            hand, data={"irradiance": "estimated", "surfaces": {"H": (0.0, 0.0)}}
        ),
        "init, 2012 8/4, no source": lambda: _with(
            init_cfg,
            thermal={"options": no_gain},
            periods=("2012-01-01", "2012-09-01", "2013-01-01"),
        ),
        "init, 2014 8/4": lambda: _with(
            init_cfg, periods=("2014-01-01", "2014-09-01", "2015-01-01")
        ),
        "init, 2014 / 2015": lambda: _with(
            init_cfg, periods=("2014-01-01", "2015-01-01", "2016-01-01")
        ),
        "init as written": lambda: _with(init_cfg),
        "init + estimated sun": lambda: _with(
            init_cfg, data={"irradiance": "estimated", "surfaces": {"H": (0.0, 0.0)}}
        ),
        "init without source": lambda: _with(init_cfg, thermal={"options": no_gain}),
        # on init's periods (the heating seasons at one level), each model and ground
        "init, thermal_1c": lambda: _with(init_cfg, thermal={"model": "thermal_1c"}),
        "init, thermal_2c": lambda: _with(init_cfg, thermal={"model": "thermal_2c"}),
        "init, thermal_4a": lambda: _with(init_cfg, thermal={"model": "thermal_4a"}),
        "init, thermal_1c, annual-mean Tf": lambda: _with(
            init_cfg, thermal={"model": "thermal_1c"}, data={"ground_temperature": annual}
        ),
        "init, thermal_2c, annual-mean Tf": lambda: _with(
            init_cfg, thermal={"model": "thermal_2c"}, data={"ground_temperature": annual}
        ),
        "init, thermal_1c, Tf 2.24 m deep": lambda: _with(
            init_cfg, thermal={"model": "thermal_1c"}, data={"ground_temperature": deep(2.24)}
        ),
        "init, thermal_2c, Tf 2.24 m deep": lambda: _with(
            init_cfg, thermal={"model": "thermal_2c"}, data={"ground_temperature": deep(2.24)}
        ),
        "init, thermal_1c, Tf 3 m deep": lambda: _with(
            init_cfg, thermal={"model": "thermal_1c"}, data={"ground_temperature": deep(3.0)}
        ),
        "init, thermal_2c, Tf 3 m deep": lambda: _with(
            init_cfg, thermal={"model": "thermal_2c"}, data={"ground_temperature": deep(3.0)}
        ),
        "init, thermal_2c, Tf 1 m deep": lambda: _with(
            init_cfg, thermal={"model": "thermal_2c"}, data={"ground_temperature": deep(1.0)}
        ),
        # the default: the seasonal ground at a depth the calibration estimates (zf)
        "init, thermal_1c, Tf depth estimated": lambda: _with(
            init_cfg, thermal={"model": "thermal_1c"}, data={"ground_temperature": seasonal}
        ),
        "init, thermal_2c, Tf depth estimated": lambda: _with(
            init_cfg, thermal={"model": "thermal_2c"}, data={"ground_temperature": seasonal}
        ),
        "init, thermal_4a, Tf depth estimated": lambda: _with(
            init_cfg, thermal={"model": "thermal_4a"}, data={"ground_temperature": seasonal}
        ),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("variants", nargs="*", help="default: all")
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        config, questions, _ = run_init("orholm", args.data, Path(tmp))
        if questions:
            print(f"init left questions: {questions}")
            return 1
        v = variants(load_config(config))
        for name in args.variants or list(v):
            fits = map_fits(v[name](), 100, 2)
            print(f"{name}: FIT Ti {fits['Ti']:.1f} %  ({json.dumps(fits)})", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
