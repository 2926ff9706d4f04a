"""Static equilibrium by Newton's method with adaptive load stepping.

Solves ``f_int(q) + lambda f_ext(q) = 0`` on the free coordinates for ``lambda`` from 0 to 1
(internal forces include prestrain, so a pretensioned wire is loaded from the start). Each
load step is a damped Newton iteration with the compiled sparse tangent; a step that fails is
halved, one that converges quickly lets the next grow.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse.linalg as spla

from ..assembly.system import System
from ..errors import SolverError
from ..progress import Progress


@dataclass
class StaticResult:
    """Outcome of :func:`solve_static`.

    Attributes
    ----------
    q : ndarray
        Equilibrium coordinates (the last converged state if ``converged`` is False).
    load_factor : float
        Load factor reached (1 on success).
    load_steps, newton_iterations : int
        Accepted load steps and total Newton iterations.
    residual_norm : float
        Max-norm of the free residual at ``q`` (N).
    wall_s : float
        Wall time (s).
    history : list of (load_factor, iterations)
    """

    q: np.ndarray
    load_factor: float
    load_steps: int
    newton_iterations: int
    residual_norm: float
    wall_s: float
    converged: bool = True
    history: list = field(default_factory=list)

    def stats(self) -> dict:
        return {
            "load_steps": self.load_steps,
            "newton_iterations": self.newton_iterations,
            "residual_norm_N": self.residual_norm,
        }


def solve_static(
    system: System,
    q0: np.ndarray | None = None,
    load_steps: int = 1,
    rtol: float = 1e-9,
    max_iterations: int = 25,
    min_step: float = 1e-4,
    progress: bool = False,
) -> StaticResult:
    """Static equilibrium of ``system`` under its full load.

    Parameters
    ----------
    system : System
        Assembled scene.
    q0 : ndarray, optional
        Starting guess (default: the scene's initial coordinates).
    load_steps : int
        Initial number of equal load increments (the stepping adapts from there).
    rtol : float
        Convergence when the free residual's max-norm is below ``rtol`` times the load scale,
        or when a full Newton step changes no coordinate by more than 1e-10 (relative).
    max_iterations : int
        Newton iterations allowed per load step before the step is halved.
    min_step : float
        Smallest load increment before giving up.
    progress : bool
        Show a progress bar of the load factor.

    Raises
    ------
    SolverError
        With the load factor reached, the reason, and the partial :class:`StaticResult`.
    """
    t_start = time.perf_counter()
    free = system.dofs.free
    q = np.array(system.dofs.q0 if q0 is None else q0, dtype=float)
    scale = _load_scale(system, q)
    lam, step = 0.0, 1.0 / max(1, int(load_steps))
    total_iterations, accepted, history = 0, 0, []
    bar = Progress("statics", total=1.0, unit="load", enabled=progress)

    # Equilibrate the internal forces first (prestrain with no external load).
    ok, q_try, its, reason = _newton(system, q, 0.0, free, scale, rtol, max_iterations)
    total_iterations += its
    if ok:
        q = q_try
    while lam < 1.0:
        target = min(1.0, lam + step)
        ok, q_try, its, reason = _newton(system, q, target, free, scale, rtol, max_iterations)
        total_iterations += its
        if ok:
            q, lam = q_try, target
            accepted += 1
            history.append((lam, its))
            bar.update(lam)
            if its <= 8:
                step = min(2 * step, 1.0)
        else:
            step /= 2
            if step < min_step:
                bar.close()
                res = np.abs(system.eval_static(q, lam)[0][free]).max()
                partial = StaticResult(q, lam, accepted, total_iterations, res, time.perf_counter() - t_start, False, history)
                raise SolverError(
                    f"static solve stopped at load factor {lam:.4g} of 1: {reason}; the load increment fell "
                    f"below min_step={min_step:g}. Try more load_steps, or check supports (a mechanism) and "
                    "loads; the partial result is in .partial",
                    partial,
                )
    bar.close()
    r = np.abs(system.eval_static(q, 1.0)[0][free]).max() if free.size else 0.0
    return StaticResult(q, 1.0, accepted, total_iterations, float(r), time.perf_counter() - t_start, True, history)


def _load_scale(system: System, q: np.ndarray) -> float:
    f_ext = system.external_force_value(q)
    r0, _ = system.eval_static(q, 0.0)
    return max(np.abs(f_ext).max(initial=0.0), np.abs(r0).max(initial=0.0), 1.0)


def _newton(system, q, lam, free, scale, rtol, max_iterations, xtol=1e-10):
    """Damped Newton iteration at a fixed load factor; returns (ok, q, iterations, reason)."""
    q = q.copy()
    r, jac = system.eval_static(q, lam)
    norm = np.abs(r[free]).max(initial=0.0)
    norm0 = max(norm, rtol * scale)
    tol = rtol * scale
    for it in range(1, max_iterations + 1):
        if norm <= tol:
            return True, q, it - 1, ""
        j_ff = jac[free][:, free]
        try:
            dq = spla.spsolve(j_ff.tocsc(), -r[free])
        except RuntimeError as exc:  # singular factor
            return False, q, it, f"singular tangent ({exc})"
        if not np.all(np.isfinite(dq)):
            return False, q, it, "singular tangent (a mechanism or an unloaded slack cable?)"
        if np.abs(dq).max() <= xtol * (1 + np.abs(q).max()):
            # The correction is at round-off: the residual of stiff wires (EA ~ 1e9 N) cannot
            # get below ~1e-16 EA, whatever the force tolerance says.
            q[free] += dq
            return True, q, it, ""
        # Full Newton steps: the residual norm is a poor merit function for wires (a small
        # transverse step excites EA-sized axial residuals that the next step removes), so
        # divergence is caught by the load-step control instead of a line search.
        q = q.copy()
        q[free] += dq
        r, jac = system.eval_static(q, lam)
        norm = np.abs(r[free]).max(initial=0.0)
        if not np.isfinite(norm):
            return False, q, it, "non-finite residual"
        if norm > 1e8 * norm0:
            return False, q, it, f"Newton diverged (residual {norm:.3g} N)"
    if norm <= tol:
        return True, q, max_iterations, ""
    return False, q, max_iterations, f"Newton did not converge in {max_iterations} iterations (residual {norm:.3g} N)"
