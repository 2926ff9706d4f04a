"""Pantograph/catenary speed against error: benchmark2015 at 320 km/h on the models' default path
(the lumped pantograph as scene bodies on the shared multibody path, ``pantograph=lumped``).

Statistics against elements per span, time step and Newton tolerance, with the wall time per
simulated second of each run; the cost growth with the number of spans; the issue's hard cases;
and the speed against the earlier interaction path, run at the last commit that has it
(:data:`INTERACTION_COMMIT`, from a git worktree of this repository, in a subprocess) so that
the ratios still come from one bench run. Run alone with ``python -m bench.pantograph`` (writes
``bench/report/pantograph.md``); ``make bench`` includes it.
"""
from __future__ import annotations

import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from unittest import mock

from symcat.model import run_model

KEYS = ("contact_force_mean_N", "contact_force_std_N", "contact_force_max_N", "contact_force_min_N",
        "support_uplift_max_m", "contact_loss_percent")
#: The last commit with the interaction path (CoupledLine, run_passage; ``pantograph=lumped_interaction``).
INTERACTION_COMMIT = "fe59032"
REPO = Path(__file__).resolve().parents[1]


def _model(params: dict) -> dict:
    """Summary of the model benchmark2015 (320 km/h unless ``params`` say otherwise), no files."""
    return run_model("benchmark2015", {"speed_kmh": 320.0, "progress": False, "paraview": False, **params}).summary


def _pantograph_stats(summary: dict, k: int = 1) -> dict:
    """The statistics of pantograph ``k`` (1: the leading one) in a model summary."""
    return summary.get(f"pantograph_{k}", summary)


def _run(elements=60, dt=1e-3, tol=1e-4, n_spans=10, t_end=None, repeats=1, wires="nonlinear", compiled=True):
    """Statistics, wall per simulated second (median of ``repeats``: static placement and time
    integration, form finding excluded) and summary of one configuration of the model.

    ``compiled``: the line's compiled steps, built first as a user's first run builds them (in
    the background, ``SYMCAT_OPTIMIZE=background``), so that every row of a table times the
    same path (a library cached for one configuration and not another made the rows of one
    table compare compiled with Python steps); False: the Python steps (a line's first run)."""
    params = dict(elements_per_span=elements, dt=dt, tol=tol, n_spans=n_spans, wires=wires,
                  t_end=-1.0 if t_end is None else t_end)
    if compiled:
        _warm(params)
    walls, summary = [], None
    with mock.patch.dict(os.environ, {} if compiled else {"SYMCAT_OPTIMIZE": "off"}):
        for _ in range(repeats):
            summary = _model(params)
            walls.append(summary["wall_per_simulated_s"])
    return {k: summary.get(k) for k in KEYS}, statistics.median(walls), summary


def _warm(params: dict) -> None:
    """Build the line's compiled steps for ``params`` as a first run does (a short run under
    ``SYMCAT_OPTIMIZE=background`` leaves the build to a background job) and wait for them."""
    from symcat.codegen.optimized import wait_for_background

    with mock.patch.dict(os.environ, {"SYMCAT_OPTIMIZE": "background"}):
        _model({**params, "t_end": 0.05})
        wait_for_background()


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


#: The issue's hard cases: label -> model parameters (the uplift the EN 50367 target at 320 km/h).
HARD_CASES = [
    ("0.9 x wave speed (413.6 km/h), uplift 169 N", dict(speed_kmh=413.6, n_spans=10)),
    ("two pantographs 200 m apart, 320 km/h", dict(n_spans=13, n_pantographs=2)),
    ("1.16 km passage (24 spans, 20 analysed), 320 km/h", dict(n_spans=24, analysis_spans=20)),
    ("overlap of two 10-span sections (3 spans analysed), 320 km/h",
     dict(n_spans=10, tension_sections=2, analysis_spans=3)),
    ("same 3 spans of a 17-span single section, 320 km/h", dict(n_spans=17, analysis_spans=3)),
]


def hard_cases(cases=None) -> list[str]:
    """The issue's hard cases run through a whole passage of the model: near the wave speed, two
    pantographs, more than 1 km of line, an overlap between tension sections (``cases``:
    (label, parameters) pairs, default :data:`HARD_CASES`)."""
    rows = []
    uplift = 0.00097 * 320.0**2 + 70.0  # N, at every speed here
    for label, params in cases or HARD_CASES:
        run = run_model("benchmark2015", {"speed_kmh": 320.0, "uplift_N": uplift, "progress": False,
                                          "paraview": False, **params})
        s = run.summary
        halvings = run.arrays["result"].record.stats["halvings"]
        n = params.get("n_pantographs", 1)
        for p in range(n):
            stats = _pantograph_stats(s, p + 1)
            rows.append(f"| {label} | {('leading', 'trailing')[p] if n > 1 else 1} | "
                        f"{stats['contact_force_mean_N']:.1f} | {stats['contact_force_std_N']:.1f} | "
                        f"{stats['contact_force_min_N']:.1f} | {stats['contact_loss_percent']:.2f} | "
                        f"{1e3 * stats['support_uplift_max_m']:.1f} | {s['slack_dropper_events']} | "
                        f"{s['energy_balance_error_J']:.3f} / {s['contact_work_J']:.1f} | {halvings} | "
                        f"{s['wall_per_simulated_s']:.2f} |")
    return [
        "### Hard cases (model benchmark2015: 60 elements/span, dt 1 ms, penalty contact)",
        "",
        "| case | pantograph | mean [N] | std [N] | min [N] | loss [%] | uplift [mm] | slack-dropper events | "
        "energy error / contact work [J] | step halvings | wall / simulated |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        "The energy error includes the numerical dissipation of generalized-alpha (rho_inf 0.8); with "
        "rho_inf = 1 the balance closes to second order in the step (tests/dynamics/test_energy_balance.py).",
        "",
    ]


@contextlib.contextmanager
def interaction_checkout(commit: str = INTERACTION_COMMIT):
    """A detached git worktree of this repository at ``commit`` in a temporary folder, removed
    afterwards: the interaction path's code, for :func:`interaction_model`."""
    folder = Path(tempfile.mkdtemp(prefix=f"symcat-{commit}-"))
    subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", "--quiet", str(folder), commit],
                   check=True)
    try:
        yield folder
    finally:
        subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(folder)], check=False)


#: Runs the model on the checkout's code and prints its summary as JSON (stdout's last line).
_SUBPROCESS = ("import json, sys\n"
               "from symcat.model import run_model\n"
               "summary = run_model('benchmark2015', json.loads(sys.argv[1])).summary\n"
               "print(json.dumps(summary, default=str))\n")


def model_in_subprocess(checkout: Path, params: dict, optimize: str = "background") -> dict:
    """Summary of the model benchmark2015 with ``params`` (320 km/h unless they say otherwise),
    run by this Python in a fresh process on the code of ``checkout`` with
    ``SYMCAT_OPTIMIZE=optimize``: as a user runs it (``symcat run``), nothing kept from earlier
    runs but the disk cache."""
    params = {"speed_kmh": 320.0, **params, "progress": False, "paraview": False}
    env = {**os.environ, "PYTHONPATH": str(checkout), "SYMCAT_OPTIMIZE": optimize}
    done = subprocess.run([sys.executable, "-c", _SUBPROCESS, json.dumps(params)], cwd=checkout, env=env,
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"benchmark2015 at {checkout.name} failed with {params}:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def interaction_model(checkout: Path, params: dict, optimize: str = "background") -> dict:
    """:func:`model_in_subprocess` on the interaction path (``pantograph=lumped_interaction``) of
    ``checkout`` (:func:`interaction_checkout`)."""
    return model_in_subprocess(checkout, {**params, "pantograph": "lumped_interaction"}, optimize)


#: The cases of the speed comparison: label -> model parameters.
UNIFIED_CASES = [
    ("defaults (60 elements/span, dt 1 ms, tol 1e-4 m)", {}),
    ("1 % settings (50 elements/span, dt 2 ms, tol 1e-3 m, linear wires)",
     dict(elements_per_span=50, dt=2e-3, tol=1e-3, wires="linear")),
    ("overlap of two 10-span sections (3 spans analysed)", dict(tension_sections=2, analysis_spans=3)),
    ("two pantographs 200 m apart, 275 km/h", dict(n_pantographs=2, speed_kmh=275.0)),
]


def unified_paths(repeats: int = 3, cases=None) -> list[str]:
    """The model benchmark2015 on the interaction path (``pantograph=lumped_interaction`` at
    :data:`INTERACTION_COMMIT`, :func:`interaction_model`) and on the shared multibody path
    (``lumped``, the default: the same pantograph as scene bodies, generalized-alpha on the
    catenary scene), interleaved runs in this bench run, each in a fresh process, medians of
    ``repeats``: statistics apart and the ratio of wall per simulated second (static placement
    and time integration on both paths), the multibody path's with its compiled steps (built in the background after a
    first run) and, in the last column, with its Python steps (a first run on a machine).
    ``cases``: (label, parameters) pairs (default :data:`UNIFIED_CASES`)."""
    from symcat.codegen.optimized import wait_for_background

    lines = ["| case | mean apart [N] | std apart [N] | max apart [N] | interaction [s/s] | multibody [s/s] | "
             "ratio | multibody, Python steps [s/s] |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    keys = ("contact_force_mean_N", "contact_force_std_N", "contact_force_max_N")
    with interaction_checkout() as checkout:
        for label, params in cases or UNIFIED_CASES:
            walls = {"interaction": [], "multibody": []}
            stats = {}
            # A line's compiled steps are built in the background after its first run, which steps
            # in Python: the timed runs use them, the last column is the Python steps'.
            # (the users' default mode, background: the bench's own, "now", compiles a line's steps
            # only for runs of CHUNK_COMPILE_STEPS steps or more)
            with mock.patch.dict(os.environ, {"SYMCAT_OPTIMIZE": "background"}):
                _model(params)
                wait_for_background()
            with mock.patch.dict(os.environ, {"SYMCAT_OPTIMIZE": "off"}):  # a line's long run then steps in Python
                python_steps = _model(params)["wall_per_simulated_s"]
            for _ in range(repeats):
                for path in walls:
                    # each run in a process of its own, as users run the model
                    summary = (interaction_model(checkout, params) if path == "interaction" else
                               model_in_subprocess(REPO, params))
                    walls[path].append(summary["wall_per_simulated_s"])
                    stats[path] = {k: _pantograph_stats(summary)[k] for k in keys}
            a, b = stats["interaction"], stats["multibody"]
            wa, wb = statistics.median(walls["interaction"]), statistics.median(walls["multibody"])
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
    # (Python steps: an 80-span line's compiled library takes minutes to build; the compiled
    # steps are the same loops over the wires)
    spans = {n: _run(n_spans=n, t_end=0.5, repeats=3, compiled=False) for n in (10, 20, 40, 80)}
    hard = hard_cases()
    unified = unified_paths()
    lines = [
        "## Pantograph/catenary: benchmark2015 at 320 km/h (one pantograph, penalty contact)",
        "",
        "The model benchmark2015 at its defaults but for the setting studied (the lumped pantograph as scene bodies "
        "on the shared multibody path). Statistics of the 20 Hz filtered contact force over spans 5-6 (of 10); in "
        "brackets the change against the finest run of the same study. Wall time per simulated second of the "
        "passage (static placement and time integration; form finding excluded; one run each unless stated, the "
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
        "### Faster than real time: 50 elements/span, dt 2 ms, tol 1e-3 m (median of 3; change against 120 "
        "elements/span at 1 ms)",
        "",
        *header,
        *[_row(f"{w} wires", s, r, ref) for w, s, r, _ in fast],
        "",
        "Run it with `symcat run benchmark2015 --set elements_per_span=50 --set dt=0.002 --set tol=0.001 --set "
        "wires=linear`.",
        "",
        "Target: at most 1 s of wall time per simulated second at the discretization converged to 1 %. "
        "The run continues 0.2 s past the section so that the zero-phase filter has settled there (without "
        "this, its edge treatment bent the end of the section and made the mean drift as O(dt)).",
        "",
        "### Cost against line length (60 elements/span, dt 1 ms, 0.5 s simulated, median of 3)",
        "",
        "The coordinates include the pantograph's bodies. The target of issue 28: 80 spans at most 9 times "
        "10 spans. This table runs the Python steps (a line's first run; an 80-span line's compiled library "
        "takes minutes to build); the other tables the line's compiled steps, built before they are timed.",
        "",
        "| spans | coordinates | wall / simulated |",
        "|---:|---:|---:|",
        *[f"| {n} | {summary['n_coordinates']} | {r:.2f} |" for n, (_, r, summary) in spans.items()],
        "",
        f"80 spans against 10: {spans[80][1] / spans[10][1]:.2f} times.",
        "",
        *hard,
        "",
        "### The shared multibody path against the interaction path (model benchmark2015, 320 km/h unless stated)",
        "",
        "The lumped pantograph as scene bodies under the catenary scene, integrated by the shared generalized-alpha "
        "(`pantograph=lumped`, the models' default), against the interaction path (retired: `pantograph="
        f"lumped_interaction` at commit {INTERACTION_COMMIT}, run from a git worktree of it in a subprocess of this "
        "bench run): statistics apart (the last run of each) and wall time per simulated second, static placement "
        "and time integration on both paths (medians of 3 interleaved runs; ratio multibody / interaction).",
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
