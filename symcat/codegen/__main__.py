"""``python -m symcat.codegen [generate|check|compile] [LIBRARY ...]`` (used by the Makefile)."""
from __future__ import annotations

import argparse
import sys
import time


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m symcat.codegen")
    parser.add_argument("action", choices=["generate", "check", "compile"])
    parser.add_argument("libraries", nargs="*", help="library names (default: all)")
    args = parser.parse_args(argv)
    from .generate import generate, stale_libraries, tool_mismatches
    from .kernels import library_names

    names = args.libraries or library_names()
    if args.action == "generate":
        t = time.perf_counter()
        generate(names)
        print(f"generated {len(names)} libraries in {time.perf_counter() - t:.1f} s")
        return 0
    if args.action == "check":
        stale = [n for n in stale_libraries() if n in names]
        if stale:
            print(f"stale generated code: {', '.join(stale)}; run `make generate` and commit generated/", file=sys.stderr)
            return 1
        mismatches = tool_mismatches()
        if mismatches:
            print(f"generated code made with {', '.join(mismatches)}: install the versions pinned in "
                  "pyproject.toml (`make install`), or change the pins and run `make generate`", file=sys.stderr)
            return 1
        print("generated code is current")
        return 0
    from .library import kernel_library

    for name in names:
        t = time.perf_counter()
        kernel_library(name)
        print(f"compiled {name} in {time.perf_counter() - t:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
