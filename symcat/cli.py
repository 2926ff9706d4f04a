"""Command line: ``symcat run <model> [--set name=value ...] [--out DIR] [--summary FILE.json]``,
``symcat study <model> [--grid ...] [--random ...]`` (:mod:`symcat.study`), ``symcat list`` and
``symcat validate en50318``.

Whatever goes wrong ends in one line on stderr, never a traceback. Exit codes: 0 done,
1 a solver failure (the results so far are written), 2 bad input (nothing is written),
130 interrupted by Ctrl-C (the results so far are written).
"""
from __future__ import annotations

import argparse
import json
import logging
import sys

from .errors import ParameterError, RunStopped, SymcatError

EXIT_FAILED, EXIT_USAGE, EXIT_INTERRUPTED = 1, 2, 130

RUN_EPILOG = """\
--out DIR: a folder for plots, ParaView files and summary.json, created if missing. A folder
used by an earlier run is reused: the files that run wrote (listed in its summary.json) are
removed first, other files are kept.

A run that fails or is interrupted (Ctrl-C) writes what it computed up to then to --out and
--summary, marked "complete": false with the time and reason; exit 1 (failure) or 130 (Ctrl-C).
Bad input is refused before any work: exit 2, nothing written."""

STUDY_EPILOG = """\
The runs are the full factorial of the grids times --samples random samples (sample k has the same
random values at every grid point). A catenary model with deviation_seed (not given here) gets one
seed per sample, derived from --seed: `symcat study benchmark2015 --set dropper_length_sd_m=0.005
--samples 200 --seed 7` is the Monte Carlo study of dropper errors.

--out DIR: results.parquet (one row per run: parameters, every scalar summary entry, run_wall_s,
status, error), plots/ (each statistic against each swept parameter, 5/50/95 % bands), rows/ (one
file per finished run) and, with --keep-outputs, runs/<run_id>/. Rerunning the same study into DIR
runs only the runs not finished there; a DIR holding another study is refused.

A failed run is a row with its error and the study goes on (exit 1 at the end); a run whose worker
dies is run once more. Bad input (unknown parameter, empty or malformed range, unknown
distribution, unreachable scheduler) is refused before any work: exit 2, nothing written. Ctrl-C
keeps the finished runs (exit 130)."""


class _Parser(argparse.ArgumentParser):
    """argparse whose usage errors are one line (exit 2), like symcat's own."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"symcat: error: {message} (see `{self.prog} --help`)\n")


def _models_table() -> str:
    from .model import describe_models

    rows = describe_models()
    width = max((len(name) for name in rows), default=0)
    return "\n".join(f"  {name:<{width}}  {text}" for name, text in rows.items())


def _parser() -> tuple[argparse.ArgumentParser, argparse.ArgumentParser]:
    """The parser and its ``run`` subparser."""
    parser = _Parser(prog="symcat", description="symcat: pantograph/catenary multibody dynamics")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    run = sub.add_parser("run", help="run a model", add_help=False, formatter_class=argparse.RawDescriptionHelpFormatter,
                         epilog=RUN_EPILOG)
    run.add_argument("model", nargs="?", help="a model's name (`symcat list`) or the path of a model file")
    run.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="set a parameter")
    run.add_argument("--out", help="folder for plots, ParaView files and summary.json (see below)")
    run.add_argument("--summary", help="write the summary JSON here")
    run.add_argument("--quiet", action="store_true", help="do not print the summary")
    run.add_argument("-h", "--help", action="store_true", help="without a model: this help and the models; with "
                     "one: its parameters")
    study = sub.add_parser("study", help="run a model over grids and random samples (on Dask)",
                           formatter_class=argparse.RawDescriptionHelpFormatter, epilog=STUDY_EPILOG)
    study.add_argument("model", help="a model's name (`symcat list`) or the path of a model file")
    study.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="a parameter of every run")
    study.add_argument("--grid", action="append", default=[], metavar="NAME=START:STOP:STEP|NAME=V1,V2",
                       help="a swept parameter (both ends of a range included)")
    study.add_argument("--random", action="append", default=[], metavar="NAME=normal:MEAN:SD|NAME=uniform:LOW:HIGH",
                       help="a real parameter drawn for each sample")
    study.add_argument("--samples", type=int, default=1, metavar="N", help="random samples per grid point (1)")
    study.add_argument("--seed", type=int, default=0, metavar="S", help="seed of the samples (0)")
    study.add_argument("--scheduler", default="local", metavar="local|tcp://HOST:PORT",
                       help="a local cluster (default) or an existing Dask scheduler")
    study.add_argument("--workers", type=int, metavar="N", help="local workers (default: one per core); with "
                       "tcp://, wait for N workers")
    study.add_argument("--out", metavar="DIR", help="the study folder (see below)")
    study.add_argument("--keep-outputs", action="store_true", help="keep each run's files in DIR/runs/")
    study.add_argument("--quiet", action="store_true", help="no progress bar, no table on stdout")
    sub.add_parser("list", help="list the available models")
    val = sub.add_parser("validate", help="validate against a standard: en50318")
    val.add_argument("standard", choices=["en50318"])
    val.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="set a model parameter")
    val.add_argument("--out", help="folder for the plots and summaries of both runs")
    return parser, run


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser, run_parser = _parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="symcat: %(levelname)s: %(message)s")
    try:
        return _command(run_parser, args)
    except RunStopped as stop:
        print(f"symcat: {stop}", file=sys.stderr)
        return EXIT_INTERRUPTED if stop.interrupted else EXIT_FAILED
    except ParameterError as exc:
        print(f"symcat: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except SymcatError as exc:
        print(f"symcat: error: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        print("symcat: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def _command(run_parser, args) -> int:
    from .run_control import install_interrupt_handler

    if args.command == "list":
        print(_models_table())
        return 0
    if args.command == "study":
        return _study(args)
    if args.command == "run" and args.model is None:
        if args.help:
            print(run_parser.format_help().rstrip() + "\n\nmodels:\n" + _models_table())
            return 0
        raise ParameterError("run: give a model (one of the models of `symcat list`, or a model file's path)")
    install_interrupt_handler()
    if args.command == "run":
        from .run_output import OutputPaths

        # Refused within a second, before the model is even loaded; run_model checks again.
        OutputPaths(args.out, args.summary, ("--out", "--summary")).discard()
    from .model import load_model, run_model

    if args.command == "validate":
        from .validation import validate_en50318

        table, passed, _ = validate_en50318(_parse_sets(args.set), out=args.out)
        print(table)
        return 0 if passed else 1
    model = load_model(args.model)
    if args.help:
        print(model.help())
        return 0
    result = run_model(model, _parse_sets(args.set), out=args.out, summary_path=args.summary,
                       labels=("--out", "--summary"))
    if not args.quiet:
        print(json.dumps(result.summary, indent=1, default=lambda x: getattr(x, "tolist", lambda: str(x))()))
    return 0


def _study(args) -> int:
    from .study import run_study

    try:
        result = run_study(args.model, _parse_sets(args.set), args.grid, args.random, args.samples, args.seed,
                           args.scheduler, args.workers, args.out, args.keep_outputs, progress=not args.quiet)
    except KeyboardInterrupt:
        where = f"; the finished runs are in {args.out}: rerun the same command to resume" if args.out else ""
        print(f"symcat: interrupted{where}", file=sys.stderr)
        return EXIT_INTERRUPTED
    table = result.table
    if args.out is None and not args.quiet:
        print(table.to_csv(index=False), end="")
    where = f"; table {result.files[0]}" if result.files else ""
    print(f"symcat: study of {len(table)} runs: {result.ran} run now, {result.skipped} finished earlier, "
          f"{result.failed} failed{where}", file=sys.stderr)
    return EXIT_FAILED if result.failed else 0


def _parse_sets(items: list[str]) -> dict:
    """``--set name=value`` items as a dict; a name given twice is an error."""
    values = {}
    for item in items:
        if "=" not in item:
            raise ParameterError(f"--set {item!r}: expected name=value")
        name, value = item.split("=", 1)
        name = name.strip()
        if not name:
            raise ParameterError(f"--set {item!r}: expected name=value")
        if name in values:
            raise ParameterError(f"--set {name}: given twice ({name}={values[name]} and {name}={value.strip()}); "
                                 "give each parameter once")
        values[name] = value.strip()
    return values


if __name__ == "__main__":
    sys.exit(main())
