"""Work-precision of the sliding joint (`slider_on_wire`): error against a tight-tolerance
reference vs wall time, for augmented/embedded x index-1/GGL, several tolerances and meshes;
and the wall time per simulated second of a 48-element wire over 10 s."""
from __future__ import annotations

import time

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from symcat.model import load_model  # noqa: E402

FORMS = [("augmented", "1"), ("embedded", "1"), ("augmented", "ggl"), ("embedded", "ggl")]


def _run(model, params):
    t = time.perf_counter()
    out = model.run(model.resolve(params))
    return out, time.perf_counter() - t


def work_precision(report_dir, t_end=0.5, n_elements=8):
    model = load_model("slider_on_wire")
    base = {"t_end": t_end, "n_elements": n_elements}
    ref, _ = _run(model, {**base, "rtol": 1e-10, "formulation": "augmented", "index": "1"})
    ref_pos = np.array(ref.summary["body_position_m"])
    rows, curves = [], {}
    for form, index in FORMS:
        for rtol in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
            try:
                out, wall = _run(model, {**base, "rtol": rtol, "formulation": form, "index": index})
            except Exception as exc:  # record failures, e.g. GGL below its tolerance limit
                rows.append((form, index, n_elements, rtol, float("nan"), float("nan"), 0, 0, "failed: " + str(exc)[:50]))
                continue
            err = float(np.linalg.norm(np.array(out.summary["body_position_m"]) - ref_pos))
            st = out.stats
            rows.append((form, index, n_elements, rtol, err, wall, st["nsteps"], st["nlinsetups"], f"{st['nfevals']} residuals"))
            curves.setdefault((form, index), []).append((wall, max(err, 1e-14)))
    mesh_rows = []
    for n in (4, 8, 16):
        out, wall = _run(model, {**base, "n_elements": n, "rtol": 1e-6})
        mesh_rows.append((n, out.summary["s_final_m"], out.summary["body_position_m"][2], wall, out.stats["nsteps"]))
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for (form, index), pts in curves.items():
        pts = np.array(pts)
        ax.loglog(pts[:, 0], pts[:, 1], "o-", label=f"{form}, index {index}")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("body position error at t_end [m]")
    ax.set_title(f"slider_on_wire, {n_elements} cable3d elements, {t_end} s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(report_dir / "slider_work_precision.png", dpi=100)
    plt.close(fig)
    return rows, mesh_rows


def cholesky_study(t_end=0.3):
    model = load_model("slider_on_wire")
    rows = []
    for n in (8, 32):
        for chol in (False, True):
            out, wall = _run(model, {"t_end": t_end, "n_elements": n, "rtol": 1e-6, "cholesky": chol})
            rows.append((n, chol, wall, out.stats["nsteps"], out.stats["nlinsetups"]))
    return rows


def linear_solvers(t_end=0.3, n_elements=32):
    from symcat.assembly.multibody import MultibodyModel
    from symcat.integrate import simulate

    import importlib.util
    from symcat.model import models_dirs

    path = next(d / "slider_on_wire.py" for d in models_dirs() if (d / "slider_on_wire.py").is_file())
    spec = importlib.util.spec_from_file_location("slider_bench", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    params = {p.name: p.default for p in mod.PARAMETERS}
    params["n_elements"] = n_elements
    rows = []
    for solver in ("csparse", "qr", "lapacklu"):
        model = MultibodyModel(mod.build(params))
        t = time.perf_counter()
        res = simulate(model, t_end, rtol=1e-6, atol=1e-8, n_out=60, progress=False, linear_solver=solver)
        rows.append((solver, time.perf_counter() - t, res.stats["nsteps"], res.stats["nlinsetups"]))
    return rows


def real_time_ratio(t_end=10.0, n_elements=48):
    model = load_model("slider_on_wire")
    out, wall = _run(model, {"t_end": t_end, "n_elements": n_elements, "rtol": 1e-6})
    return wall / t_end, out.stats


def section(report_dir) -> list[str]:
    rows, mesh_rows = work_precision(report_dir)
    ratio, stats = real_time_ratio()
    chol = cholesky_study()
    solvers = linear_solvers()
    lines = [
        "## Sliding joint: work-precision (`slider_on_wire`)",
        "",
        "![work-precision](slider_work_precision.png)",
        "",
        "Error: body position at t = 0.5 s against augmented index-1 at rtol 1e-10 (8 cable3d elements).",
        "",
        "| formulation | index | elements | rtol | error [m] | wall [s] | steps | Jacobian setups | note |",
        "|---|---|---:|---:|---:|---:|---:|---:|---|",
        *[f"| {f} | {i} | {n} | {r:g} | {e:.2e} | {w:.2f} | {s} | {j} | {note} |" for f, i, n, r, e, w, s, j, note in rows],
        "",
        "The step count grows with the tolerance because IDAS resolves the wire's axial and bending "
        "vibrations (the wire is released straight, not from equilibrium); the body position itself is "
        "accurate to 1e-8 m already at rtol 1e-4. Residual evaluations are about 1.5 per step (Newton "
        "iterations), Jacobians are formed once per 20-30 steps.",
        "",
        "Mesh study at rtol 1e-6 (the same 0.5 s):",
        "",
        "| elements | s_final [m] | body z [m] | wall [s] | steps |",
        "|---:|---:|---:|---:|---:|",
        *[f"| {n} | {s:.6f} | {z:.6f} | {w:.2f} | {st} |" for n, s, z, w, st in mesh_rows],
        "",
        f"Wall time per simulated second, 48-element wire over 10 s (augmented, index 1, rtol 1e-6): "
        f"**{ratio:.2f} s/s** ({stats['nsteps']} steps, {stats['nlinsetups']} Jacobian setups, "
        f"{stats['restarts']} window restarts, {stats['nfevals']} residual evaluations; linear solver: "
        "csparse sparse LU, symcat's default).",
        "",
        "### Linear solver of IDAS's Newton systems (32 elements, 0.3 s, rtol 1e-6)",
        "",
        "| linear solver | wall [s] | steps | Jacobian setups |",
        "|---|---:|---:|---:|",
        *[f"| {n} | {w:.2f} | {st} | {j} |" for n, w, st, j in solvers],
        "",
        "### Cholesky coordinates (0.3 s, rtol 1e-6)",
        "",
        "| elements | Cholesky | wall [s] | steps | Jacobian setups |",
        "|---:|---|---:|---:|---:|",
        *[f"| {n} | {c} | {w:.2f} | {st} | {j} |" for n, c, w, st, j in chol],
        "",
        "With Cholesky coordinates the mass matrix is the identity, but U^-1 is dense, so every Jacobian "
        "of the wire becomes dense: the sparse direct solver then pays O(n^2) or worse per factorization.",
        "",
    ]
    return lines
