"""Issue 28 de-risking: a benchmark2015 passage on the interaction path (``run_passage``) and on
the shared multibody pipeline (``catenary_scene`` + ``add_lumped_pantograph`` +
``solve_equilibrium`` + ``generalized_alpha``, optionally IDAS), same line, mesh, pantograph,
penalty law, start position, time step and rho_inf. Prints the contact-force statistics of both
over the same window and the differences of the histories.

``python -m bench.unified_passage [n_spans elements_per_span speed_kmh t_end dt idas]``
(defaults 4 10 320 1.0 1e-3 0).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary import benchmark2015, find_form
from symcat.catenary.scene import catenary_scene
from symcat.integrate import generalized_alpha, simulate
from symcat.interaction.passage import run_passage
from symcat.interaction.statistics import lowpass
from symcat.pantograph import benchmark2015_pantograph
from symcat.pantograph.lumped_scene import add_lumped_pantograph, loaded_wire_height

#: Start-up (s) left out of the comparison window.
STARTUP_S = 0.1


def compare(n_spans=4, elements=10, speed_kmh=320.0, t_end=1.0, dt=1e-3, rho_inf=0.8, idas=False,
            contact_stiffness=5.0e4, smoothing=1e-5, progress=False, tol_ip=1e-4, tol_mb=1e-4) -> dict:
    """Run both paths; return histories, statistics and wall times."""
    speed = speed_kmh / 3.6
    design = benchmark2015(n_spans)
    panto = benchmark2015_pantograph(speed_kmh)
    t0 = time.perf_counter()
    form = find_form(design, elements, progress=False)
    wall_form = time.perf_counter() - t0

    # (a) interaction path
    t0 = time.perf_counter()
    ip = run_passage(design, [panto], speed, elements_per_span=elements, contact="penalty",
                     contact_stiffness=contact_stiffness, dt=dt, rho_inf=rho_inf, tol=tol_ip, t_end=t_end, record_every=dt,
                     progress=progress, form=form)
    wall_ip = time.perf_counter() - t0
    x0 = ip.line.runs[0].x_start
    t_a, f_a = ip.record.t_s, ip.record.contact_force_N[:, 0]

    # (b) shared multibody pipeline
    t0 = time.perf_counter()
    scene = catenary_scene(form)
    head_z = loaded_wire_height(form, x0, float(panto.static_force(speed).sum()))
    info = add_lumped_pantograph(scene, panto, "contact", x0, speed, contact="penalty",
                                 contact_stiffness=contact_stiffness, smoothing=smoothing, head_z=head_z)
    model = MultibodyModel(scene)
    eq = solve_equilibrium(model)
    eq.apply(model)
    wall_build = time.perf_counter() - t0
    n_out = round(t_end / dt)
    t0 = time.perf_counter()
    res = generalized_alpha(model, t_end, dt, rho_inf, n_out=n_out, progress=progress, tol=tol_mb,
                            multipliers="integrator")
    wall_mb = time.perf_counter() - t0
    t_b, f_b = res.t_s, res.contacts[info["contact"]]["force_N"]
    out = {"x0_m": x0, "static_force_ip_N": float(f_a[0]), "static_force_mb_N": float(eq.contact_force_N[info["contact"]]),
           "wall_form_s": wall_form, "wall_ip_s": wall_ip, "wall_mb_build_eq_s": wall_build, "wall_mb_alpha_s": wall_mb,
           "mb_stats": res.stats, "t_a": t_a, "f_a": f_a, "t_b": t_b, "f_b": f_b,
           "n_dofs_ip": ip.line.n, "n_q_mb": model.n_q}
    if idas:
        model2 = MultibodyModel(scene)
        eq.apply(model2)
        t0 = time.perf_counter()
        r2 = simulate(model2, t_end, n_out=n_out, progress=progress, rtol=1e-6)
        out["wall_idas_s"] = time.perf_counter() - t0
        out["t_c"], out["f_c"] = r2.t_s, r2.contacts[info["contact"]]["force_N"]
    # comparison on the common grid after the start-up
    keep = t_a >= STARTUP_S - 1e-12
    fb = np.interp(t_a, t_b, f_b)
    diff = fb[keep] - f_a[keep]
    out.update(mean_ip_N=float(f_a[keep].mean()), std_ip_N=float(f_a[keep].std()), mean_mb_N=float(fb[keep].mean()),
               std_mb_N=float(fb[keep].std()), max_abs_diff_N=float(np.abs(diff).max()),
               rms_diff_N=float(np.sqrt(np.mean(diff**2))), loss_ip=float(np.mean(f_a[keep] <= 0)),
               loss_mb=float(np.mean(fb[keep] <= 0)))
    # EN 50318 style: 20 Hz zero-phase low-pass over the whole run, then the same window
    fa_f, fb_f = lowpass(t_a, f_a), lowpass(t_a, fb)
    dff = fb_f[keep] - fa_f[keep]
    out.update(mean_ip_20Hz_N=float(fa_f[keep].mean()), std_ip_20Hz_N=float(fa_f[keep].std()),
               std_mb_20Hz_N=float(fb_f[keep].std()), max_abs_diff_20Hz_N=float(np.abs(dff).max()))
    if idas:
        fc = np.interp(t_a, out["t_c"], out["f_c"])
        d2 = fc[keep] - f_a[keep]
        out.update(mean_idas_N=float(fc[keep].mean()), std_idas_N=float(fc[keep].std()),
                   max_abs_diff_idas_N=float(np.abs(d2).max()), rms_diff_idas_N=float(np.sqrt(np.mean(d2**2))))
    return out


def section(spans=(10, 20, 40, 80), elements=60, t_end=0.5) -> list[str]:
    """Markdown: the lumped benchmark pantograph at 320 km/h on the interaction path and on the
    shared multibody path (catenary scene + generalized-alpha), wall per simulated second and
    contact-force statistics, for lines of ``spans`` spans (one run each)."""
    rows = []
    for n in spans:
        out = compare(n_spans=n, elements=elements, t_end=t_end)
        rows.append((n, out["n_dofs_ip"], out["n_q_mb"], out["wall_ip_s"] / t_end, out["wall_mb_alpha_s"] / t_end,
                     out["wall_mb_build_eq_s"], out["mean_ip_N"], out["mean_mb_N"], out["std_ip_N"], out["std_mb_N"],
                     out["rms_diff_N"], out["mb_stats"]["newton_iterations"] / out["mb_stats"]["steps"]))
        print(f"  {n} spans done", flush=True)
    base_ip, base_mb = rows[0][3], rows[0][4]
    return [
        "## A line passage on the shared multibody path",
        "",
        f"benchmark2015 catenary, {elements} elements/span, lumped pantograph at 320 km/h, penalty contact, dt = 1 ms, "
        f"rho_inf = 0.8, {t_end:g} s from the static equilibrium. *interaction*: `run_passage` (CoupledLine, tol 1e-4 m). "
        "*scene*: `catenary_scene` + `add_lumped_pantograph` + `solve_equilibrium` + `generalized_alpha` (tol 1e-4 m as the interaction path, "
        "the integrator's multipliers). Wall per simulated second of the integration (the scene's includes its "
        "start and post-processing); set-up = scene, model and static equilibrium. One run each: compare ratios.",
        "",
        "| spans | unknowns (interaction / scene) | interaction [s/s] | scene [s/s] | scene / interaction | "
        "scene / its 10-span | set-up [s] | mean [N] (int. / scene) | std [N] (int. / scene) | rms diff [N] | "
        "Newton it./step |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *[f"| {n} | {a} / {b} | {w_ip:.2f} | {w_mb:.2f} | {w_mb / w_ip:.1f} | {w_mb / base_mb:.1f} | {su:.1f} | "
          f"{m1:.2f} / {m2:.2f} | {s1:.2f} / {s2:.2f} | {rms:.3f} | {it:.2f} |"
          for n, a, b, w_ip, w_mb, su, m1, m2, s1, s2, rms, it in rows],
        "",
        f"Interaction path: its own 10-span figure {base_ip:.2f} s/s.",
        "",
    ]


def work_precision(report_dir=None, spans=4, elements=10, speed_kmh=200.0, t_end=0.2) -> list[str]:
    """Markdown (and ``work_precision_passage.png`` in ``report_dir``): generalized-alpha (dt) and
    IDAS (rtol) on the same short passage (the lumped pantograph on the catenary scene), the
    largest contact-force error against generalized-alpha at dt = 0.125 ms over wall time."""
    from symcat.simulation import simulate as simulate_idas

    speed = speed_kmh / 3.6
    form = find_form(benchmark2015(spans), elements, progress=False)
    panto = benchmark2015_pantograph(speed_kmh)
    x0 = benchmark2015(spans).span_length

    def model():
        scene = catenary_scene(form)
        z = loaded_wire_height(form, x0, float(panto.static_force(speed).sum()))
        name = add_lumped_pantograph(scene, panto, "contact", x0, speed, contact="penalty", head_z=z)["contact"]
        m = MultibodyModel(scene)
        solve_equilibrium(m).apply(m)
        return m, name

    grid = np.linspace(0.0, t_end, 201)

    def run(kind, x):
        m, name = model()
        t0 = time.perf_counter()
        if kind == "alpha":
            r = generalized_alpha(m, t_end, x, 0.8, n_out=round(t_end / x), progress=False, tol=1e-8,
                                  multipliers="integrator")
        else:
            r = simulate_idas(m, t_end, rtol=x, atol=x * 1e-2, n_out=200, progress=False)
        return time.perf_counter() - t0, np.interp(grid, r.t_s, r.contacts[name]["force_N"]), r.stats

    _, ref, _ = run("alpha", 1.25e-4)
    rows = []
    for dt in (2e-3, 1e-3, 5e-4, 2.5e-4):
        wall, f, st = run("alpha", dt)
        rows.append(("generalized-alpha", f"dt {dt * 1e3:g} ms", wall, float(np.abs(f - ref).max()), st["steps"]))
    for rtol in (1e-3, 1e-4, 1e-5):
        wall, f, st = run("idas", rtol)
        rows.append(("IDAS", f"rtol {rtol:g}", wall, float(np.abs(f - ref).max()), st.get("nsteps", 0)))
    alpha = [r for r in rows if r[0] != "IDAS"]
    orders = [np.log2(a[3] / b[3]) for a, b in zip(alpha, alpha[1:])]
    if report_dir is not None:
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4.2))
        for label, marker in (("generalized-alpha", "o-"), ("IDAS", "s-")):
            sel = [r for r in rows if r[0] == label]
            ax.loglog([r[2] for r in sel], [r[3] for r in sel], marker, label=label)
            for r in sel:
                ax.annotate(r[1], (r[2], r[3]), fontsize=7)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("max contact-force error [N]")
        ax.set_title(f"{spans} spans x {elements} el/span, {speed_kmh:g} km/h, {t_end:g} s")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(Path(report_dir) / "work_precision_passage.png", dpi=110)
        plt.close(fig)
    return [
        "### Work-precision of the two integrators on a passage",
        "",
        f"The lumped pantograph on the catenary scene ({spans} spans, {elements} elements/span, {speed_kmh:g} km/h, "
        f"{t_end:g} s from the static state); error: the largest contact-force difference from generalized-alpha "
        "at dt = 0.125 ms. Observed order of generalized-alpha between successive dt: "
        + ", ".join(f"{o:.2f}" for o in orders) + ". IDAS's wall includes building its DAE.",
        "",
        "![work-precision](work_precision_passage.png)" if report_dir is not None else "",
        "",
        "| integrator | setting | wall [s] | max error [N] | steps |",
        "|---|---|---:|---:|---:|",
        *[f"| {k} | {s} | {w:.2f} | {e:.3g} | {n} |" for k, s, w, e, n in rows],
        "",
    ]


def main(argv):
    args = [float(a) for a in argv]
    names = ("n_spans", "elements", "speed_kmh", "t_end", "dt", "idas")
    kw = dict(zip(names, args))
    for k in ("n_spans", "elements"):
        if k in kw:
            kw[k] = int(kw[k])
    if "idas" in kw:
        kw["idas"] = bool(kw["idas"])
    out = compare(**kw)
    for k, v in out.items():
        if not isinstance(v, np.ndarray) and k != "mb_stats":
            print(f"{k:24s} {v}")
    s = out["mb_stats"]
    print("mb stats", {k: s.get(k) for k in ("steps", "newton_iterations", "factorizations", "rebuilds", "halvings",
                                             "build_s")})
    return out


if __name__ == "__main__":
    main(sys.argv[1:])
