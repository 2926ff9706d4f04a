"""Command line: ``symcat run <model> [--set name=value ...] [--out DIR] [--summary FILE.json]``,
``symcat list`` and ``symcat validate en50318``."""
from __future__ import annotations

import argparse
import json
import logging
import sys

from .errors import SymcatError


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="symcat", description="symcat: pantograph/catenary multibody dynamics")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a model", add_help=False)
    run.add_argument("model")
    run.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="set a parameter")
    run.add_argument("--out", help="folder for plots, ParaView files and summary.json")
    run.add_argument("--summary", help="write the summary JSON here")
    run.add_argument("--quiet", action="store_true", help="do not print the summary")
    run.add_argument("-h", "--help", action="store_true", help="list the model's parameters")
    sub.add_parser("list", help="list the available models")
    val = sub.add_parser("validate", help="validate against a standard: en50318")
    val.add_argument("standard", choices=["en50318"])
    val.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="set a model parameter")
    val.add_argument("--out", help="folder for the plots and summaries of both runs")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s: %(message)s")
    try:
        from .model import available_models, load_model, run_model

        if args.command == "list":
            print("\n".join(available_models()))
            return 0
        if args.command == "validate":
            from .validation import validate_en50318

            table, passed, _ = validate_en50318(_parse_sets(args.set), out=args.out)
            print(table)
            return 0 if passed else 1
        model = load_model(args.model)
        if args.help:
            print(model.help())
            return 0
        result = run_model(model, _parse_sets(args.set), out=args.out, summary_path=args.summary)
        if not args.quiet:
            print(json.dumps(result.summary, indent=1, default=lambda x: getattr(x, "tolist", lambda: str(x))()))
        return 0
    except SymcatError as exc:
        print(f"symcat: error: {exc}", file=sys.stderr)
        partial = getattr(exc, "partial", None)
        if partial is not None:
            print("symcat: the partial result was kept in the exception (Python API)", file=sys.stderr)
        return 2


def _parse_sets(items: list[str]) -> dict:
    values = {}
    for item in items:
        if "=" not in item:
            raise SymcatError(f"--set {item!r}: expected name=value")
        name, value = item.split("=", 1)
        values[name.strip()] = value.strip()
    return values


if __name__ == "__main__":
    sys.exit(main())
