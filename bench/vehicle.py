"""The seed vehicle (``vehicle``) and the complete seed scene (``seo2005``): work-precision and
wall time per simulated second. ``python -m bench.vehicle`` prints the section; ``make bench``
adds it to the report."""
from __future__ import annotations

import statistics
import sys

import numpy as np

from symcat.errors import SolverError
from symcat.model import load_model

T_END = 1.0
#: The reference run: a decade below the tightest row, atol 100x below its.
REFERENCE = {"rtol": 1e-8, "atol": 1e-9}
REPEATS = 3


def _run(name, params):
    model = load_model(name)
    resolved = model.resolve(params)
    resolved["progress"] = False  # not a model parameter: the bench prints no progress bars
    return model.run(resolved)


def _lateral(out):
    res = out.arrays["result"]
    return np.array([res.coordinate(f"{w}.y") for w in ("b1_ws1", "b1_ws2", "b2_ws1", "b2_ws2")])


def work_precision(profile="conical"):
    """Largest wheelset lateral-displacement error against :data:`REFERENCE`, GGL stabilization
    (atol the model's default, rtol / 10)."""
    base = {"profile": profile, "t_end": T_END, "n_out": 50, "lateral_offset_m": 0.002}
    try:
        ref = _lateral(_run("vehicle", {**base, **REFERENCE}))
    except SolverError as err:
        return [(profile, REFERENCE["rtol"], float("nan"), float("nan"), 0, "reference: " + str(err).split(":")[0])]
    rows = []
    for rtol in (1e-4, 1e-5, 1e-6, 1e-7):
        walls, out, failed = [], None, ""
        for _ in range(REPEATS):
            try:
                out = _run("vehicle", {**base, "rtol": rtol})
            except SolverError as err:
                failed = str(err).split(":")[0]
                break
            walls.append(out.summary["wall_s"])
        if failed:
            rows.append((profile, rtol, float("nan"), float("nan"), 0, failed))
            continue
        err = float(np.abs(_lateral(out) - ref).max())
        rows.append((profile, rtol, err, statistics.median(walls) / T_END, out.stats["nsteps"], ""))
    return rows


def complete_scene():
    walls, out = [], None
    for _ in range(REPEATS):
        try:
            out = _run("seo2005", {"t_end": 0.5})
        except SolverError as err:
            return float("nan"), {"contact_force_mean_N": float("nan"), "failure": str(err).split(":")[0]}
        walls.append(out.summary["wall_s"])
    return statistics.median(walls) / 0.5, out.summary


def section(report_dir=None) -> list[str]:
    rows = work_precision() + work_precision("s1002_uic60")
    seo_wall, seo = complete_scene()
    return [
        "## Seed vehicle (`vehicle`) and complete scene (`seo2005`)",
        "",
        f"17 m/s, linear creep, 2 mm initial offset, {T_END:g} s, GGL stabilization, atol = rtol / 10. Error: largest "
        f"difference of the four wheelsets' lateral displacement from the same model at rtol {REFERENCE['rtol']:g}, atol {REFERENCE['atol']:g}. Wall time "
        f"per simulated second: median of {REPEATS} runs (including post-processing of 50 outputs).",
        "",
        "| profiles | rtol | error [m] | wall per simulated s | steps | failure |",
        "|---|---:|---:|---:|---:|---|",
        *[f"| {p} | {r:g} | {e:.2e} | {w:.2f} | {s} | {f} |" for p, r, e, w, s, f in rows],
        "",
        f"`seo2005` (vehicle + pantograph + 8-element beam3d wire, 0.5 s at rtol 1e-6): **{seo_wall:.1f} s wall per "
        f"simulated second** (median of {REPEATS}); mean contact force {seo['contact_force_mean_N']:.1f} N.",
        "",
    ]


if __name__ == "__main__":
    print("\n".join(section()))
    sys.exit(0)
