"""Pantograph/catenary speed against error: benchmark2015 at 320 km/h.

Statistics against elements per span, time step and Newton tolerance, with the wall time per
simulated second of each run; the cost growth with the number of spans. Run alone with
``python -m bench.pantograph`` (writes ``bench/report/pantograph.md``); ``make bench`` includes it.
"""
from __future__ import annotations

import os
import statistics
import time
from pathlib import Path
from unittest import mock

import numpy as np

from symcat.catenary import benchmark2015, find_form
from symcat.interaction.passage import run_passage
from symcat.pantograph import benchmark2015_pantograph

KEYS = ("contact_force_mean_N", "contact_force_std_N", "contact_force_max_N", "contact_force_min_N",
        "support_uplift_max_m", "contact_loss_percent")
SPEED = 320 / 3.6
#: The model benchmark2015's static convention (the benchmark's published dropper lengths).
CONVENTION = dict(steady_arm="free", dropper_statics="strings")


def _run(elements=60, dt=1e-3, tol=1e-4, n_spans=10, t_end=None, repeats=1, wires="nonlinear"):
    design = benchmark2015(n_spans, **CONVENTION)
    form = find_form(design, elements)
    walls, res = [], None
    for _ in range(repeats):
        res = run_passage(design, [benchmark2015_pantograph(320)], SPEED, form=form, dt=dt, tol=tol, t_end=t_end,
                          progress=False, wires=wires)
        walls.append(res.record.stats["wall_s"])  # static placement and time integration
    wall = statistics.median(walls)
    stats = res.statistics[0] if res.statistics else {}
    return stats, wall / res.simulated_s, res


def _row(label, stats, ratio, ref):
    cells = []
    for k in KEYS:
        v = stats[k]
        if k in ("contact_force_std_N", "contact_force_mean_N") and ref is not None:
            cells.append(f"{v:.2f} ({100 * (v / ref[k] - 1):+.1f} %)")
        elif k == "support_uplift_max_m":
            cells.append(f"{1e3 * v:.1f} mm")
        else:
            cells.append(f"{v:.2f}")
    return f"| {label} | " + " | ".join(cells) + f" | {ratio:.2f} |"


def hard_cases() -> list[str]:
    """The issue's hard cases run through a whole passage: near the wave speed, two
    pantographs, more than 1 km of line, an overlap between tension sections."""
    rows = []
    cases = [
        ("0.9 x wave speed (413.6 km/h), uplift 169 N", dict(speed_kmh=413.6, n_spans=10, pantographs=1)),
        ("two pantographs 200 m apart, 320 km/h", dict(speed_kmh=320.0, n_spans=13, pantographs=2)),
        ("1.16 km passage (24 spans, 20 analysed), 320 km/h", dict(speed_kmh=320.0, n_spans=24, pantographs=1,
                                                                  analysis_spans=20)),
        ("overlap of two 10-span sections (3 spans analysed), 320 km/h",
         dict(speed_kmh=320.0, n_spans=10, sections=2, pantographs=1, analysis_spans=3)),
        ("same 3 spans of a 17-span single section, 320 km/h", dict(speed_kmh=320.0, n_spans=17, pantographs=1,
                                                                   analysis_spans=3)),
    ]
    for label, c in cases:
        design = benchmark2015(c["n_spans"], **CONVENTION).with_(n_sections=c.get("sections", 1))
        panto = benchmark2015_pantograph(320)
        t0 = time.perf_counter()
        res = run_passage(design, [panto] * c["pantographs"], c["speed_kmh"] / 3.6, elements_per_span=60, dt=1e-3,
                          tol=1e-4, analysis_spans=c.get("analysis_spans", 2), progress=False)
        wall = time.perf_counter() - t0
        rec = res.record
        balance = rec.energy_balance()
        slack = int(np.sum(np.diff((rec.dropper_tension_N <= 0).astype(int), axis=0) == 1))
        for p, stats in enumerate(res.statistics):
            rows.append(f"| {label} | {('leading', 'trailing')[p] if len(res.statistics) > 1 else 1} | {stats['contact_force_mean_N']:.1f} | {stats['contact_force_std_N']:.1f} | "
                        f"{stats['contact_force_min_N']:.1f} | {stats['contact_loss_percent']:.2f} | "
                        f"{1e3 * stats['support_uplift_max_m']:.1f} | {slack} | "
                        f"{np.abs(balance['error_J']).max():.3f} / {balance['work_scale_J']:.1f} | "
                        f"{rec.stats['halvings']} | {wall / res.simulated_s:.2f} |")
    return [
        "### Hard cases (60 elements/span, dt 1 ms, penalty contact)",
        "",
        "| case | pantograph | mean [N] | std [N] | min [N] | loss [%] | uplift [mm] | slack-dropper events | "
        "energy error / contact work [J] | step halvings | wall / simulated |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        "The energy error includes the numerical dissipation of generalized-alpha (rho_inf 0.8); with "
        "rho_inf = 1 the balance closes to 0.2 % of the contact work (tests/interaction).",
        "",
    ]


def _scene_run(n_spans: int) -> tuple[int, float]:
    """Coordinates and wall per simulated second of benchmark2015 on the multibody path
    (``pantograph=lumped``), ``n_spans`` spans, 0.5 s simulated."""
    from symcat.model import run_model

    out = run_model("benchmark2015", {"pantograph": "lumped", "n_spans": n_spans, "t_end": 0.5,
                                      "progress": False, "paraview": False})
    return out.summary["n_coordinates"], out.summary["wall_per_simulated_s"]


def unified_paths(repeats: int = 3) -> list[str]:
    """The model benchmark2015 on the interaction path (``pantograph=lumped_interaction``) and on
    the shared multibody path (``lumped``, the default: the same pantograph as scene bodies,
    generalized-alpha on the catenary scene), interleaved runs, medians of ``repeats``: statistics apart and the
    ratio of wall per simulated second (static placement and time integration on both paths),
    the multibody path's with its compiled steps (built in the background after a first run)
    and, in the last column, with its Python steps (a first run on a machine)."""
    from symcat.model import run_model

    cases = [("defaults (60 elements/span, dt 1 ms, tol 1e-4 m)", {}),
             ("1 % settings (50 elements/span, dt 2 ms, tol 1e-3 m, linear wires)",
              dict(elements_per_span=50, dt=2e-3, tol=1e-3, wires="linear")),
             ("overlap of two 10-span sections (3 spans analysed)", dict(tension_sections=2, analysis_spans=3)),
             ("two pantographs 200 m apart, 275 km/h", dict(n_pantographs=2, speed_kmh=275.0))]
    lines = ["| case | mean apart [N] | std apart [N] | max apart [N] | interaction [s/s] | multibody [s/s] | "
             "ratio | multibody, Python steps [s/s] |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    from symcat.codegen.optimized import wait_for_background

    for label, params in cases:
        walls = {"lumped_interaction": [], "lumped": []}
        stats = {}
        # A line's compiled steps are built in the background after its first run, which steps
        # in Python: the timed runs use them, the last column is the Python steps'.
        # (the users' default mode, background: the bench's own, "now", compiles a line's steps
        # only for runs of CHUNK_COMPILE_STEPS steps or more)
        multibody = {**params, "pantograph": "lumped", "progress": False, "paraview": False}
        with mock.patch.dict(os.environ, {"SYMCAT_OPTIMIZE": "background"}):
            run_model("benchmark2015", multibody)
            wait_for_background()
        with mock.patch.dict(os.environ, {"SYMCAT_OPTIMIZE": "off"}):  # a line's long run then steps in Python
            python_steps = run_model("benchmark2015", multibody).summary["wall_per_simulated_s"]
        for _ in range(repeats):
            for path in walls:
                with mock.patch.dict(os.environ, {"SYMCAT_OPTIMIZE": "background"}):
                    out = run_model("benchmark2015", {**params, "pantograph": path, "progress": False,
                                                      "paraview": False})
                walls[path].append(out.summary["wall_per_simulated_s"])
                summary = out.summary.get("pantograph_1", out.summary)
                stats[path] = {k: summary[k] for k in ("contact_force_mean_N", "contact_force_std_N",
                                                       "contact_force_max_N")}
        a, b = stats["lumped_interaction"], stats["lumped"]
        wa, wb = statistics.median(walls["lumped_interaction"]), statistics.median(walls["lumped"])
        lines.append(f"| {label} | {abs(b['contact_force_mean_N'] - a['contact_force_mean_N']):.3f} | "
                     f"{abs(b['contact_force_std_N'] - a['contact_force_std_N']):.3f} | "
                     f"{abs(b['contact_force_max_N'] - a['contact_force_max_N']):.2f} | {wa:.2f} | {wb:.2f} | "
                     f"{wb / wa:.2f} | {python_steps:.2f} |")
    return lines


def section(report_dir: Path) -> list[str]:
    header = ["| run | mean [N] | std [N] | max [N] | min [N] | uplift | loss [%] | wall / simulated |",
              "|---|---:|---:|---:|---:|---:|---:|---:|"]
    mesh = [(e, *_run(elements=e)) for e in (10, 20, 40, 60, 80, 120)]
    ref = mesh[-1][1]
    steps = [(dt, *_run(dt=dt)) for dt in (4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4)]
    ref_dt = steps[-1][1]
    tols = [(tol, *_run(tol=tol)) for tol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-8)]
    models = [(w, *_run(wires=w, repeats=3)) for w in ("nonlinear", "linear")]
    fast = [(w, *_run(elements=50, dt=2e-3, tol=1e-3, wires=w, repeats=3)) for w in ("nonlinear", "linear")]
    spans = [(n, *_run(n_spans=n, t_end=0.5, repeats=3)) for n in (10, 20, 40)]
    scene_spans = {n: _scene_run(n) for n in (10, 20, 40, 80)}
    hard = hard_cases()
    unified = unified_paths()
    lines = [
        "## Pantograph/catenary: benchmark2015 at 320 km/h (one pantograph, penalty contact)",
        "",
        "Statistics of the 20 Hz filtered contact force over spans 5-6 (of 10); in brackets the change "
        "against the finest run of the same study. Wall time per simulated second of the passage "
        "(static placement and time integration; form finding excluded; one run each unless stated, the "
        "machine is noisy).",
        "",
        "### Elements per span (dt 1 ms, tol 1e-4 m)",
        "",
        *header,
        *[_row(f"{e} elements/span", s, r, ref) for e, s, r, _ in mesh],
        "",
        "### Time step (60 elements/span)",
        "",
        *header,
        *[_row(f"dt {1e3 * dt:g} ms", s, r, ref_dt) for dt, s, r, _ in steps],
        "",
        "### Newton tolerance (60 elements/span, dt 1 ms)",
        "",
        *header,
        *[_row(f"tol {tol:g} m", s, r, tols[-1][1]) for tol, s, r, _ in tols],
        "",
        "### Wire model at the default discretization (60 elements/span, dt 1 ms, tol 1e-4 m, median of 3)",
        "",
        *header,
        *[_row(f"{w} wires", s, r, models[0][1]) for w, s, r, _ in models],
        "",
        "### Faster than real time: 50 elements/span, dt 2 ms, tol 1e-3 m (median of 3; change against 120 elements/span at 1 ms)",
        "",
        *header,
        *[_row(f"{w} wires", s, r, ref) for w, s, r, _ in fast],
        "",
        "Each error source alone stays within about 1 % here (mesh: 40 -> 60 elements/span takes sigma from +1.3 % to "
        "+0.4 %; step: 2 ms is -0.7 %; tol 1e-3 m: +0.2 %). Run it with `symcat run benchmark2015 --set "
        "elements_per_span=50 --set dt=0.002 --set tol=0.001 --set wires=linear`.",
        "",
        "Target: at most 1 s of wall time per simulated second at the discretization converged to 1 %. "
        "The run continues 0.2 s past the section so that the zero-phase filter has settled there (without "
        "this, its edge treatment bent the end of the section and made the mean drift as O(dt)). "
        "Per step the cost is one to two evaluations of the wire forces (0.33 ms at 60 elements/span, 2400 "
        "elements), one or two banded solves (0.15 ms each) and about 0.5 ms of Python.",
        "",
        "### Cost against line length (60 elements/span, dt 1 ms, 0.5 s simulated, median of 3)",
        "",
        "Interaction path (`pantograph=lumped_interaction`) and the shared multibody path (`pantograph=lumped`, one run "
        "each; its coordinates include the pantograph's bodies). The target of issue 28: 80 spans at most 9 times "
        "10 spans on the multibody path.",
        "",
        "| spans | coordinates | interaction: wall / simulated | multibody: coordinates | multibody: wall / simulated |",
        "|---:|---:|---:|---:|---:|",
        *[f"| {n} | {res.line.n} | {r:.2f} | {scene_spans[n][0]} | {scene_spans[n][1]:.2f} |"
          for n, s, r, res in spans],
        f"| 80 | | | {scene_spans[80][0]} | {scene_spans[80][1]:.2f} |",
        "",
        f"Multibody path, 80 spans against 10: {scene_spans[80][1] / scene_spans[10][1]:.2f} times.",
        "",
        *hard,
        "",
        "### The shared multibody path against the interaction path (model benchmark2015, 320 km/h unless stated)",
        "",
        "The lumped pantograph as scene bodies under the catenary scene, integrated by the shared generalized-alpha "
        "(`pantograph=lumped`, the models' default), against the interaction path (`pantograph=lumped_interaction`): "
        "statistics apart (the "
        "last run of each) and wall time per simulated second, static placement and time integration on both paths "
        "(the multibody path's static solve, a step of its own, is counted since 2026-11-27; medians of 3 "
        "interleaved runs; ratio multibody / interaction).",
        "",
        *unified,
    ]
    return lines


def main() -> None:
    report = Path(__file__).resolve().parent / "report"
    report.mkdir(parents=True, exist_ok=True)
    lines = section(report)
    (report / "pantograph.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
