"""Command-line interface: ``hbayes``.

Thin: parse arguments, call the library, map outcomes to exit codes:

- 0: success (``calibrate``: every chain converged);
- 3: finished but **not converged** (``calibrate``: the run directory is complete, but a
  chain stopped at ``sampler.max_time`` or ``sampler.max_steps`` before the criteria
  held: ``summary.json`` has ``converged: false`` and ``unconverged_reasons``; continue
  with ``--resume`` or a larger budget. ``batch``: every room finished, some unconverged.
  ``project``: written, but from an unconverged calibration);
- 2: a user error (config, data, arguments; a message, no traceback);
- 1: an internal error (a bug: the traceback is shown);
- 130: interrupted by SIGINT or SIGTERM at any stage;
- 141: the reader of the output went away (``hbayes models | head -1``), as for Unix
  tools (128 + SIGPIPE); nothing is printed.

Messages are written in the terminal's encoding, with escapes (``\\xb0``) for what it
cannot hold; a message quotes at most 100 characters of a user's data.

Tested by calling :func:`main` directly, and as a subprocess (``tests/test_faults.py``).
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading

from heritage_bayes._terminal import DISK_ERRORS, disk_error_text, internal_error
from heritage_bayes._terminal import print_error as _error
from heritage_bayes._terminal import reader_gone as _reader_gone
from heritage_bayes._terminal import tolerant_streams as _tolerant_streams
from heritage_bayes._version import __version__
from heritage_bayes.errors import InputError
from heritage_bayes.names import DEFAULT_NOISE, NOISE_MODELS

__all__ = ["main"]


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="hbayes",
        description="Bayesian calibration of RC models of the indoor climate of monuments.",
    )
    parser.add_argument("--version", action="version", version=f"hbayes {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    for add in (_add_run_commands, _add_model_commands, _add_setup_commands):
        add(sub)
    return parser


def _add_run_commands(sub) -> None:
    """``calibrate``, ``report`` and ``project``."""
    cal = sub.add_parser(
        "calibrate",
        help="calibrate the models of a YAML config",
        description="Calibrate the thermal and/or hygric RC models of a "
        "config; write posterior.nc, summary.json, config.yaml "
        "and report.html to the run directory.",
    )
    cal.add_argument("config", help="YAML configuration file (e.g. configs/demo.yaml)")
    cal.add_argument("--out", metavar="DIR", help="run directory (default: reports/<config name>/)")
    cal.add_argument("--seed", type=int, help="random seed (overrides the config's)")
    cal.add_argument(
        "--resume", action="store_true", help="continue the chains saved in the run directory"
    )
    cal.add_argument("--quiet", action="store_true", help="no progress output")
    cal.add_argument("--no-report", action="store_true", help="skip report.html")
    cal.add_argument(
        "--force",
        action="store_true",
        help="write the run beside the files of a folder hbayes did not make (none of them "
        "is replaced; one named like a run's file is refused)",
    )
    cal.set_defaults(func=_cmd_calibrate)

    rep = sub.add_parser(
        "report",
        help="(re)write RUN_DIR/report.html",
        description="Write the self-contained HTML report of a run.",
    )
    rep.add_argument("run_dir", help="a run directory written by `hbayes calibrate`")
    rep.add_argument("--quiet", action="store_true")
    rep.set_defaults(func=_cmd_report)

    prj = sub.add_parser(
        "project",
        help="project a calibrated room's climate and risk onto future weather",
        description="Run the posterior draws of a calibrated room on future weather "
        "(KNMI'14 scenarios, morphing, or future files) and turn the indoor climate into "
        "conservation risk; write projection.nc, projection.json, projection.csv and "
        "projection.html. Exit status 3 (written, with a warning) when the calibration "
        "did not converge.",
    )
    prj.add_argument("run_dir", help="a run directory written by `hbayes calibrate`")
    prj.add_argument("projection", help="projection YAML file (e.g. configs/projection_demo.yaml)")
    prj.add_argument("--out", metavar="DIR", help="output folder (default: RUN_DIR/projection)")
    prj.add_argument("--draws", type=int, metavar="N", help="posterior draws (overrides the file)")
    prj.add_argument("--seed", type=int, metavar="S", help="random seed (overrides the file)")
    prj.add_argument("--quiet", action="store_true", help="no progress output")
    prj.set_defaults(func=_cmd_project)


def _add_model_commands(sub) -> None:
    """``models`` and ``compare``."""
    mod = sub.add_parser(
        "models",
        help="list the catalogue of RC models, or describe one",
        description="Without NAME: the catalogue. With NAME: the model's equations in "
        "words, its parameters with units and default priors (the names for `priors:`), "
        "inputs and outputs.",
    )
    mod.add_argument("name", nargs="?", help="a catalogue model, e.g. thermal_2c")
    mod.add_argument(
        "--noise",
        default=DEFAULT_NOISE,
        choices=NOISE_MODELS,  # read when parsed or shown: a name registered later shows
        metavar="NOISE",
        help="noise model: %(choices)s (default %(default)s)",
    )
    mod.set_defaults(func=_cmd_models)

    cmp_ = sub.add_parser(
        "compare",
        help="calibrate candidate models and compare accuracy vs identifiability",
        description="Calibrate each candidate model of one section with full posteriors "
        "(each in its own run directory) and compare them on accuracy (validation "
        "FIT/MSE/MAE and ELPD, blocked PSIS-LOO on calibration) and identifiability "
        "(contraction, structural and practical rank); write comparison.json and "
        "comparison.html with a recommendation.",
    )
    cmp_.add_argument("config", help="YAML configuration file (e.g. configs/demo.yaml)")
    cmp_.add_argument(
        "--models",
        metavar="A,B,...",
        help="catalogue models of one section (default: thermal_1c,thermal_2c,thermal_4a)",
    )
    cmp_.add_argument(
        "--out", metavar="DIR", help="output folder (default: reports/<config name>-compare/)"
    )
    cmp_.add_argument("--seed", type=int, help="random seed (overrides the config's)")
    cmp_.add_argument("--resume", action="store_true", help="continue saved chains")
    cmp_.add_argument(
        "--force",
        action="store_true",
        help="write beside the files of folders hbayes did not make (<out>, <out>/<model>/); "
        "none of them is replaced",
    )
    cmp_.add_argument("--quiet", action="store_true", help="no progress output")
    cmp_.add_argument("--no-report", action="store_true", help="no report.html per model")
    cmp_.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="candidates calibrated at once (default: one per core, at most one per "
        "model; the largest in this process, the others in N-1 worker processes; 1: one "
        "after the other)",
    )
    cmp_.set_defaults(func=_cmd_compare)


def _add_setup_commands(sub) -> None:
    """``init`` and ``batch``."""
    ini = sub.add_parser(
        "init",
        help="write a commented config.yaml from a logger file and a weather file",
        description="Inspect a logger export and a weather file (layout, time column, "
        "clocks checked against the sun, columns and units, gaps, periods) and write a "
        "commented configuration. What cannot be decided is left as a '??' question "
        "that `hbayes calibrate` refuses until answered.",
    )
    ini.add_argument("indoor", metavar="INDOOR_FILE", help="logger export (indoor T, RH)")
    ini.add_argument("--weather", metavar="WEATHER_FILE", required=True, help="weather file")
    ini.add_argument(
        "--weather-format",
        metavar="FMT",
        choices=["csv", "epw", "knmi", "tmy3"],
        help="csv, epw, knmi or tmy3 (default: from the file)",
    )
    ini.add_argument("--latitude", type=float, metavar="DEG", help="site latitude [° north]")
    ini.add_argument("--longitude", type=float, metavar="DEG", help="site longitude [° east]")
    ini.add_argument("--name", help="run name (default: from the output file)")
    ini.add_argument(
        "--timezone",
        metavar="TZ",
        help="the logger's clock when its header does not name it (UTC+1, Europe/Paris)",
    )
    ini.add_argument("--weather-timezone", metavar="TZ", help="the weather file's clock, likewise")
    ini.add_argument(
        "-o", "--output", metavar="PATH", default="config.yaml", help="default: config.yaml"
    )
    ini.add_argument(
        "--force",
        action="store_true",
        help="replace an existing file (a symbolic link is replaced itself, never written through)",
    )
    ini.add_argument(
        "--in-data-folder",
        action="store_true",
        help="allow --output in the folder of INDOOR_FILE or WEATHER_FILE (refused by "
        "default: data folders are archives of raw measurements)",
    )
    ini.set_defaults(func=_cmd_init)

    bat = sub.add_parser(
        "batch",
        help="calibrate every room of a portfolio on Dask",
        description="Calibrate every room of a portfolio file as a task on dask.distributed "
        "(a local cluster by default, or --scheduler); write one run directory per room, "
        "portfolio.csv, portfolio.json and index.html.",
    )
    bat.add_argument("portfolio", help="portfolio YAML file (e.g. configs/portfolio_demo.yaml)")
    bat.add_argument("--out", metavar="DIR", help="output folder (default: reports/<name>/)")
    bat.add_argument(
        "--scheduler", metavar="ADDRESS", help="a running Dask scheduler, e.g. tcp://host:8786"
    )
    bat.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="local workers (default and maximum: the CPUs available)",
    )
    bat.add_argument(
        "--workers-unbounded",
        action="store_true",
        help="allow --workers above the CPUs available",
    )
    bat.add_argument(
        "--resume", action="store_true", help="skip finished rooms, continue interrupted chains"
    )
    bat.add_argument("--quiet", action="store_true", help="no progress output")
    bat.set_defaults(func=_cmd_batch)


def _cmd_calibrate(args) -> int:
    from heritage_bayes.config import load_config

    cfg = load_config(args.config)  # config errors before the heavy imports
    from heritage_bayes.calibration.calibrate import run_calibration

    out = run_calibration(
        cfg,
        args.out,
        seed=args.seed,
        resume=args.resume,
        quiet=args.quiet,
        report=False if args.no_report else None,
        force=args.force,
    )
    if not args.quiet:
        print(out)
    return _converged_or_3(out)


def _converged_or_3(run_dir) -> int:
    """0 when the run's ``summary.json`` says converged; else name the reasons, return 3."""
    from heritage_bayes.calibration.convergence import EXIT_UNCONVERGED
    from heritage_bayes.report.accuracy import accuracy_failures, resolutions
    from heritage_bayes.rundir.summary import load_summary

    rs = load_summary(run_dir)
    conv = rs.convergence
    failures = accuracy_failures(rs, resolutions({}))
    if failures:
        print(
            "hbayes: warning: this model does not reproduce the room: "
            + "; ".join(f["text"] for f in failures)
            + f". The report's verdict names what is most likely missing: {run_dir}",
            file=sys.stderr,
        )
    if conv.converged:
        if not conv.draws_ok:  # the report's verdict is amber
            print(f"hbayes: note: {conv.draws_text}", file=sys.stderr)
        return 0
    print(
        f"hbayes: finished but NOT converged (exit code {EXIT_UNCONVERGED}): {run_dir}",
        file=sys.stderr,
    )
    for reason in conv.reasons or ["see summary.json"]:
        print(f"hbayes:   {reason}", file=sys.stderr)
    print("hbayes: continue the chains with --resume, or raise sampler.max_time", file=sys.stderr)
    return EXIT_UNCONVERGED


def _cmd_init(args) -> int:
    from heritage_bayes.config import Site
    from heritage_bayes.config._base import check_in_range

    for name in ("latitude", "longitude"):  # before any file is read
        if getattr(args, name) is not None:
            check_in_range(Site, name, getattr(args, name), f"--{name}")
    from heritage_bayes.init_config import init_config

    opts = ("weather_format", "latitude", "longitude", "name", "timezone", "weather_timezone")
    res = init_config(
        args.indoor,
        args.weather,
        output=args.output,
        force=args.force,
        in_data_folder=args.in_data_folder,
        **{k: getattr(args, k) for k in opts},
    )
    from heritage_bayes._terminal import MAX_LINE
    from heritage_bayes.errors import shorten

    for f in res.findings:
        print(f"hbayes init: {shorten(f, MAX_LINE)}", file=sys.stderr)
    for q in res.questions:
        print(f"hbayes init: QUESTION {shorten(q, MAX_LINE)}", file=sys.stderr)
    n = len(res.questions)
    tail = f"; {n} open question(s) to answer in it before `hbayes calibrate`" if n else ""
    print(f"{res.path}{tail}")
    return 0


def _cmd_report(args) -> int:
    from heritage_bayes.report import write_report

    path = write_report(args.run_dir)
    if not args.quiet:
        print(path)
    return 0


def _cmd_project(args) -> int:
    from heritage_bayes.projection import load_projection_config

    pcfg = load_projection_config(args.projection)  # config errors before heavy imports
    from heritage_bayes.projection import project

    def say(line: str) -> None:
        print(f"hbayes project: {line}", file=sys.stderr, flush=True)

    proj = project(
        args.run_dir,
        pcfg,
        out=args.out,
        draws=args.draws,
        seed=args.seed,
        progress=None if args.quiet else say,
    )
    if not args.quiet:
        print(proj.probability_table().to_string(float_format=lambda v: f"{v:.2f}"))
        for p in proj.paths.values():
            print(p)
    if not proj.summary["converged"]:
        from heritage_bayes.projection import EXIT_UNCONVERGED_RUN, UNCONVERGED_TEXT

        print(
            f"hbayes project: written, but {UNCONVERGED_TEXT} (exit code "
            f"{EXIT_UNCONVERGED_RUN}); continue the calibration with --resume",
            file=sys.stderr,
        )
        return EXIT_UNCONVERGED_RUN
    return 0


def _cmd_models(args) -> int:
    from heritage_bayes.models import describe_model
    from heritage_bayes.rc.catalog import available_models

    if args.name is None:
        for name, desc in available_models().items():
            print(f"{name:<20s} {desc}")
        print(_CONTROL_HELP)
        return 0
    try:
        text = describe_model(args.name, noise=args.noise)
    except ValueError as exc:
        raise InputError(f"models NAME: {exc}") from None
    print(text)  # outside the check: the terminal's encoding is not the name's fault
    return 0


def _cmd_compare(args) -> int:
    from heritage_bayes.compare import accuracy_rows, identifiability_rows, run_compare
    from heritage_bayes.config import load_config

    cfg = load_config(args.config)
    models = None if args.models is None else _model_list(args.models)
    if args.seed is not None:
        from heritage_bayes.config import CalibrationConfig
        from heritage_bayes.config._base import check_in_range

        check_in_range(CalibrationConfig, "seed", args.seed, "--seed")
    out = run_compare(
        cfg,
        models,
        args.out,
        seed=args.seed,
        quiet=args.quiet,
        report=False if args.no_report else None,
        resume=args.resume,
        force=args.force,
        workers=args.workers,
    )
    if not args.quiet:
        from heritage_bayes.rundir.reader import read_json_object

        res = read_json_object(out / "comparison.json", "the object of a comparison")
        for head, rows in (accuracy_rows(res), identifiability_rows(res)):
            print(" | ".join(head))
            for r in rows:
                print(" | ".join(r))
            print()
        for m, info in (res.get("screened_out") or {}).items():
            print(f"{m}: {info['reason']}")
        print("recommendation:", res["recommendation"]["reason"])
        print(out / "comparison.html")
    return 0


def _model_list(text: str) -> list[str]:
    """``--models A,B``: the names, none empty (an unset shell variable gives '')."""
    from heritage_bayes.errors import quoted

    names = [n.strip() for n in text.split(",")]
    if not any(names):
        raise InputError(
            "--models: empty; give catalogue models of one section separated by commas, "
            "e.g. thermal_1c,thermal_2c (see `hbayes models`), or leave --models out for "
            "the default candidates"
        )
    if not all(names):
        raise InputError(f"--models: an empty name in {quoted(text)}; separate names by one comma")
    return names


_CONTROL_HELP = """
Options (YAML: <section>.options), any catalogue model:
  thermal: surfaces, ground (true | false | estimate), heating (known power Ph [W])
  control of the air node (a heated or humidity-controlled room):
    thermostat: true            ideal heating to an estimated set-point Tset [°C]
    thermostat: {power_limit: true, schedule: COLUMN, conservation: true}
                                Pmax [W] maximum power; Tset_use [°C] in the hours of
                                use (input COLUMN: 1 in use, 0 not); conservation
                                heating: RH kept <= RH_ch [-] (input Pi, measured)
    thermostat: {schedule: {weekly: ["Sun 08-12", "Wed 19-21"], timezone: Europe/Copenhagen}}
                                the hours of use from a weekly calendar in a local
                                clock (DAYS HH[:MM]-HH[:MM]; DAYS Sun, Mon-Fri or
                                Sat,Sun): generated input hours_of_use [-]
    humidistat: band | dehumidifier | humidifier | setpoint   (hygric)
                                RH at the indoor temperature (input Ti, measured) held
                                in [RH_lo, RH_hi] [-] (or at RH_set)
    humidistat: {mode: band, capacity: true}
                                M_dehum, M_hum [kg/s] capacities (otherwise ideal)
    source: true                constant heat gain Qs [W] or moisture source Ms [kg/s]
  Projections can switch control off: Run.simulate(..., control=False) or
  control={"humidistat": False} (see heritage_bayes.rc.control)."""


def _cmd_batch(args) -> int:
    from heritage_bayes.portfolio import check_workers, load_portfolio, run

    check_workers(args.workers, unbounded=args.workers_unbounded)  # before any work
    pf = load_portfolio(args.portfolio)  # every room validated before any work starts
    df = run(
        pf,
        args.out,
        scheduler=args.scheduler,
        workers=args.workers,
        resume=args.resume,
        quiet=args.quiet,
        workers_unbounded=args.workers_unbounded,
    )
    from heritage_bayes.calibration.convergence import EXIT_UNCONVERGED

    bad = df[~df["status"].isin(["done", "skipped"])]
    for _, r in bad.iterrows():
        print(f"hbayes: room {r['room']!r} {r['status']}: {r['message']}", file=sys.stderr)
    finished = df[df["status"].isin(["done", "skipped"])]
    conv = finished.get("converged")
    unconverged = finished[~conv.fillna(False).astype(bool)] if conv is not None else finished[:0]
    for _, r in unconverged.iterrows():
        why = r.get("unconverged_reasons")
        why = why if isinstance(why, str) and why else "see its summary.json"
        print(f"hbayes: room {r['room']!r} finished NOT converged: {why}", file=sys.stderr)
    if len(unconverged) and not args.quiet:
        print(
            f"hbayes: {len(finished) - len(unconverged)} of {len(df)} room(s) converged, "
            f"{len(unconverged)} finished unconverged, {len(bad)} failed",
            file=sys.stderr,
        )
    if not bad.empty:
        return 1 if (bad["status"] == "error").any() else 2
    return EXIT_UNCONVERGED if len(unconverged) else 0


class _Terminated(KeyboardInterrupt):
    """SIGTERM, handled like Ctrl-C (the chains are saved; exit 130)."""


def _on_sigterm(signum, frame):
    raise _Terminated


def main(argv: list[str] | None = None) -> int:
    """Run ``hbayes``; return the exit code."""
    old = None
    if threading.current_thread() is threading.main_thread():
        old = signal.signal(signal.SIGTERM, _on_sigterm)
    swallowed: list = []
    old_hook = sys.unraisablehook

    def hook(u):
        # an interrupt raised inside a callback (a finaliser, the import system) would be
        # lost, and a run with a large max_steps would sample on: deliver it again from
        # another thread, so that the main thread's handler raises it in ordinary code
        if isinstance(u.exc_value, KeyboardInterrupt):
            swallowed.append(u.exc_value)
            signum = signal.SIGTERM if isinstance(u.exc_value, _Terminated) else signal.SIGINT
            threading.Thread(target=signal.raise_signal, args=(signum,), daemon=True).start()
        else:
            old_hook(u)

    sys.unraisablehook = hook
    _tolerant_streams()
    try:
        code = _main(argv)
        sys.stdout.flush()  # here, not at exit: a reader gone (| head) is handled below
        if swallowed and code == 0:
            print(
                "hbayes: the interrupt came too late to stop it: the run is complete",
                file=sys.stderr,
            )
        return code
    except KeyboardInterrupt as exc:  # before or after a command ran
        return _interrupted(exc, None)
    except BrokenPipeError:
        return _reader_gone()
    finally:
        sys.unraisablehook = old_hook
        if old is not None:
            signal.signal(signal.SIGTERM, old)


def _interrupted(exc: BaseException, command: str | None) -> int:
    what = "terminated (SIGTERM)" if isinstance(exc, _Terminated) else "interrupted"
    hint = " (continue with --resume)" if command == "calibrate" else ""
    print(f"hbayes: {what}{hint}", file=sys.stderr, flush=True)
    _notes(exc)
    return 130


def _notes(exc: BaseException) -> None:
    """What a failed run left behind (added by the library as exception notes)."""
    for note in getattr(exc, "__notes__", ()):
        print(f"hbayes: {note}", file=sys.stderr, flush=True)


def _main(argv: list[str] | None) -> int:
    parser = _build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or argparse usage errors
        return int(exc.code or 0)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except InputError as exc:
        _error(exc)
        _notes(exc)
        return 2
    except KeyboardInterrupt as exc:
        return _interrupted(exc, args.command)
    except BrokenPipeError:
        return _reader_gone()
    except OSError as exc:
        if exc.errno not in DISK_ERRORS:
            return internal_error()
        print(f"hbayes: error: {disk_error_text(exc, args)}", file=sys.stderr)
        _notes(exc)
        return 2
    except Exception:  # an internal error: a bug, so show where it happened
        return internal_error()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
