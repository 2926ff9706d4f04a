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
#: The reference run: a decade below the tightest row, atol 100x below its (the velocities' too).
REFERENCE = {"rtol": 1e-8, "atol": 1e-9, "atol_velocity": 1e-9}
REPEATS = 3
#: Steady running: the wall time per simulated second from STEADY[0] to STEADY[1] s of a run to
#: STEADY[1] s (the run's ``output_wall_s``), once the bogies have steered the start offset out.
STEADY = (2.0, 5.0)


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


def work_precision(profile="conical", velocity_factors=(1.0, 10.0)):
    """Largest wheelset lateral-displacement and wheel normal-force errors against
    :data:`REFERENCE` (one run for all rows), GGL stabilization (atol the model's default, rtol /
    10; the velocities' each of ``velocity_factors`` times it)."""
    base = {"profile": profile, "t_end": T_END, "n_out": 50, "lateral_offset_m": 0.002}
    nan = float("nan")
    try:
        ref_out = _run("vehicle", {**base, **REFERENCE})
    except SolverError as err:
        failed = "reference: " + str(err).split(":")[0]
        return [(profile, velocity_factors[0], REFERENCE["rtol"], nan, nan, nan, 0, 0, failed)]
    ref, ref_normal = _lateral(ref_out), _normal(ref_out)
    rows = []
    for velocity_factor, rtol in ((f, r) for f in velocity_factors for r in (1e-4, 1e-5, 1e-6, 1e-7)):
        walls, out, failed = [], None, ""
        for _ in range(REPEATS):
            try:
                out = _run("vehicle", {**base, "rtol": rtol, "atol_velocity": velocity_factor * 0.1 * rtol})
            except SolverError as err:
                failed = str(err).split(":")[0]
                break
            walls.append(out.summary["wall_s"])
        if failed:
            rows.append((profile, velocity_factor, rtol, nan, nan, nan, 0, 0, failed))
            continue
        err = float(np.abs(_lateral(out) - ref).max())
        err_n = float(np.abs(_normal(out) - ref_normal).max())
        rows.append((profile, velocity_factor, rtol, err, err_n, statistics.median(walls) / T_END, out.stats["nsteps"],
                     out.stats["contact_calls"], ""))
    return rows


def steady_running(profile, rtol):
    """Wall time per simulated second from ``STEADY[0]`` to ``STEADY[1]`` s and over the whole
    run (medians of :data:`REPEATS` runs, outputs every 20 ms), with the run's steps, calls and
    contact jumps."""
    parts, wholes, out = [], [], None
    for _ in range(REPEATS):
        try:
            out = _run("vehicle", {"profile": profile, "t_end": STEADY[1], "n_out": int(round(50 * STEADY[1])),
                                   "lateral_offset_m": 0.002, "rtol": rtol})
        except SolverError as err:
            return (profile, rtol, float("nan"), float("nan"), 0, 0, 0, str(err).split(":")[0])
        res = out.arrays["result"]
        i = int(np.searchsorted(res.t_s, STEADY[0] - 1e-9))
        parts.append((res.output_wall_s[-1] - res.output_wall_s[i]) / (res.t_s[-1] - res.t_s[i]))
        wholes.append(out.summary["wall_s"] / STEADY[1])
    return (profile, rtol, statistics.median(parts), statistics.median(wholes), out.stats["nsteps"],
            out.stats["contact_calls"], out.stats["contact_jumps"], "")


#: The complete scene's reference: generalized-alpha at a quarter of the finest row's step.
SCENE_REFERENCE = {"integrator": "generalized_alpha", "dt": 2.5e-4}
SCENE_ROWS = ([{"integrator": "idas", "rtol": r} for r in (1e-4, 1e-5, 1e-6)]
              + [{"integrator": "generalized_alpha", "dt": d} for d in (4e-3, 2e-3, 1e-3, 5e-4)])


def complete_scene(t_end=1.0):
    """Work-precision of the complete seed scene (``seo2005``) on both integrators: the largest
    contact-force difference (N) over ``t_end`` from :data:`SCENE_REFERENCE` (outputs every
    5 ms), the contact-force standard deviation's relative difference, and the wall time per
    simulated second (median of :data:`REPEATS`, the compiled step already in the cache)."""
    from symcat.pantograph.seo2005 import contact_history

    base = {"t_end": t_end, "n_out": 200}
    contact = load_model("seo2005").resolve({})["contact"]
    ref = _run("seo2005", {**base, **SCENE_REFERENCE})
    ref_force = contact_history(ref.arrays["result"], contact)[0]
    rows = []
    for setting in SCENE_ROWS:
        walls, out, failed = [], None, ""
        for _ in range(REPEATS):
            try:
                out = _run("seo2005", {**base, **setting})
            except SolverError as err:
                failed = str(err).split(":")[0]
                break
            walls.append(out.summary["wall_s"])
        label = f"IDAS rtol {setting['rtol']:g}" if "rtol" in setting else f"alpha dt {setting['dt'] * 1e3:g} ms"
        if failed:
            rows.append((label, float("nan"), float("nan"), float("nan"), 0, failed))
            continue
        force = contact_history(out.arrays["result"], contact)[0]
        std_err = abs(out.summary["contact_force_std_N"] / ref.summary["contact_force_std_N"] - 1)
        rows.append((label, float(np.abs(force - ref_force).max()), std_err, statistics.median(walls) / t_end,
                     out.summary["steps"], ""))
    return rows, ref.summary


def line_scene():
    """The seed's complete scene on the benchmark line (``seo2005_line``, 10 spans, 17 m/s):
    integration wall time per simulated second on generalized-alpha (2 s, median of
    :data:`REPEATS`: long enough to compile its step, :data:`~symcat.integrate.generalized_alpha.COMPILE_STEPS`)
    and on IDAS (0.05 s, once: it factorizes the whole line at each of its thousands of steps),
    with the raw contact force's mean and standard deviation of each run."""
    rows = []
    for integrator, t_end, repeats in (("generalized_alpha", 2.0, REPEATS), ("idas", 0.05, 1)):
        walls, out = [], None
        for _ in range(repeats):
            try:
                out = _run("seo2005_line", {"t_end": t_end, "integrator": integrator})
            except SolverError as err:
                rows.append((integrator, t_end, float("nan"), float("nan"), float("nan"), str(err).split(":")[0]))
                break
            walls.append(out.summary["integration_wall_s"])
        else:
            s = out.summary
            rows.append((integrator, t_end, statistics.median(walls) / t_end, s["contact_force_run_mean_N"],
                         s["contact_force_run_std_N"], ""))
    return rows


def section(report_dir=None) -> list[str]:
    rows = work_precision() + work_precision("s1002_uic60")
    steady = [steady_running(p, r) for p in ("s1002_uic60", "conical") for r in (1e-4, 1e-6)]
    scene_rows, seo = complete_scene()
    line_rows = line_scene()
    return [
        "## Seed vehicle (`vehicle`) and complete scene (`seo2005`)",
        "",
        f"17 m/s, linear creep, 2 mm initial offset, {T_END:g} s, GGL stabilization, atol = rtol / 10. Errors: largest "
        f"difference of the four wheelsets' lateral displacement and of the eight wheels' normal forces (about 57 kN) "
        f"from the same model at rtol {REFERENCE['rtol']:g}, atol {REFERENCE['atol']:g} (the velocities' too). Wall "
        "time per simulated "
        f"second: median of {REPEATS} runs (including post-processing of 50 outputs); calls: integrator calls "
        "(each followed by a contact check of every wheel). Faster than real time: a wall time below 1. Velocity atol: "
        "the velocities' absolute tolerance (m/s, rad/s; the model's `atol_velocity`, default 10 atol) as a multiple "
        "of atol.",
        "",
        "| profiles | velocity atol | rtol | lateral error [m] | normal force error [N] | wall per simulated s | steps "
        "| calls | failure |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---|",
        *[f"| {p} | {v:g} atol | {r:g} | {e:.2e} | {en:.3g} | {w:.2f} | {s} | {c} | {f} |"
          for p, v, r, e, en, w, s, c, f in rows],
        "",
        f"Steady running: the same vehicle run for {STEADY[1]:g} s from the 2 mm offset (outputs every 20 ms; the "
        "velocities' atol 10 times atol, the model's default); wall time "
        f"per simulated second from {STEADY[0]:g} to {STEADY[1]:g} s (from the result's `output_wall_s`), once the "
        f"bogies have steered the offset out, and over the whole run (with post-processing), medians of {REPEATS} "
        "runs; steps, calls and contact jumps of the whole run.",
        "",
        f"| profiles | rtol | wall per simulated s, {STEADY[0]:g}-{STEADY[1]:g} s | wall per simulated s, 0-{STEADY[1]:g} s "
        "| steps | calls | jumps | failure |",
        "|---|---:|---:|---:|---:|---:|---:|---|",
        *[f"| {p} | {r:g} | **{w:.2f}** | {wa:.2f} | {s} | {c} | {j} | {f} |" for p, r, w, wa, s, c, j, f in steady],
        "",
        "`seo2005` (vehicle + pantograph + 8-element beam3d wire, 17 m/s, 1 s) on both integrators: the largest "
        "contact-force difference from generalized-alpha at dt 0.25 ms (outputs every 5 ms; reference mean "
        f"{seo['contact_force_mean_N']:.2f} N, std {seo['contact_force_std_N']:.3f} N), the relative difference of the "
        f"contact force's standard deviation, and the wall time per simulated second (median of {REPEATS}, the "
        "compiled step already in the cache; IDAS with the GGL form's default tolerances, generalized-alpha "
        "stabilized, rho_inf 0.9).",
        "",
        "| integrator | contact force error [N] | std error | wall per simulated s | steps | failure |",
        "|---|---:|---:|---:|---:|---|",
        *[f"| {label} | {e:.3g} | {se:.1e} | {w:.2f} | {st} | {f} |" for label, e, se, w, st, f in scene_rows],
        "",
        "`seo2005_line` (the same vehicle and pantograph under the form-found benchmark catenary, 10 spans, 10 "
        "elements per span, 17 m/s, from the joint static equilibrium): integration wall time per simulated second "
        f"(generalized-alpha: 2 s, median of {REPEATS}, the model's dt 1 ms and tol 1e-7 m, its step compiled; IDAS: "
        "0.05 s, once), and "
        "the raw contact force over each run (the start of the passage).",
        "",
        "| integrator | simulated s | wall per simulated s | contact force mean [N] | std [N] | failure |",
        "|---|---:|---:|---:|---:|---|",
        *[f"| {i} | {t:g} | {w:.2f} | {m:.2f} | {sd:.3f} | {f} |" for i, t, w, m, sd, f in line_rows],
        "",
    ]


def alpha_scene_run(t_end: float = 1.0) -> dict:
    """One run of the complete scene (``seo2005``) on generalized-alpha (the model's dt 1 ms and
    tol 1e-8 m, ``t_end`` s): its wall time per simulated second (the result's ``wall_s``:
    integration and post-processing, not the model's build), Newton iterations, factorizations
    and contact-force statistics. ``python -m bench.vehicle alpha`` prints one run as JSON: run it
    from two checkouts in turn (old, new, old, ...) and compare medians, so that both see the
    same load of a shared machine."""
    out = _run("seo2005", {"t_end": t_end, "integrator": "generalized_alpha"})
    stats = out.arrays["result"].stats
    return {"wall_per_simulated_s": out.summary["wall_s"] / t_end, "steps": stats.get("steps"),
            "newton_iterations": stats.get("newton_iterations"), "factorizations": stats.get("factorizations"),
            "contact_force_mean_N": out.summary["contact_force_mean_N"],
            "contact_force_std_N": out.summary["contact_force_std_N"]}


if __name__ == "__main__" and sys.argv[1:] == ["alpha"]:
    import json

    print(json.dumps(alpha_scene_run()))
    sys.exit(0)

if __name__ == "__main__":
    lines = section()
    (Path(__file__).resolve().parent / "report" / "vehicle.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    sys.exit(0)
