"""Which noise model should be the default? Full calibrations of one config, per noise model
and (for the demo) per data seed, tabulated from each run's ``summary.json``.

Each run goes through the package's own calibrate path (``run_calibration``, no report,
no model ladder: the ladder's MAP fits do not change the posterior), with the config's
``noise:`` replaced in every section. The noise parameters' priors follow the model:
``sigma_meas_<out>`` (``ar1_white``'s reading noise) is ``kalman``'s ``sigma_<out>`` and
back; ``phi_<out>`` and the AR part's ``sigma_<out>`` have no ``kalman`` counterpart,
``q_<node>`` none in ``ar1_white``. A controlled room (thermostat/humidistat) cannot be
filtered by ``kalman``: its row records the refusal.

One JSON line per run (``--log``, appended and flushed as each run ends): validation
FIT/MAE of the posterior-median free-run simulation, 90 % band coverage (free run and,
for ``kalman``, one step ahead), steps, τmax, R-hat, ESS, CPU [s], and, where the data
are synthetic, every derived quantity with a truth: inside its 90 % interval or not, and
its distance from the posterior median in posterior sd.

    python benchmarks/noise_default.py configs/trh1_attic.yaml --noise ar1_white kalman \\
        --log real.jsonl
    python benchmarks/noise_default.py configs/demo.yaml --noise ar1_white kalman \\
        --seeds 7 8 9 10 11 12 --log seeds.jsonl
    python benchmarks/noise_default.py configs/demo.yaml --noise ar1_white \\
        --temperature thermal=1 --seeds 7 8 9 --log untempered.jsonl
    python benchmarks/noise_default.py --table real.jsonl seeds.jsonl

``--temperature SECTION=T`` sets a section's ``likelihood_temperature`` (default: the
package's, 2 for one- and two-node thermal sections and 1 otherwise; each line's
``chains`` record the values the runs used).
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import sys
import tempfile
from pathlib import Path

import numpy as np

NOISES = ("ar1_white", "ar1", "iid", "kalman")


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def translate_priors(priors: dict, outputs: list[str], noise: str) -> dict:
    """The section's priors with the noise parameters renamed for ``noise``
    (``sigma_meas_<out>`` <-> kalman's ``sigma_<out>``; the others dropped)."""
    out = {}
    for k, v in priors.items():
        if noise == "kalman":
            if k.startswith("sigma_meas_"):
                out["sigma_" + k[len("sigma_meas_") :]] = v
            elif k.startswith("phi_") or k in {f"sigma_{o}" for o in outputs}:
                continue
            else:
                out[k] = v
        else:
            if k.startswith("q_"):
                continue
            out[k] = v
    return out


def variant(
    cfg, noise: str, seed: int | None, split: str | None = None, temperature: dict | None = None
):
    """``cfg`` with ``noise`` in every model section, no ladder, (demo) data seed and,
    with ``split``, calibration before that instant and validation from it to the end
    of the configured calibration period (a record with no validation period);
    ``temperature`` {section: T} sets those sections' ``likelihood_temperature``."""
    from heritage_bayes.config.periods import Period
    from heritage_bayes.models import build_model

    update = {"ladder": False}
    if split is not None:
        cal = cfg.periods.calibration
        periods = cfg.periods.model_copy(
            update={
                "calibration": Period(start=cal.start, end=split),
                "validation": Period(start=split, end=cal.end),
            }
        )
        update["periods"] = periods
    for name in ("thermal", "hygric"):
        sec = getattr(cfg, name)
        if sec is None:
            continue
        outputs = list(build_model(cfg, name).output_names)
        priors = sec.priors
        if sec.noise == "kalman" and noise != "kalman":  # kalman's sigma is the reading noise
            priors = {
                ("sigma_meas_" + k[6:] if k in {f"sigma_{o}" for o in outputs} else k): v
                for k, v in priors.items()
            }
        sec_update = {"noise": noise, "priors": translate_priors(priors, outputs, noise)}
        if temperature and name in temperature:
            sec_update["likelihood_temperature"] = temperature[name]
        update[name] = sec.model_copy(update=sec_update)
    if seed is not None:
        demo = cfg.data.demo.model_copy(update={"seed": seed})
        update["data"] = cfg.data.model_copy(update={"demo": demo})
    return cfg.model_copy(update=update)


def row_of(summary: dict) -> dict:
    """The figures of one run from its ``summary.json``."""
    row: dict = {
        "converged": summary.get("converged"),
        "max_rhat": summary.get("max_rhat"),
        "min_ess_bulk": summary.get("min_ess_bulk"),
        "chains": {},
        "metrics": {},
        "truths": {},
    }
    for name, m in (summary.get("models") or {}).items():
        ch = m.get("chain") or {}
        row["chains"][name] = {
            k: ch.get(k) for k in ("steps", "tau_max", "cpu_seconds", "stopped_by")
        }
        # the temperature the run used (the config's, or the package's default)
        row["chains"][name]["likelihood_temperature"] = m.get("likelihood_temperature")
    for name, outs in (summary.get("metrics") or {}).items():
        for out, per in outs.items():
            val = per.get("validation") or {}
            row["metrics"][f"{name}.{out}"] = {
                k: val.get(k) for k in ("FIT", "MAE", "coverage90", "coverage90_1step")
            }
    for key, d in (summary.get("derived") or {}).items():
        t = d.get("truth")
        if t is None or not math.isfinite(float(t)):
            continue
        sd = float(d.get("sd") or 0.0)
        row["truths"][key] = {
            "inside": bool(d["q05"] <= t <= d["q95"]),
            "z": (t - d["median"]) / sd if sd > 0 else None,
        }
    return row


def run(
    config: str,
    noises: list[str],
    seeds: list[int | None],
    log: Path,
    split: str | None,
    temperature: dict | None = None,
) -> None:
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.config import load_config

    cfg0 = load_config(config)
    for seed in seeds:
        for noise in noises:
            cfg = variant(cfg0, noise, seed, split, temperature)
            rec = {"config": config, "noise": noise, "data_seed": seed, "split": split}
            c0 = _cpu()
            with tempfile.TemporaryDirectory(prefix="hb-noise-") as tmp:
                try:
                    out = run_calibration(cfg, Path(tmp) / "run", quiet=True, report=False)
                except ValueError as exc:  # e.g. kalman on a controlled room
                    rec["error"] = str(exc)
                else:
                    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
                    rec.update(row_of(summary))
                    rec["run_bytes"] = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
            rec["cpu_seconds"] = _cpu() - c0
            with log.open("a", encoding="utf-8") as f:
                f.write(json.dumps(rec) + "\n")
            print(json.dumps(rec), flush=True)


def _f(v, fmt: str) -> str:
    return "—" if v is None else format(v, fmt)


def table(paths: list[str]) -> None:
    """Markdown tables: one row per run and output; the demo truths per seed and quantity."""
    recs = [
        {**json.loads(line), "_log": p} for p in paths for line in Path(p).read_text().splitlines()
    ]
    print(
        "| config | noise | seed | output | val FIT % | val MAE | 90 % band | 1-step 90 % "
        "| steps / τmax | max R-hat | min ESS | CPU s |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in recs:
        name = Path(r["config"]).stem
        if "error" in r:
            print(
                f"| {name} | {r['noise']} | | refused: {r['error'][:90]} |||||||| "
                f"{r['cpu_seconds']:.0f} |"
            )
            continue
        chains = ", ".join(f"{c['steps']} / {c['tau_max']:.0f}" for c in r["chains"].values())
        for out, m in r["metrics"].items():
            print(
                f"| {name} | {r['noise']} | {_f(r['data_seed'], 'd')} | {out} "
                f"| {_f(m['FIT'], '.1f')} | {_f(m['MAE'], '.3g')} | {_f(m['coverage90'], '.3f')} "
                f"| {_f(m.get('coverage90_1step'), '.3f')} | {chains} "
                f"| {_f(r['max_rhat'], '.3f')} | {_f(r['min_ess_bulk'], '.0f')} "
                f"| {r['cpu_seconds']:.0f} |"
            )
    truths = [r for r in recs if r.get("truths")]
    if not truths:
        return
    keys = sorted({k for r in truths for k in r["truths"]})
    print("\nz = (truth - median) / sd; * outside the 90 % interval\n")
    print("| noise | seed | inside | worst z | " + " | ".join(keys) + " |")
    print("|---|---|---|---|" + "---|" * len(keys))
    for r in truths:
        t = r["truths"]
        zs = [abs(v["z"]) for v in t.values() if v["z"] is not None]
        cells = [f"{t[k]['z']:+.2f}{'' if t[k]['inside'] else '*'}" if k in t else "" for k in keys]
        inside = sum(v["inside"] for v in t.values())
        print(
            f"| {r['noise']} | {r['data_seed']} | {inside}/{len(t)} | {max(zs):.2f} | "
            + " | ".join(cells)
            + " |"
        )
    # per log and noise model: coverage, mean and sd of z, and how each quantity's z goes
    # with the gain from Te's over the seeds (which misses travel together)
    for log, noise in dict.fromkeys((r["_log"], r["noise"]) for r in truths):
        rs = [r for r in truths if (r["_log"], r["noise"]) == (log, noise)]
        z = {k: np.array([r["truths"][k]["z"] for r in rs if k in r["truths"]]) for k in keys}
        per = {k: sum(r["truths"][k]["inside"] for r in rs if k in r["truths"]) for k in keys}
        inside = sum(per.values())
        worst = max(abs(v["z"]) for r in rs for v in r["truths"].values())
        print(
            f"\n{log} [{noise}]: {len(rs)} seeds, {inside} of {len(rs) * len(keys)} truths "
            f"inside, seeds with >= {len(keys) - 2} of {len(keys)}: "
            f"{sum(sum(v['inside'] for v in r['truths'].values()) >= len(keys) - 2 for r in rs)}, "
            f"largest |z| {worst:.2f}; per quantity inside, mean z / sd z:"
        )
        for k in keys:
            line = f"  {k:24s} {per[k]}/{len(rs)}  {z[k].mean():+.2f} / {z[k].std():.2f}"
            ref = z.get("thermal.gain_Ti_Te")
            if ref is not None and k != "thermal.gain_Ti_Te" and len(rs) > 2 and z[k].std() > 0:
                line += f"  corr with the Te gain's z {np.corrcoef(ref, z[k])[0, 1]:+.2f}"
            print(line)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("config", nargs="?")
    ap.add_argument("--noise", nargs="+", choices=NOISES, default=["ar1_white", "kalman"])
    ap.add_argument("--seeds", nargs="+", type=int, help="data.demo.seed values (demo only)")
    ap.add_argument(
        "--split",
        metavar="INSTANT",
        help="calibrate before INSTANT, validate from it to the calibration period's end",
    )
    ap.add_argument(
        "--temperature",
        nargs="+",
        metavar="SECTION=T",
        default=[],
        help="set a section's likelihood_temperature (e.g. thermal=1: untempered)",
    )
    ap.add_argument("--log", type=Path, default=Path("noise_default.jsonl"))
    ap.add_argument("--table", nargs="+", metavar="JSONL", help="tabulate logs and exit")
    a = ap.parse_args(argv)
    if a.table:
        table(a.table)
        return 0
    if not a.config:
        ap.error("a config (or --table)")
    temperature = {}
    for item in a.temperature:
        name, _, value = item.partition("=")
        if name not in ("thermal", "hygric") or not value:
            ap.error(
                f"--temperature: expected SECTION=T with SECTION thermal or hygric, got {item!r}"
            )
        temperature[name] = float(value)
    run(a.config, a.noise, a.seeds or [None], a.log, a.split, temperature)
    return 0


if __name__ == "__main__":
    sys.exit(main())
