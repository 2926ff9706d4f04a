"""The seed vehicle (``vehicle``) and the complete seed scene (``seo2005``): work-precision and
wall time per simulated second. ``python -m bench.vehicle`` prints the section and writes it to
``bench/report/vehicle.md``; ``make bench`` adds it to the report."""
from __future__ import annotations

import statistics
import sys
from pathlib import Path

import numpy as np

from symcat.errors import SolverError
from symcat.model import load_model
from symcat.vehicle import wheel_forces

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


def _normal(out):
    forces = wheel_forces(out.arrays["result"], out.arrays["layout"])
    return np.array([f["normal_N"] for f in forces.values()])


def work_precision(profile="conical"):
    """Largest wheelset lateral-displacement and wheel normal-force errors against
    :data:`REFERENCE`, GGL stabilization (atol the model's default, rtol / 10)."""
    base = {"profile": profile, "t_end": T_END, "n_out": 50, "lateral_offset_m": 0.002}
    nan = float("nan")
    try:
        ref_out = _run("vehicle", {**base, **REFERENCE})
    except SolverError as err:
        return [(profile, REFERENCE["rtol"], nan, nan, nan, 0, 0, "reference: " + str(err).split(":")[0])]
    ref, ref_normal = _lateral(ref_out), _normal(ref_out)
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
            rows.append((profile, rtol, nan, nan, nan, 0, 0, failed))
            continue
        err = float(np.abs(_lateral(out) - ref).max())
        err_n = float(np.abs(_normal(out) - ref_normal).max())
        rows.append((profile, rtol, err, err_n, statistics.median(walls) / T_END, out.stats["nsteps"],
                     out.stats["contact_calls"], ""))
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
        f"17 m/s, linear creep, 2 mm initial offset, {T_END:g} s, GGL stabilization, atol = rtol / 10. Errors: largest "
        f"difference of the four wheelsets' lateral displacement and of the eight wheels' normal forces (about 57 kN) "
        f"from the same model at rtol {REFERENCE['rtol']:g}, atol {REFERENCE['atol']:g}. Wall time per simulated "
        f"second: median of {REPEATS} runs (including post-processing of 50 outputs); calls: integrator calls "
        "(each followed by a contact check of every wheel). Faster than real time: a wall time below 1.",
        "",
        "| profiles | rtol | lateral error [m] | normal force error [N] | wall per simulated s | steps | calls | failure |",
        "|---|---:|---:|---:|---:|---:|---:|---|",
        *[f"| {p} | {r:g} | {e:.2e} | {en:.3g} | {w:.2f} | {s} | {c} | {f} |" for p, r, e, en, w, s, c, f in rows],
        "",
        f"`seo2005` (vehicle + pantograph + 8-element beam3d wire, 0.5 s at rtol 1e-6): **{seo_wall:.1f} s wall per "
        f"simulated second** (median of {REPEATS}); mean contact force {seo['contact_force_mean_N']:.1f} N.",
        "",
    ]


if __name__ == "__main__":
    lines = section()
    (Path(__file__).resolve().parent / "report" / "vehicle.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    sys.exit(0)
