"""Build a case's optimized library of compiled line steps now, in this process (no
background job: on a shared machine another's job holds the cache's compile slot).
Usage: python -m bench.wires_build CASE"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

os.environ["SYMCAT_OPTIMIZE"] = "background"


def main(case: str) -> None:
    import symcat.integrate.alpha_chunk as ac
    from bench.wires_speed import CASES
    from symcat.codegen.library import build_library, find_compiler, symbolic_kernels
    from symcat.codegen.model_dae import cached_library
    from symcat.integrate.alpha_chunk_later import write_c
    from symcat.model import run_model

    captured = {}
    init = ac.CompiledSteps.__init__

    def init_(self, integ, *a, **k):
        init(self, integ, *a, **k)
        captured["cs"] = self
        raise KeyboardInterrupt

    ac.CompiledSteps.__init__ = init_
    try:
        run_model("benchmark2015", dict(CASES[case], progress=False, paraview=False))
    except BaseException:
        pass
    integ = captured["cs"].integ
    st = integ.stepper
    key = ac.library_key(st, integ.coef)
    target = cached_library("alpha_chunk", key.encode(), ac.OPTIMIZED_FLAGS)
    if target.exists():
        print(case, "exists", target)
        return
    t0 = time.perf_counter()
    with symbolic_kernels():
        fns = ac.chunk_functions(st, integ.coef)
    with tempfile.TemporaryDirectory() as tmp:
        c = write_c(fns, Path(tmp))
        t1 = time.perf_counter()
        build_library(find_compiler(), ac.OPTIMIZED_FLAGS, c, target)
    print(case, f"generated {t1 - t0:.1f} s, compiled {time.perf_counter() - t1:.1f} s:", target)


if __name__ == "__main__":
    main(sys.argv[1])
