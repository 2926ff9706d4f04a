"""Time integration of a :class:`CoupledLine` by the generalized-alpha method.

Chung-Hulbert generalized-alpha in the form of Arnold and Bruls (2007): equilibrium is enforced
at the end of each step, which suits contact. The Newton iteration is a modified one: the
iteration matrix ``S = M + gamma' C + beta' K`` uses the stiffness at static equilibrium and is
factorised once; the contact stiffness (penalty) or the contact constraint (bilateral) enters
through a Woodbury / Schur update with one extra back-substitution per contact and step, since
the contact point moves every step. Slack droppers and geometric nonlinearity only change the
residual. When a step does not converge, the matrix is refactorised at the current tangent and
the step retried, then the step is halved.
"""
from __future__ import annotations

import math
import time

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..errors import ParameterError, SolverError
from ..integrate.alpha_coefficients import AlphaCoefficients
from ..progress import Progress
from ..run_control import check_interrupt, ended_early, integrating
from ..assembly.banded import BandedCholesky
from .coupled import CoupledLine
from .recorder import PassageRecorder


class _Stepper:
    """One step size: coefficients and the factorised iteration matrix."""

    def __init__(self, line: CoupledLine, h: float, coef: AlphaCoefficients, stiffness=None):
        self.h = h
        a_m, a_f = coef.alpha_m, coef.alpha_f
        self.beta_p = h * h * coef.beta * (1 - a_f) / (1 - a_m)
        self.gamma_p = h * coef.gamma * (1 - a_f) / (1 - a_m)
        k = line.K if stiffness is None else stiffness
        s = (line.M + self.gamma_p * line.C + self.beta_p * k).tocsr()
        self.lu = BandedCholesky(s, getattr(line, "_band_permutation", None))
        line._band_permutation = self.lu.permutation  # same pattern for every step size
        self._columns: dict[int, np.ndarray] = {}

    def column(self, i: int) -> np.ndarray:
        """``S^-1 e_i``, cached: a contact's ``S^-1 g`` is a weighted sum of a few of these, and
        the contact stays on the same element for many steps."""
        col = self._columns.get(i)
        if col is None:
            if len(self._columns) > 64:
                self._columns.clear()
            e = np.zeros(self.lu.n)
            e[i] = 1.0
            col = self._columns[i] = self.lu.solve(e)
        return col

    def influence(self, states) -> np.ndarray:
        """``S^-1 g`` of every contact (n x n_contacts)."""
        z = np.zeros((self.lu.n, len(states)))
        for p, s in enumerate(states):
            for i, w in zip(s.g_index, s.g):
                z[:, p] += w * self.column(int(i))
        return z


def integrate(line: CoupledLine, t_end: float, dt: float = 1e-3, rho_inf: float = 0.8, tol: float = 1e-8,
              max_iterations: int = 12, record_every: float = 0.01, progress: bool = True,
              y0=None, contact_forces0=None) -> PassageRecorder:
    """Integrate ``line`` from its static equilibrium (or ``y0``) to ``t_end`` (s).

    Parameters
    ----------
    dt : float
        Time step (s).
    rho_inf : float
        High-frequency spectral radius (1: no numerical damping; 0.8 damps mesh-scale noise).
    tol : float
        Newton convergence on the update of the coordinates (m).
    record_every : float
        Interval of full-state snapshots (s); contact quantities are recorded every step.

    Returns
    -------
    PassageRecorder
        Everything recorded; on failure a :class:`SolverError` carries it as ``partial``.
    """
    if not dt > 0:
        raise ParameterError(f"dt={dt:g} s: must be > 0")
    from ..threads import serial_blas

    with serial_blas():
        return _integrate(line, t_end, dt, rho_inf, tol, max_iterations, record_every, progress, y0, contact_forces0)


def _integrate(line, t_end, dt, rho_inf, tol, max_iterations, record_every, progress, y0, contact_forces0):
    if not t_end >= 0:
        raise ParameterError(f"t_end={t_end:g} s: must be >= 0")
    coef = AlphaCoefficients(rho_inf)
    wall0 = time.perf_counter()
    if y0 is None:
        y, fc = line.static_state()
    else:
        y, fc = np.array(y0, float), np.array(contact_forces0, float)
    v = np.zeros(line.n)
    f, states, fc = line.forces(y, v, 0.0, None, fc if line.contact == "bilateral" else None)
    acc = spla.spsolve(line.M.tocsc(), f)
    a = acc.copy()
    rec = PassageRecorder(line, record_every)
    rec.record(0.0, y, v, acc, states, fc, iterations=0)
    # equal steps no longer than dt: a uniform grid for the filters, and no sliver of a last step
    n_steps = int(math.ceil(t_end / dt - 1e-6))
    dt = t_end / n_steps if n_steps else dt
    stepper = _Stepper(line, dt, coef)
    bar = Progress("passage", total=t_end, unit="s", enabled=progress)
    t, refactorisations, halvings = 0.0, 0, 0
    acc_prev = None
    lam = fc.copy()
    try:
        with integrating():
            for step in range(n_steps):
                h_target = dt
                result = _step(line, stepper, coef, t, y, v, acc, a, lam, tol, max_iterations, acc_prev)
                if result is None:  # refactorise at the current tangent and retry, then halve
                    refactorisations += 1
                    k_now = _current_stiffness(line, y)
                    result = _step(line, _Stepper(line, h_target, coef, k_now), coef, t, y, v, acc, a, lam, tol,
                                   max_iterations)
                    sub = 1
                    while result is None and sub < 16:
                        sub *= 2
                        halvings += 1
                        result = _substeps(line, coef, t, y, v, acc, a, lam, tol, max_iterations, h_target, sub)
                    if result is None:
                        raise SolverError(f"generalized-alpha: Newton did not converge at t={t:.6g} s even with the step "
                                          f"divided by {sub}; look at the contact force and dropper states recorded "
                                          "up to this time", rec)
                acc_prev = acc
                y, v, acc, a, lam, states, iters = result
                t = (step + 1) * dt
                rec.record(t, y, v, acc, states, lam, iters)
                bar.update(t)
                check_interrupt(t, t_end)
    except SolverError as err:
        err.partial = rec
        if not ended_early(err, t, t_end):
            raise
    finally:
        bar.close()
    rec.finish(wall_s=time.perf_counter() - wall0, dt=dt, rho_inf=rho_inf, refactorisations=refactorisations,
               halvings=halvings)
    return rec


def _current_stiffness(line: CoupledLine, y: np.ndarray):
    k_cat = line.structure.stiffness(line.catenary_q(y))[line.free][:, line.free]
    return sps.block_diag([k_cat] + line.K_panto, format="csc")


def _substeps(line, coef, t, y, v, acc, a, lam, tol, max_iterations, h, sub):
    stepper = _Stepper(line, h / sub, coef)
    iters_total = 0
    for k in range(sub):
        res = _step(line, stepper, coef, t + k * h / sub, y, v, acc, a, lam, tol, max_iterations)
        if res is None:
            return None
        y, v, acc, a, lam, states, iters = res
        iters_total += iters
    return y, v, acc, a, lam, states, iters_total


def _step(line: CoupledLine, st: _Stepper, coef: AlphaCoefficients, t, y, v, acc, a, lam, tol, max_iterations,
          acc_prev=None):
    """One generalized-alpha step from t to t + h; None if Newton does not converge.

    The predictor extrapolates the acceleration linearly from the last two steps (one Newton
    iteration per step instead of 1.24 on the benchmark at 0.5 ms)."""
    h = st.h
    a_m, a_f, beta, gamma = coef.alpha_m, coef.alpha_f, coef.beta, coef.gamma
    t1 = t + h
    acc1 = acc.copy() if acc_prev is None else 2 * acc - acc_prev
    lam1 = np.array(lam, dtype=float)
    base_y = y + h * v + h * h * (0.5 - beta) * a
    base_v = v + h * (1 - gamma) * a
    n_c = len(line.runs)
    z = None
    bilateral = line.contact == "bilateral"
    for it in range(1, max_iterations + 1):
        a1 = (a_f * acc + (1 - a_f) * acc1 - a_m * a) / (1 - a_m)
        y1 = base_y + h * h * beta * a1
        v1 = base_v + h * gamma * a1
        states = line.contact_states(y1, v1, t1)
        f, states, fc = line.forces(y1, v1, t1, states, lam1 if bilateral else None)
        r = line.M_csr @ acc1 - f
        if z is None:  # S^-1 g of every contact (the point moves little within a step)
            z = st.influence(states)
        g_rows = [s.g_index for s in states]
        x = st.lu.solve(-r)
        if bilateral:
            delta = np.array([s.delta for s in states])
            gz = np.array([[states[i].g @ z[g_rows[i], j] for j in range(n_c)] for i in range(n_c)])
            gx = np.array([s.g @ x[s.g_index] for s in states])
            d_lam = np.linalg.solve(gz, gx + delta / st.beta_p)
            d_acc = x - z @ d_lam
            lam1 = lam1 + d_lam
        else:
            active = [i for i, s in enumerate(states) if s.delta > 0]
            d_acc = x
            if active:
                w = np.array([line.k_c * st.beta_p + line.c_c * st.gamma_p for _ in active])
                za = z[:, active]
                gz = np.array([[states[i].g @ za[g_rows[i], j] for j in range(len(active))] for i in active])
                gx = np.array([states[i].g @ x[g_rows[i]] for i in active])
                d_acc = x - za @ np.linalg.solve(np.diag(1.0 / w) + gz, gx)
        acc1 = acc1 + d_acc
        dy = st.beta_p * np.abs(d_acc).max()
        if dy < tol and (not bilateral or np.abs(delta).max() < 10 * tol):
            a1 = (a_f * acc + (1 - a_f) * acc1 - a_m * a) / (1 - a_m)
            y1 = base_y + h * h * beta * a1
            v1 = base_v + h * gamma * a1
            states = line.contact_states(y1, v1, t1)
            if not bilateral:
                lam1 = np.array([line.penalty_force(s) for s in states])
            return y1, v1, acc1, a1, lam1, states, it
    return None
