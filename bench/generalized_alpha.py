"""Generalized-alpha (fixed step) against IDAS on the same multibody scenes: error, steps, Newton
iterations, factorizations and wall time. ``python -m bench.generalized_alpha`` prints a
Markdown section (one run per row: the machine is shared, so walls are indicative; compare
ratios)."""
from __future__ import annotations

import importlib.util
import sys
import time

import numpy as np

from symcat.assembly.multibody import MultibodyModel
from symcat.integrate import simulate
from symcat.integrate.generalized_alpha import generalized_alpha
from symcat.model import model_path


def _module(name):
    spec = importlib.util.spec_from_file_location(f"bench_alpha_{name}", model_path(name))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _scene_factory(name, **overrides):
    module = _module(name)
    params = {**{p.name: p.default for p in module.PARAMETERS}, **overrides}
    window = params.get("window", 16)
    return lambda: MultibodyModel(module.build(params), window=window)


def _measure(make, t_end, n_out, reference, columns, **run):
    """One run (IDAS with ``rtol``, else generalized-alpha with ``dt``): a table row."""
    wall = time.perf_counter()
    if "rtol" in run:
        res = simulate(make(), t_end, rtol=run["rtol"], atol=run["rtol"] * 1e-2, n_out=n_out, progress=False)
        label, newton, factor = f"IDAS rtol {run['rtol']:g}", res.stats["nniters"], res.stats["nlinsetups"]
    else:
        res = generalized_alpha(make(), t_end, run["dt"], rho_inf=run.get("rho_inf", 0.9), n_out=n_out,
                                progress=False)
        label = f"alpha dt {run['dt'] * 1e3:g} ms, rho {run.get('rho_inf', 0.9):g}"
        newton, factor = res.stats["newton_iterations"], res.stats["factorizations"]
    wall = time.perf_counter() - wall
    errors = [f"{np.abs(pick(res) - pick(reference)).max():.2e}" for pick in columns.values()]
    return (f"| {label} | {res.stats['steps']} | {newton} | {factor} | {wall:.2f} | " + " | ".join(errors)
            + f" | {res.position_drift.max():.1e} |")


def section() -> list[str]:
    lines = ["## Generalized-alpha against IDAS", ""]
    cases = [
        ("double pendulum (rigid rods, revolute joints), 2 s", _scene_factory("pendulum"), 2.0,
         {"q (m, -)": lambda r: r.q, "v (m/s)": lambda r: r.v},
         [{"rtol": 1e-6}, {"rtol": 1e-8}, {"dt": 4e-3}, {"dt": 2e-3}, {"dt": 1e-3}], 1e-11),
        ("slider_on_wire, 16 cable3d elements, damping 1e-4 s, 1 s", _scene_factory("slider_on_wire", n_elements=16),
         1.0, {"s (m)": lambda r: r.s_m, "body z (m)": lambda r: r.q[:, -5]},
         [{"rtol": 1e-6}, {"dt": 2e-3}, {"dt": 1e-3}, {"dt": 5e-4}], 1e-9),
        ("slider_on_wire, 16 elements, undamped wire, 0.5 s",
         _scene_factory("slider_on_wire", n_elements=16, damping=0.0), 0.5,
         {"s (m)": lambda r: r.s_m, "body z (m)": lambda r: r.q[:, -5]},
         [{"rtol": 1e-6}, {"dt": 1e-3}, {"dt": 1e-3, "rho_inf": 0.6}, {"dt": 5e-4}], 1e-9),
    ]
    for title, make, t_end, columns, runs, ref_rtol in cases:
        wall = time.perf_counter()
        ref = simulate(make(), t_end, rtol=ref_rtol, atol=ref_rtol * 1e-2, n_out=20, progress=False)
        wall = time.perf_counter() - wall
        lines += [f"### {title}", "",
                  (f"Reference: IDAS rtol {ref_rtol:g} ({ref.stats['steps']} steps, {wall:.1f} s). Errors are "
                   "maxima over 20 outputs."), "",
                  "| run | steps | Newton iterations | factorizations | wall s | "
                  + " | ".join(f"error {c}" for c in columns) + " | max drift |",
                  "|---" * (6 + len(columns)) + "|"]
        for run in runs:
            lines.append(_measure(make, t_end, 20, ref, columns, **run))
            print(lines[-1], file=sys.stderr)
        lines.append("")
    return lines


if __name__ == "__main__":
    print("\n".join(section()))
