"""Benchmarks: `make bench` writes bench/report/README.md with PNG plots."""

import os

# Benchmarks measure the optimized model libraries (symcat.codegen.optimized), compiled at once.
os.environ.setdefault("SYMCAT_OPTIMIZE", "now")
