"""Run the four problems in both codes and write ``bench/report/peers.md`` with one
work-precision figure per problem (``python -m bench.peers [--quick]``)."""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from . import cantilever, moving_load, pendulum, sliding_joint
from .common import Point, plot, ratios, timed

ROOT = Path(__file__).resolve().parents[2]
REPORT = ROOT / "bench" / "report"
FIGURES = REPORT / "peers"
CACHE = Path(os.environ.get("SYMCAT_BENCH_CACHE", Path.home() / ".cache" / "symcat-bench-peers"))

# The table of issue 29 (symcat time / Exudyn time at equal error, before this bench).
OLD = {
    "sliding joint": "2.2 (loose error) to 1.3 (at the example's own setting), 0.3 at the tightest error",
    "moving load": "3 to 15",
    "cantilever": "16 (2D), 9 (3D)",
    "pendulum": "3.5 to 6.5",
}
TITLES = {
    "sliding joint": "3D sliding joint (Exudyn's ANCFslidingJoint: 2 m wire, 48 elements, 28 kg cuboid), 2 s",
    "moving load": "moving load on a taut 60 m wire (0.5 of the wave speed), 60 elements",
    "pendulum": "3D spinning cable pendulum, 16 elements, 2 s",
}
MODULES = {"sliding joint": sliding_joint, "moving load": moving_load, "pendulum": pendulum}


NOTES = [
    "## How the statements differ between the codes", "",
    "- **Sliding joint**: the wire's damping law (see the damping row above: each code's law against no "
    "damping at all). The sliding joints differ too: Exudyn's `ObjectJointSliding` solves for the "
    "sliding coordinate relative to its start-of-step value, switches the element after each step "
    "(`PostNewtonStep`, a data node holds the element and the start-of-step coordinate) and, by its "
    "documentation, leaves the s-dot term out of the sliding point's velocity; symcat's arc length is an "
    "unknown of the step like any coordinate. On this problem Exudyn's error against its own reference "
    "falls about linearly with the step (first order), symcat's generalized-alpha error quadratically: "
    "the two curves barely overlap in error.",
    "- **Moving load**: Exudyn applies consistent nodal forces at the material point s = v t (load user "
    "functions, Python callbacks on the 2 (n + 1) transverse coordinates); symcat has no moving nodal load "
    "and hangs a 1 g body (rotation held) on a sliding joint driven along x at v, which carries the force: "
    "the force acts where the deformed wire's x is v t, and the body adds its inertia; the wire is "
    "`cable3d` (the sliding joint needs it) and stays in its plane. The physics-match row is the result of "
    "both differences.",
    "- **Pendulum**: symcat's scene has no initial velocities of ANCF nodes; the bench writes them into "
    "`MultibodyModel.v0`.",
    "- **Cantilever**: identical (both against the extensible elastica).",
    "- **Compiled steps** (`symcat.integrate.alpha_chunk`): symcat's generalized-alpha runs its steps "
    "compiled, up to 32 to a call, on all three dynamic problems (the sliding joint's and the moving "
    "load's points on one proxy element that the code fills with the element holding them). symcat's "
    "runs keep the integrator's own multipliers (no KKT solve per output), as Exudyn reports only its "
    "sensors; each model's compiled library is built before the timed runs, as the kernels are, in its "
    "optimized tier (-O3, the band's factorization and solves C loops: about 20 s once for the moving load's "
    "model; a user's first run takes the -O0 library while the optimized one compiles in the background); "
    "so are the terms of a run's result when its steps are compiled (a few seconds once per model). Every timed run builds its model anew and finds that "
    "library from a digest of the model (`symcat.integrate.alpha_chunk_cache`), without building the "
    "Python step equations, which only a step that falls back to Python (or the start filter when "
    "rho_inf < 1, as on the pendulum) builds.",
    "- **IDAS on the moving load and the pendulum**: the error does not change with rtol (1e-5 to 2e-5 m): "
    "it is the distance between IDAS's solution and symcat's generalized-alpha reference, whose numerical "
    "dissipation (spectral radius 0.8 on the pendulum) and step leave that much; the IDAS points therefore "
    "say \"as accurate as the reference\", and the \"best\" envelope joins them to the generalized-alpha "
    "curve in log-log.", "",
]


def _label(setting: dict) -> str:
    if "rtol" in setting:
        return f"rtol {setting['rtol']:g}"
    return f"dt {setting['dt'] * 1e3:.4g} ms"


def reference(name: str, code: str, fn, setting: dict) -> tuple[np.ndarray, float]:
    """A code's reference run, cached on disk by problem, code and setting (they take minutes)."""
    key = hashlib.sha1(json.dumps([name, code, setting], sort_keys=True).encode()).hexdigest()[:12]
    path = CACHE / f"{name.replace(' ', '_')}_{code}_{key}.npz"
    if path.is_file():
        data = np.load(path)
        return data["out"], float(data["wall"])
    out, wall = timed(fn, setting)
    CACHE.mkdir(parents=True, exist_ok=True)
    np.savez(path, out=out, wall=wall)
    return out, wall


def dynamic(name: str, repeats: int, quick: bool, log) -> dict:
    """One dynamic problem: both references, then the three curves' points run interleaved
    ``repeats`` times; returns the points, the physics match and the references' settings."""
    mod = MODULES[name]
    ref_sym, wall_rs = reference(name, "symcat", mod.symcat_run, mod.SYMCAT_REFERENCE)
    ref_exu, wall_re = reference(name, "exudyn", mod.exudyn_run, mod.EXUDYN_REFERENCE)
    series = {
        "symcat IDAS": (mod.symcat_run, mod.SYMCAT_IDAS, ref_sym),
        "symcat generalized-alpha": (mod.symcat_run, mod.SYMCAT_ALPHA, ref_sym),
        "Exudyn generalized-alpha": (mod.exudyn_run, mod.EXUDYN, ref_exu),
    }
    if quick:
        series = {k: (f, s[:3], r) for k, (f, s, r) in series.items()}
    points = {k: [Point(k, _label(s), np.nan) for s in settings] for k, (_, settings, _) in series.items()}
    # Compiled code beforehand, as the kernels are: a run at the coarsest step compiles the
    # generalized-alpha steps if the model's library is not cached yet (seconds, once).
    timed(mod.symcat_run, {**mod.SYMCAT_ALPHA[0], "compiled": True})
    longest = max(len(s) for _, s, _ in series.values())
    # Interleaved: the i-th point of every series, then the next i; repeats of slow points
    # (over 30 s) are skipped, the median of what ran is reported.
    for r in range(repeats):
        for i in range(longest):
            for k, (fn, settings, ref) in series.items():
                if i >= len(settings):
                    continue
                p = points[k][i]
                if r > 0 and (not p.walls or p.walls[0] > 30.0):
                    continue
                try:
                    out, wall = timed(fn, settings[i])
                except Exception as exc:  # a failed run is a missing point, with its reason
                    p.info = f"failed: {str(exc).splitlines()[0][:80]}"
                    continue
                p.error = mod.error(out, ref)
                p.walls.append(wall)
                log(f"{name}: {k} {p.label}: error {p.error:.2e}, wall {wall:.2f} s")
    return {"points": points, "match": mod.error(ref_sym, ref_exu),
            "reference": (mod.SYMCAT_REFERENCE, wall_rs, mod.EXUDYN_REFERENCE, wall_re)}


def with_ratios(res: dict) -> dict:
    """``res`` with the ratio tables of each symcat curve (and of the best of both) to Exudyn's."""
    points = res["points"]
    sym_all = points["symcat IDAS"] + points["symcat generalized-alpha"]
    exu = points["Exudyn generalized-alpha"]
    return {**res, "ratios": {
        "symcat (best of both) / Exudyn": ratios(sym_all, exu),
        "symcat generalized-alpha / Exudyn": ratios(points["symcat generalized-alpha"], exu),
        "symcat IDAS / Exudyn": ratios(points["symcat IDAS"], exu),
    }}


def save(name: str, res: dict) -> None:
    """Keep a problem's measurements, so that ``--only`` reruns one problem into a full report."""
    data = {k: v for k, v in res.items() if k != "points"}
    data["points"] = {k: [p.__dict__ for p in pts] for k, pts in res["points"].items()}
    CACHE.mkdir(parents=True, exist_ok=True)
    (CACHE / f"result_{name.replace(' ', '_')}.json").write_text(json.dumps(data, default=float))


def load(name: str) -> dict | None:
    path = CACHE / f"result_{name.replace(' ', '_')}.json"
    if not path.is_file():
        return None
    data = json.loads(path.read_text())
    if isinstance(data.get("points"), dict):
        if name == "cantilever":
            return {case: {code: [Point(**p) for p in pts] for code, pts in codes.items()}
                    for case, codes in data["points"].items()}
        data["points"] = {k: [Point(**p) for p in pts] for k, pts in data["points"].items()}
    return data


#: Steps of the damping-law comparison: each code's error at them is below a tenth of the
#: difference measured (symcat about 2e-5 m, Exudyn about 9e-4 m with the damped wire).
DAMPING_STEPS = {"symcat": {"dt": 1e-3, "tol": 1e-8}, "Exudyn": {"dt": 6.25e-5}}


def damping_law_effect(log) -> tuple[float, float]:
    """Sliding joint: difference of the two codes with the wire damped (each code's own law)
    and undamped (no damping law at all), each at a step where its own error is small."""
    out = []
    for damping in (sliding_joint.DAMPING, 0.0):
        saved = sliding_joint.DAMPING
        sliding_joint.DAMPING = damping
        try:
            a = sliding_joint.symcat_run(DAMPING_STEPS["symcat"])
            b = sliding_joint.exudyn_run(DAMPING_STEPS["Exudyn"])
        finally:
            sliding_joint.DAMPING = saved
        out.append(sliding_joint.error(a, b))
        log(f"sliding joint, damping {damping:g} s: codes differ by {out[-1]:.2e} m")
    return tuple(out)


def _fmt_ratio_range(rows) -> str:
    if not rows:
        return "no overlap"
    low, high = f"{min(row[3] for row in rows):.2g}", f"{max(row[3] for row in rows):.2g}"
    return f"{low} to {high}" if low != high else low


def write_report(results: dict, cant: dict, wall_total: float) -> Path:
    import casadi
    import exudyn

    lines = [
        "# symcat beside Exudyn (`make bench-peers`)",
        "",
        f"Machine: {platform.machine()}, {os.cpu_count()} cores (shared), Python {platform.python_version()}, "
        f"CasADi {casadi.__version__}, Exudyn {exudyn.__version__}, `OMP_NUM_THREADS=1`, Exudyn on one thread. "
        f"Generated by `python -m bench.peers` (the last run of the measurements took {wall_total:.0f} s; "
        "problems not rerun come from the measurement cache).",
        "",
        "The four problems of `exudyn-peers.md`, stated identically in both codes (`bench/peers/`). "
        "Each code's error is against its own converged reference (same mesh, finest step); the two "
        "references compared are the physics match. Walls are whole runs (model built, assembled and "
        "integrated; kernels compiled beforehand), medians of interleaved repeats (the two codes take "
        "turns). The ratio symcat time / Exudyn time at equal error is read off the two work-precision "
        "curves (Pareto fronts, interpolated in log-log) at every error of either code's points where "
        "both curves reach; a ratio below 1 means symcat is faster. symcat runs IDAS (an rtol sweep, "
        "atol = rtol / 100) and generalized-alpha (a step sweep, the same spectral radius as Exudyn's: 0.9, 1 "
        "and 0.8 for the sliding joint, moving load and pendulum; Newton tolerance 1e-8 m); Exudyn runs "
        "generalized-alpha (Newton relative tolerance 1e-8). The references: each code's generalized-alpha "
        "at the same small step (given per problem; 2 to 20 times below the finest swept step), Newton "
        "tolerance 1e-12 m (symcat) or relative 1e-10 (Exudyn). \"symcat best\" is the lower envelope of symcat's two curves (a user picks the integrator).",
        "",
        "## Summary: symcat time / Exudyn time at equal error",
        "",
        "| problem | old (issue 29) | new: symcat best | new: generalized-alpha | new: IDAS |",
        "|---|---|---|---|---|",
    ]
    for name, res in results.items():
        rr = res["ratios"]
        lines.append(f"| {TITLES[name].split(' (')[0].split(',')[0]} | {OLD[name]} | "
                     f"{_fmt_ratio_range(rr['symcat (best of both) / Exudyn'])} | "
                     f"{_fmt_ratio_range(rr['symcat generalized-alpha / Exudyn'])} | "
                     f"{_fmt_ratio_range(rr['symcat IDAS / Exudyn'])} |")
    c2, c3 = cant["2D"], cant["3D"]
    lines.append(f"| static cantilever, 64 elements (solve only) | {OLD['cantilever']} | "
                 f"{c2['symcat'][0].wall / c2['Exudyn'][0].wall:.2g} (2D), {c3['symcat'][0].wall / c3['Exudyn'][0].wall:.2g} (3D) | | |")
    lines += ["", "Where symcat's time goes on these problems (profiles) and the statics before and after: "
              "[peers-profiles.md](peers-profiles.md).", ""]
    for name, res in results.items():
        fig = plot(FIGURES / f"{name.replace(' ', '_')}.png", TITLES[name], res["points"],
                   ylabel="error against the code's own reference [m]")
        ref_s, wall_rs, ref_e, wall_re = res["reference"]
        lines += [f"## {TITLES[name]}", "", f"![work-precision](peers/{fig.name})", "",
                  f"References: symcat generalized-alpha {_label(ref_s)} ({wall_rs:.0f} s), Exudyn {_label(ref_e)} "
                  f"({wall_re:.0f} s). **Physics match: the two references differ by {res['match']:.2e}** "
                  "(largest difference over the outputs).", ""]
        damping = res.get("damping")
        if damping is not None:
            lines += [f"Damping law: symcat (generalized-alpha, 1 ms) and Exudyn (0.0625 ms) differ by "
                      f"{damping[0]:.2e} m with the wire damped (each code's law) and by {damping[1]:.2e} m with "
                      "the wire undamped (largest distance of the attachment point over the 2 s): the damping laws "
                      "(symcat's Kelvin-Voigt axial force about (1 + eps)^2 times Exudyn's) move the result by "
                      f"about {damping[0] - damping[1]:.1e} m, {100 * (1 - damping[1] / damping[0]):.0f} % of the "
                      "mismatch; the undamped remainder includes Exudyn's own error at its step (about 9e-4 m on "
                      "the damped wire) and the two sliding joints' different discretizations.", ""]
        lines += ["| code | setting | error | wall [s] (median) | runs | note |", "|---|---|---:|---:|---:|---|"]
        for series in res["points"].values():
            for p in series:
                wall = f"{p.wall:.3f}" if p.walls else "-"
                lines.append(f"| {p.code} | {p.label} | {p.error:.2e} | {wall} | {len(p.walls)} | {p.info} |")
        lines.append("")
        for title, rows in res["ratios"].items():
            if not rows:
                lines += [f"{title}: the curves do not overlap in error.", ""]
                continue
            lines += [f"{title}:", "", "| error | symcat wall [s] | Exudyn wall [s] | ratio |", "|---:|---:|---:|---:|"]
            lines += [f"| {e:.2e} | {ws:.3f} | {we:.3f} | {r:.2f} |" for e, ws, we, r in rows]
            lines.append("")
    lines += NOTES
    lines += ["## Static cantilever, 64 cable elements, tip load alpha = 3 (solve only)", "",
              "Error: tip position against the extensible elastica. Walls: the solve alone on a built and "
              "assembled system, median of interleaved repeats; symcat's first solve on a new system also "
              "compiles its Newton function.", "",
              "| case | code | error [m] | wall [ms] (median) | runs | note |", "|---|---|---:|---:|---:|---|"]
    for case, pts in cant.items():
        for code, (p,) in pts.items():
            lines.append(f"| {case} | {code} | {p.error:.2e} | {p.wall * 1e3:.2f} | {len(p.walls)} | {p.info} |")
    lines.append("")
    path = REPORT / "peers.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="three points per curve, one repeat")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--only", nargs="*", choices=list(MODULES) + ["cantilever"], default=None,
                        help="rerun these problems; the others come from the measurement cache")
    parser.add_argument("--report-only", action="store_true", help="rewrite the report from the measurement cache")
    parser.add_argument("--damping", action="store_true",
                        help="rerun only the sliding joint's damping-law comparison into the measurement cache")
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else args.repeats

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    only = [] if args.report_only or args.damping else args.only or list(MODULES) + ["cantilever"]
    if args.damping and load("sliding joint") is not None:
        cached = load("sliding joint")
        cached["damping"] = damping_law_effect(log)
        save("sliding joint", cached)
    if "cantilever" in only:
        cant = cantilever.run(15)
        for case, pts in cant.items():
            log(f"cantilever {case}: " + ", ".join(f"{c} {p[0].wall * 1e3:.2f} ms ({p[0].error:.1e} m)"
                                                   for c, p in pts.items()))
        CACHE.mkdir(parents=True, exist_ok=True)
        (CACHE / "result_cantilever.json").write_text(json.dumps(
            {"points": {case: {c: [p.__dict__ for p in pts] for c, pts in codes.items()} for case, codes in cant.items()}}))
    else:
        cant = load("cantilever")
    results = {}
    for name in MODULES:
        if name in only:
            results[name] = dynamic(name, repeats, args.quick, log)
            if name == "sliding joint":
                try:
                    results[name]["damping"] = damping_law_effect(log)
                except Exception as exc:  # the report still gets written, without the row
                    log(f"damping-law comparison failed: {exc}")
            save(name, results[name])
        elif load(name) is not None:
            results[name] = load(name)
    results = {name: with_ratios(res) for name, res in results.items()}
    wall_file = CACHE / "run_wall.json"
    if only:
        wall_file.write_text(json.dumps(time.perf_counter() - t0))
    path = write_report(results, cant, json.loads(wall_file.read_text()) if wall_file.is_file() else float("nan"))
    log(f"wrote {path}")


if __name__ == "__main__":
    main()
