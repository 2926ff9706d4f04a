"""Write the C source of a case's compiled line steps (bench.wires_speed's cases) to a folder,
with the time to generate it. Usage: python -m bench.wires_source CASE FOLDER"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

os.environ["SYMCAT_OPTIMIZE"] = "off"


def main(case: str, folder: str) -> None:
    import symcat.integrate.alpha_chunk as ac
    from bench.wires_speed import CASES
    from symcat.codegen.library import symbolic_kernels
    from symcat.integrate.alpha_chunk_later import write_c
    from symcat.model import run_model

    captured = {}
    init = ac.CompiledSteps.__init__

    def init_(self, integ, *a, **k):
        init(self, integ, *a, **k)
        captured["cs"] = self
        raise KeyboardInterrupt  # (the model is built: no need to run it)

    ac.CompiledSteps.__init__ = init_
    p = dict(CASES[case], progress=False, paraview=False)
    try:
        run_model("benchmark2015", p)
    except BaseException:
        pass
    integ = captured["cs"].integ
    st = integ.stepper
    t0 = time.perf_counter()
    with symbolic_kernels():
        fns = ac.chunk_functions(st, integ.coef)
    t1 = time.perf_counter()
    path = write_c(fns, Path(folder))
    print(f"graph {t1 - t0:.1f} s, C {time.perf_counter() - t1:.1f} s: {path} ({path.stat().st_size / 1e6:.1f} MB)")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
