"""Static equilibrium by Newton's method with adaptive load stepping.

Solves ``f_int(q) + lambda f_ext(q) = 0`` on the free coordinates for ``lambda`` from 0 to 1
(internal forces include prestrain, so a pretensioned wire is loaded from the start). Each
load step first tries a plain (undamped) Newton iteration, and if that fails a damped one
with a line search; a step that fails both is halved, one that converges quickly lets the
next grow.

An iteration costs one call of a compiled function of the free coordinates (the free residual
and the free block of the tangent, :class:`_FreeNewton`) and one sparse LU solve: a banded
LAPACK factorization in a bandwidth-reducing order when the tangent is banded (wires, beams),
SuperLU otherwise. There is no Python work per element or per nonzero.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg.lapack as lapack
import scipy.sparse as sps
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ..assembly.sparse import Congruence
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
        Initial number of equal load increments (the stepping adapts from there). With the
        default 1 the full load is tried in one step: plain Newton first, then damped Newton;
        the load is split only if both fail.
    rtol : float
        Convergence when the free residual's max-norm is below ``rtol`` times the load scale,
        or when a full Newton step changes no coordinate by more than 1e-10 (relative).
    max_iterations : int
        Newton iterations allowed per load step and method (plain, then damped) before the
        step is halved.
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
    newton = _FreeNewton.of(system)
    scale = _load_scale(system, newton, q)
    lam, step = 0.0, 1.0 / max(1, int(load_steps))
    total_iterations, accepted, history = 0, 0, []
    bar = Progress("statics", total=1.0, unit="load", enabled=progress)

    # Step from the initial state straight towards the first load level: a slack cable has no
    # equilibrium without its load, so lambda = 0 itself is not solved first.
    while lam < 1.0:
        target = min(1.0, lam + step)
        if not free.size:
            ok, q_try, its, reason = True, q, 0, ""
        else:
            ok, q_try, its, reason = _plain_newton(newton, q, target, scale, rtol, max_iterations)
            if not ok:
                ok, q_try, its_damped, reason = _newton(newton, q, target, scale, rtol, max_iterations)
                its += its_damped
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
                res = np.abs(newton.residual(q, lam)).max()
                partial = StaticResult(q, lam, accepted, total_iterations, res, time.perf_counter() - t_start, False, history)
                raise SolverError(
                    f"static solve stopped at load factor {lam:.4g} of 1: {reason}; the load increment fell "
                    f"below min_step={min_step:g}. Try more load_steps, or check supports (a mechanism) and "
                    "loads",
                    partial,
                )
    bar.close()
    r = np.abs(newton.residual(q, 1.0)).max() if free.size else 0.0
    return StaticResult(q, 1.0, accepted, total_iterations, float(r), time.perf_counter() - t_start, True, history)


def _load_scale(system: System, newton: "_FreeNewton", q: np.ndarray) -> float:
    f_ext = system.external_force_value(q)
    r0 = newton.full_residual(q, 0.0)
    return max(np.abs(f_ext).max(initial=0.0), np.abs(r0).max(initial=0.0), 1.0)


class _FreeNewton:
    """The static residual and tangent on the free coordinates, and the linear solve of a
    Newton step.

    The residual ``f_int(q) + lambda f_ext(q)`` and its tangent are evaluated numerically
    (:meth:`System.eval_internal_force`, :meth:`System.eval_force_jacobians`: the element
    kernels mapped and scattered in NumPy) and the tangent's free block taken by a fixed linear
    map of its nonzeros (:class:`~symcat.assembly.sparse.Congruence`). Its nonzeros go into
    LAPACK band storage through a precomputed index (reverse Cuthill-McKee order) and are
    factorized by ``dgbsv``; when the reordered tangent is not banded enough, SuperLU
    factorizes it in CSC form instead. Built once per system (and set of free coordinates)
    and reused by later solves.
    """

    @classmethod
    def of(cls, system: System) -> "_FreeNewton":
        free = system.dofs.free
        # kept on the system, so that it goes with it (a weak-key table would hold it for
        # ever: the value refers to its key)
        per_system = system.__dict__.setdefault("_free_newton", {})
        key = free.tobytes()
        if key not in per_system:
            per_system[key] = cls(system, free)
        return per_system[key]

    def __init__(self, system: System, free: np.ndarray):
        n = system.n
        self.system = system
        self.free = free
        nf = free.size
        k_sum = system.force_jacobian_patterns(damping=False)[0]
        pick = sps.csr_matrix((np.ones(nf), (free, np.arange(nf))), shape=(n, nf))
        self._free_block = Congruence(pick, k_sum.indptr, k_sum.indices)
        colind, row = self._free_block.indptr, self._free_block.indices
        col = np.repeat(np.arange(nf), np.diff(colind))
        pattern = sps.csc_matrix((np.ones(row.size), row, colind), shape=(nf, nf))
        self._csc = (row, colind, (nf, nf))
        perm = reverse_cuthill_mckee((pattern + pattern.T).tocsr(), symmetric_mode=True) if nf else np.arange(0)
        inverse = np.empty(nf, int)
        inverse[perm] = np.arange(nf)
        i, j = inverse[row], inverse[col]
        kl = int(max((i - j).max(initial=0), 0))
        ku = int(max((j - i).max(initial=0), 0))
        # Band LU costs O(n kl (kl + ku)); beyond a quarter of n a general sparse LU is cheaper.
        self.banded = nf > 0 and max(kl, ku) <= max(8, nf // 4)
        if self.banded:
            self._perm, self._kl, self._ku = perm, kl, ku
            shape = (2 * kl + ku + 1, nf)
            # LAPACK band storage (Fortran order): A[i, j] at ab[kl + ku + i - j, j].
            self._band_index = np.ravel_multi_index((kl + ku + i - j, j), shape, order="F")
            self._band_shape = shape

    def evaluate(self, q: np.ndarray, load_factor: float) -> tuple[np.ndarray, np.ndarray]:
        """Free residual and the tangent's nonzeros (the free block's CSC order) at ``q``."""
        k = self.system.eval_force_jacobians(q, load_factor=load_factor)[0]
        return self.full_residual(q, load_factor)[self.free], -self._free_block.data(k.data)

    def residual(self, q: np.ndarray, load_factor: float) -> np.ndarray:
        return self.full_residual(q, load_factor)[self.free]

    def full_residual(self, q: np.ndarray, load_factor: float) -> np.ndarray:
        """Residual on every coordinate (minus the reactions on the fixed ones)."""
        system = self.system
        return system.eval_internal_force(q) + load_factor * system.external_force_value(q)

    def solve(self, jac_nz: np.ndarray, rhs: np.ndarray) -> np.ndarray | None:
        """``J_ff^-1 rhs`` (None if the tangent is singular)."""
        if self.banded:
            ab = np.zeros(self._band_shape[0] * self._band_shape[1])
            ab[self._band_index] = jac_nz
            ab = ab.reshape(self._band_shape, order="F")
            b = rhs[self._perm].copy()
            _, _, x, info = lapack.dgbsv(self._kl, self._ku, ab, b, overwrite_ab=True, overwrite_b=True)
            if info != 0:
                return None
            out = np.empty_like(x)
            out[self._perm] = x
            return out
        row, colind, shape = self._csc
        try:
            return spla.splu(sps.csc_matrix((jac_nz, row, colind), shape=shape)).solve(rhs)
        except RuntimeError:  # exactly singular factor
            return None


def _plain_newton(newton: _FreeNewton, q, lam, scale, rtol, max_iterations, xtol=1e-10):
    """Undamped Newton iteration at a fixed load factor: fast when it converges, and it does
    from a straight start for the cantilever or the taut wire in one load step. Fails (for the
    damped iteration to take over) on a non-finite or singular step, or on a residual grown
    far beyond the start's. Returns (ok, q, iterations, reason)."""
    q = q.copy()
    free = newton.free
    tol = rtol * scale
    norm0 = None
    for it in range(1, max_iterations + 1):
        r, jac_nz = newton.evaluate(q, lam)
        norm = np.abs(r).max(initial=0.0)
        if not np.isfinite(norm):
            return False, q, it, "non-finite residual"
        if norm <= tol:
            return True, q, it - 1, ""
        norm0 = norm if norm0 is None else norm0
        if norm > 1e6 * norm0:
            return False, q, it, f"Newton diverged (residual {norm:.3g} N)"
        dq = newton.solve(jac_nz, -r)
        if dq is None or not np.all(np.isfinite(dq)):
            return False, q, it, "singular tangent (a mechanism or an unloaded slack cable?)"
        q[free] += dq
        if np.abs(dq).max() <= xtol * (1 + np.abs(q).max()):
            # The correction is at round-off (see _newton).
            return True, q, it, ""
    r = newton.residual(q, lam)
    if np.abs(r).max(initial=0.0) <= tol:
        return True, q, max_iterations, ""
    return False, q, max_iterations, f"plain Newton did not converge in {max_iterations} iterations"


def _line_search(newton, q, dq, lam, s0, max_trials=5):
    """Step length along ``dq`` that makes the slope ``dq . R`` small (secant iterations)."""
    free = newton.free

    def trial(alpha):
        q_a = q.copy()
        q_a[free] += alpha * dq
        r_a, j_a = newton.evaluate(q_a, lam)
        return q_a, r_a, j_a, dq @ r_a

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


def _newton(newton, q, lam, scale, rtol, max_iterations, xtol=1e-10):
    """Damped Newton iteration at a fixed load factor; returns (ok, q, iterations, reason)."""
    q = q.copy()
    r, jac = newton.evaluate(q, lam)
    norm = np.abs(r).max(initial=0.0)
    norm0 = max(norm, rtol * scale)
    tol = rtol * scale
    for it in range(1, max_iterations + 1):
        if norm <= tol:
            return True, q, it - 1, ""
        dq = newton.solve(jac, -r)
        if dq is None or not np.all(np.isfinite(dq)):
            return False, q, it, "singular tangent (a mechanism or an unloaded slack cable?)"
        if np.abs(dq).max() <= xtol * (1 + np.abs(q).max()):
            # The correction is at round-off: the residual of stiff wires (EA ~ 1e9 N) cannot
            # get below ~1e-16 EA, whatever the force tolerance says.
            q[newton.free] += dq
            return True, q, it, ""
        # Line search on the slope s(alpha) = dq . R(q + alpha dq) of the total potential along
        # dq (Crisfield): the residual norm itself is a poor merit function for wires, where a
        # good transverse step leaves large axial residuals that the next step removes.
        s0 = dq @ r
        q_new, r_new, jac_new, alpha = _line_search(newton, q, dq, lam, s0)
        q, r, jac = q_new, r_new, jac_new
        norm = np.abs(r).max(initial=0.0)
        if not np.isfinite(norm):
            return False, q, it, "non-finite residual"
        if norm > 1e8 * norm0:
            return False, q, it, f"Newton diverged (residual {norm:.3g} N)"
    if norm <= tol:
        return True, q, max_iterations, ""
    return False, q, max_iterations, f"Newton did not converge in {max_iterations} iterations (residual {norm:.3g} N)"
