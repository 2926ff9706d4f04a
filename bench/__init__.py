"""Benchmarks: `make bench` writes bench/report/README.md with PNG plots."""
