"""The recommendation of an existing ``hbayes compare`` folder by the current selection
rule, from its runs as they are (no sampling): the screen's rows from its
``comparison.json``, each candidate's posterior from its run directory.

    python benchmarks/recommend_again.py COMPARISON_FOLDER

Prints the screen (MAP validation FIT per candidate), the choice and its tie, each
sampled candidate's convergence, validation ELPD and blocked-LOO Pareto k, the ELPD
stage of :func:`heritage_bayes.calibration.selection_rule.decide`, and the recommendation's sentence
beside the one the folder holds. Writes nothing.
"""

from __future__ import annotations

import argparse
import json
import warnings
from pathlib import Path


def main(argv=None) -> int:
    from heritage_bayes.compare import compare_runs

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=Path)
    args = ap.parse_args(argv)
    old = json.loads((args.folder / "comparison.json").read_text(encoding="utf-8"))
    rows = [r for r in (old.get("screen") or {}).get("rows", []) if "error" not in r]
    dirs = {m: args.folder / m for m in old["models"]}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = compare_runs(
            dirs, old["section"], seed=old["settings"]["seed"], screen_rows=rows or None
        )
    sel = res["selection"]
    print("screen:", ", ".join(f"{m} {s:.2f} %" for m, s in sel["scores"].items()))
    print(f"choice {sel['choice']}; tied: {', '.join(sel['tied']) or '-'}")
    for m, info in res["models"].items():
        a = info["accuracy"]
        print(
            f"{m}: converged {info['converged']}, validation ELPD "
            f"{a['elpd_validation']['elpd']:.1f}, blocked-LOO max Pareto k "
            f"{a['loo_blocked']['max_pareto_k']:.2f}"
        )
    print("ELPD stage:", (sel["posterior"] or {}).get("verdict"))
    print(f"recommended {res['recommendation']['model']} (decided by {sel['decided_by']})")
    print("now:   ", res["recommendation"]["reason"])
    print("before:", old["recommendation"]["reason"])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
