"""Command line: ``symcat run <model> [--set name=value ...] [--out DIR] [--summary FILE.json]``,
``symcat list`` and ``symcat validate en50318``.

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
