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

    # Step from the initial state straight towards the first load level: a slack cable has no
    # equilibrium without its load, so lambda = 0 itself is not solved first.
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
                    "loads",
                    partial,
                )
    bar.close()
    r = np.abs(system.eval_static(q, 1.0)[0][free]).max() if free.size else 0.0
    return StaticResult(q, 1.0, accepted, total_iterations, float(r), time.perf_counter() - t_start, True, history)


def _load_scale(system: System, q: np.ndarray) -> float:
    f_ext = system.external_force_value(q)
    r0, _ = system.eval_static(q, 0.0)
    return max(np.abs(f_ext).max(initial=0.0), np.abs(r0).max(initial=0.0), 1.0)


def _line_search(system, q, dq, free, lam, s0, max_trials=5):
    """Step length along ``dq`` that makes the slope ``dq . R`` small (secant iterations)."""
    def trial(alpha):
        q_a = q.copy()
        q_a[free] += alpha * dq
        r_a, j_a = system.eval_static(q_a, lam)
        return q_a, r_a, j_a, dq @ r_a[free]

    best = None
    a_prev, s_prev = 0.0, s0
    alpha = 1.0
    for _ in range(max_trials):
        q_a, r_a, j_a, s_a = trial(alpha)
        if not np.isfinite(s_a):
            alpha /= 4
            continue
        if best is None or abs(s_a) < abs(best[4]):
            best = (q_a, r_a, j_a, alpha, s_a)
        if abs(s_a) <= 0.5 * abs(s0):
            break
        denom = s_a - s_prev
        step = alpha - s_a * (alpha - a_prev) / denom if denom != 0 else 2 * alpha
        a_prev, s_prev = alpha, s_a
        alpha = float(np.clip(step, 0.05, 4.0))
    if best is None:
        return (*trial(1e-3)[:3], 1e-3)
    return best[0], best[1], best[2], best[3]


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
        # Line search on the slope s(alpha) = dq . R(q + alpha dq) of the total potential along
        # dq (Crisfield): the residual norm itself is a poor merit function for wires, where a
        # good transverse step leaves large axial residuals that the next step removes.
        s0 = dq @ r[free]
        q_new, r_new, jac_new, alpha = _line_search(system, q, dq, free, lam, s0)
        q, r, jac = q_new, r_new, jac_new
        norm = np.abs(r[free]).max(initial=0.0)
        if not np.isfinite(norm):
            return False, q, it, "non-finite residual"
        if norm > 1e8 * norm0:
            return False, q, it, f"Newton diverged (residual {norm:.3g} N)"
    if norm <= tol:
        return True, q, max_iterations, ""
    return False, q, max_iterations, f"Newton did not converge in {max_iterations} iterations (residual {norm:.3g} N)"
