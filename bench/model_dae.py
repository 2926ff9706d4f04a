"""The compiled model DAE (:mod:`symcat.codegen.model_dae`) against CasADi's graph over the
kernels, on the seed vehicle: evaluation times of the residual and of its Jacobian, the wall
time of a whole run, for the -O0 library of a model's first run and the -Og one of later runs
(:mod:`symcat.codegen.optimized`), and what each costs to compile. ``python -m bench.model_dae``
prints the section; ``make bench`` adds it to the report."""
from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

import casadi as ca
import numpy as np

from symcat.assembly.multibody import MultibodyModel
from symcat.codegen.library import build_library, find_compiler
from symcat.codegen.model_dae import FLAGS, model_library, write_dae_c
from symcat.codegen.optimized import OPTIMIZE_ENV, OPTIMIZED_FLAGS
from symcat.dae.formulation import Formulation
from symcat.dae.initial import consistent_state
from symcat.scene import Scene
from symcat.simulation import simulate
from symcat.vehicle import add_vehicle
from symcat.wheelrail import profile_pair

REPEATS = 3
T_END = 0.3


def _vehicle():
    scene = Scene(gravity=(0.0, 0.0, -9.81))
    add_vehicle(scene, profile_pair("conical", 0.05), speed_ms=17.0, creep="linear", lateral_offset_m=0.002)
    return MultibodyModel(scene)


def _median_ms(fn, args, n=50):
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        for _ in range(n):
            fn(*args)
        times.append((time.perf_counter() - t0) / n * 1e3)
    return statistics.median(times)


#: The compiled tiers (:mod:`symcat.codegen.optimized`): name, ``SYMCAT_OPTIMIZE`` mode, flags.
TIERS = (("compiled, -O0 (first run)", "off", FLAGS), ("compiled, -Og (later runs)", "now", OPTIMIZED_FLAGS))


@contextmanager
def _mode(mode: str):
    """``$SYMCAT_OPTIMIZE`` set to ``mode`` within."""
    old = os.environ.get(OPTIMIZE_ENV)
    os.environ[OPTIMIZE_ENV] = mode
    try:
        yield
    finally:
        if old is None:
            del os.environ[OPTIMIZE_ENV]
        else:
            os.environ[OPTIMIZE_ENV] = old


def evaluation_times():
    """(name, residual ms, Jacobian ms) for the graph and each compiled tier, and the size."""
    model = _vehicle()
    form = Formulation(model, "augmented", "ggl", 10.0, False)
    x, z = consistent_state(form, 0.0)
    graph = form.dae_function()
    p = np.zeros(graph.size1_in(3))
    args = [0.0, x, z, p, ca.DM(0, 1)]
    functions = [("graph over the kernels (CasADi VM)", graph)]
    for name, mode, _ in TIERS:
        functions.append((name, ca.external(graph.name(), str(model_library(form.dae_function, graph, mode)))))
    rows = []
    for name, fn in functions:
        jac = fn.jacobian()
        jargs = args + [ca.DM.zeros(fn.sparsity_out(i)) for i in range(fn.n_out())]
        rows.append((name, _median_ms(fn, args, 500), _median_ms(jac, jargs, 50)))
    return rows, len(x) + len(z)


def compile_times():
    """Seconds to generate the vehicle's C, and to compile it with each tier's flags."""
    form = Formulation(_vehicle(), "augmented", "ggl", 10.0, False)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        c_path = write_dae_c(form.dae_function, form.dae_function().name(), Path(tmp))
        generated = "C generated (the graph expanded to SX over the kernels, differentiated, subexpressions merged)"
        out = [(generated, time.perf_counter() - t0)]
        for name, _, flags in TIERS:
            t0 = time.perf_counter()
            build_library(find_compiler(), flags, c_path, Path(tmp) / f"{flags[0][1:]}.so")
            out.append((f"compiled at {' '.join(flags[:-2])}", time.perf_counter() - t0))
    return out


def run_times():
    """(name, median wall time (s) per simulated second, IDAS steps) of the vehicle with the
    graph and with each compiled tier (steps equal up to rounding)."""
    out = []
    for name, compiled, mode in (("graph", False, "off"), *((n, True, m) for n, m, _ in TIERS)):
        walls, steps = [], 0
        with _mode(mode):
            for _ in range(REPEATS):
                t0 = time.perf_counter()
                res = simulate(_vehicle(), T_END, index="ggl", rtol=1e-7, n_out=3, progress=False, compiled=compiled)
                walls.append(time.perf_counter() - t0)
                steps = res.stats["nsteps"]
        out.append((name, statistics.median(walls) / T_END, steps))
    return out


def section(report_dir=None) -> list[str]:
    evals, n = evaluation_times()
    runs = run_times()
    compiles = compile_times()
    return [
        "## Compiled model DAE against the graph over the kernels (seed vehicle)",
        "",
        f"Augmented GGL form, {n} unknowns, conical profiles, linear creep, 2 mm offset, 17 m/s. Medians of "
        f"{REPEATS} repetitions. A model's library is compiled at -O0 on its first run and at -Og in the "
        "background for later runs (`symcat.codegen.optimized`; `SYMCAT_OPTIMIZE`).",
        "",
        "| residual evaluated by | residual [ms] | Jacobian [ms] |",
        "|---|---:|---:|",
        *[f"| {name} | {r:.3f} | {j:.3f} |" for name, r, j in evals],
        "",
        "| DAE | wall per simulated s | IDAS steps |",
        "|---|---:|---:|",
        *[f"| {name} | {w:.2f} | {s} |" for name, w, s in runs],
        "",
        f"Whole run ({T_END:g} s, rtol 1e-7, contact checks included): -O0 is {runs[0][1] / runs[1][1]:.1f}x "
        f"faster than the graph, -Og {runs[0][1] / runs[2][1]:.1f}x.",
        "",
        "| once per model | seconds |",
        "|---|---:|",
        *[f"| {name} | {t:.1f} |" for name, t in compiles],
        "",
    ]


if __name__ == "__main__":
    print("\n".join(section()))
    sys.exit(0)
