"""What the screen's restart guard changes: the ``model: auto`` screen of the thermal
section on rooms from their raw files (init's config, as :mod:`real_rooms` writes it),
without and with :func:`heritage_bayes.calibration.selection.restart_guard`.

    python benchmarks/screen_guard.py [ROOM ...] [--section thermal] [--out DIR]

ROOM: the tuning rooms of :mod:`real_rooms` by default (R2 R4 R6). Prints per room and
rung: the polished starts' log-posteriors, the guard's searches, the validation FIT of
the MAP kept, the choice with and without the guard, and the CPU time of each screen
(process time, BLAS on one thread).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from threadpoolctl import threadpool_limits  # noqa: E402

from real_rooms import ROOMS, run_init  # noqa: E402


def main(argv=None) -> int:
    from heritage_bayes.calibration.selection import screen
    from heritage_bayes.config import load_config
    from heritage_bayes.models import models_of
    from heritage_bayes.prepare import prepare

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("rooms", nargs="*", default=["R2", "R4", "R6"])
    ap.add_argument("--section", default="thermal", choices=("thermal", "hygric"))
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--out", type=Path, help="work folder (default: a temporary one)")
    args = ap.parse_args(argv)
    work = args.out or Path(tempfile.mkdtemp(prefix="screen_guard_"))
    for room in args.rooms:
        if room not in ROOMS:
            ap.error(f"unknown room {room}; choose from {list(ROOMS)}")
        w = work / room
        w.mkdir(parents=True, exist_ok=True)
        config, questions, _ = run_init(room, args.data, w)
        if questions:
            print(f"{room}: init still asks {questions}")
            continue
        cfg = load_config(config)
        cfg = cfg.model_copy(update={args.section: getattr(cfg, args.section).model_copy(
            update={"model": "auto"})})  # fmt: skip
        models, rungs = models_of(cfg)
        prep = prepare(cfg, models)
        for guarded in (False, True):
            c0 = time.process_time()
            with threadpool_limits(limits=1, user_api="blas"):
                scr = screen(
                    cfg, prep, args.section, rungs[args.section], seed=cfg.seed, guarded=guarded
                )
            cpu = time.process_time() - c0
            for r in scr.rows:
                mp = scr.maps.get(r["model"])
                starts = "" if mp is None else " ".join(f"{c:.1f}" for c in mp.candidates)
                g = r.get("map_guard")
                extra = "" if g is None else f" guard: {g['said']}"
                print(
                    f"{room} guard {'on ' if guarded else 'off'} {r['model']}: "
                    f"val FIT {r.get('score', float('nan')):.2f} %, log-post "
                    f"{'' if mp is None else f'{mp.log_post:.1f}'} (starts {starts}){extra}"
                    + (f" {r['error']}" if "error" in r else ""),
                    flush=True,
                )
            print(
                f"{room} guard {'on ' if guarded else 'off'} chosen {scr.choice['choice']} "
                f"(tied: {', '.join(scr.choice['tied']) or '-'}); screen {cpu:.0f} s CPU",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
