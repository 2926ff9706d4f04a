"""Timing, work-precision curves and the ratio of two codes' times at equal error."""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field

import numpy as np

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("SYMCAT_OPTIMIZE", "now")  # any compiled model DAE at its optimized tier, as `make bench`


@dataclass
class Point:
    """One run of one code: its setting, error against its own reference and wall times (s)."""

    code: str
    label: str
    error: float
    walls: list = field(default_factory=list)
    info: str = ""

    @property
    def wall(self) -> float:
        return float(np.median(self.walls))


def outputs(res, n_out: int) -> np.ndarray:
    """``res.q`` of a symcat run, checked to be on the bench's output grid of ``n_out``
    intervals (generalized-alpha gives at most one output per step)."""
    if len(res.t_s) != n_out + 1:
        raise ValueError(f"{len(res.t_s)} outputs, not {n_out + 1}: use a step that divides the output interval")
    return np.asarray(res.q)


def symcat_solve(model, t_end: float, n_out: int, setting: dict, rho: float):
    """``res.q`` of ``model`` over ``t_end`` (s) at ``n_out`` intervals: IDAS for ``{"rtol": ...}``
    (atol = rtol / 100), else generalized-alpha at ``setting["dt"]`` with spectral radius
    ``setting.get("rho", rho)``, Newton tolerance ``setting.get("tol", 1e-10)`` and compiled
    steps as ``setting.get("compiled")`` (None: the library's default). Only positions are
    compared: generalized-alpha keeps its own multipliers (no KKT solve per output), as
    Exudyn reports its sensors."""
    from symcat.integrate import simulate
    from symcat.integrate.generalized_alpha import generalized_alpha

    if "rtol" in setting:
        res = simulate(model, t_end, rtol=setting["rtol"], atol=setting["rtol"] * 1e-2, n_out=n_out, progress=False)
    else:
        res = generalized_alpha(model, t_end, setting["dt"], rho_inf=setting.get("rho", rho), n_out=n_out,
                                progress=False, tol=setting.get("tol", 1e-10), multipliers="integrator",
                                compiled=setting.get("compiled"))
    return outputs(res, n_out)


def exudyn_solve(exu, mbs, sensor, t_end: float, n_out: int, setting: dict, rho: float,
                 modified_newton: bool = True) -> np.ndarray:
    """Exudyn's generalized-alpha (spectral radius ``rho``, modified Newton or not, at relative
    tolerance ``setting.get("newton_rtol", 1e-8)``, one thread, Eigen's sparse solver) at
    ``setting["dt"]`` over ``t_end`` (s); the sensor's stored data (time first)."""
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.solutionSettings.writeSolutionToFile = False
    s.solutionSettings.sensorsWritePeriod = t_end / n_out
    s.timeIntegration.numberOfSteps = int(round(t_end / setting["dt"]))
    s.timeIntegration.endTime = t_end
    s.timeIntegration.generalizedAlpha.spectralRadius = rho
    if modified_newton:
        s.timeIntegration.newton.useModifiedNewton = True
    s.timeIntegration.newton.relativeTolerance = setting.get("newton_rtol", 1e-8)
    s.timeIntegration.verboseMode = 0
    s.parallel.numberOfThreads = 1
    s.linearSolverType = exu.LinearSolverType.EigenSparse
    mbs.SolveDynamic(s)
    return np.asarray(mbs.GetSensorStoredData(sensor))


def timed(fn, *args, **kwargs):
    """``(result, wall_s)`` of one call."""
    t = time.perf_counter()
    out = fn(*args, **kwargs)
    return out, time.perf_counter() - t


def interleaved(runs: dict, repeats: int) -> dict:
    """Run every ``name -> callable`` ``repeats`` times, alternating the callables, and
    return ``name -> (last result, [walls])``: the two codes see the same machine load."""
    out = {name: (None, []) for name in runs}
    for _ in range(repeats):
        for name, fn in runs.items():
            result, wall = timed(fn)
            out[name] = (result, out[name][1] + [wall])
    return out


def pareto(points: list[Point]) -> np.ndarray:
    """``(wall, error)`` rows of the points no other point beats in both, by increasing wall."""
    pts = sorted(((p.wall, max(p.error, 1e-300)) for p in points if np.isfinite(p.error)))
    front, best = [], np.inf
    for w, e in pts:
        if e < best:
            front.append((w, e))
            best = e
    return np.array(front).reshape(-1, 2)


def wall_at_error(front: np.ndarray, error: float) -> float:
    """Wall time of a curve at ``error``, interpolated in log-log (NaN outside its range)."""
    if front.size == 0:
        return np.nan
    w, e = np.log(front[:, 0]), np.log(front[:, 1])
    le = np.log(error)
    if le > e.max() + 1e-12 or le < e.min() - 1e-12:
        return np.nan
    order = np.argsort(e)
    return float(np.exp(np.interp(le, e[order], w[order])))


def ratios(sym: list[Point], exu: list[Point]) -> list[tuple[float, float, float, float]]:
    """``(error, symcat wall, Exudyn wall, ratio)`` at the errors of both codes' points that lie
    in the overlap of the two curves' error ranges."""
    fs, fe = pareto(sym), pareto(exu)
    if fs.size == 0 or fe.size == 0:
        return []
    rows = []
    for e in sorted(set(fs[:, 1]) | set(fe[:, 1]), reverse=True):
        ws, we = wall_at_error(fs, e), wall_at_error(fe, e)
        if np.isfinite(ws) and np.isfinite(we) and (not rows or e < 0.95 * rows[-1][0]):
            rows.append((e, ws, we, ws / we))  # one row for points of (nearly) equal error
    return rows


def plot(path, title: str, curves: dict, xlabel="wall time [s]", ylabel="error [m]"):
    """Work-precision figure: ``label -> list of Point`` on log-log axes, one PNG."""
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    styles = {"symcat": "o-", "Exudyn": "s--"}
    for label, points in curves.items():
        pts = sorted((p.wall, max(p.error, 1e-16)) for p in points if np.isfinite(p.error))
        if not pts:
            continue
        pts = np.array(pts)
        style = next((s for k, s in styles.items() if label.startswith(k)), "^-")
        ax.loglog(pts[:, 0], pts[:, 1], style, label=label)
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    import textwrap

    ax.set_title("\n".join(textwrap.wrap(title, 70)), fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
