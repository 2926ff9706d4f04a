"""Static equilibrium of a multibody model (rigid bodies, ANCF wires, joints, sliding joints,
penalty contacts), the state every dynamic run should start from.

Unknowns ``u = [q, s, s_c, lambda]`` (free coordinates, sliding-joint and contact arc lengths,
multipliers) solve the KKT system at ``v = 0``::

    R(u) = [Q(q, s_c) - C_q^T lambda,  -C_s^T lambda,  C(q, s, t),  T(q, s_c)] = 0

whose iteration matrices are those of a generalized-alpha step from rest (:class:`_StepSystem`):
the wires' banded Cholesky and the rest's Woodbury update, shared with the time integration.

Plain Newton stalls here: a frictionless sliding point on a straight wire has no stiffness
along the wire until the wire sags (a singular Jacobian at the start, and a load continuation
jumps: for any load the point belongs at the lowest place, not where it started), and the
curvature of the C1 interpolation jumps at element ends, so residual-norm backtracking rejects
good steps there. The solver therefore uses *pseudo-transient continuation*: each iteration is
an implicit step of the motion from rest, ``(J - M / h^2) du = -R`` (``M`` the mass matrix on
the coordinates, nothing on arc lengths and multipliers), whose pseudo time step ``h`` grows as
the force residual falls (switched evolution relaxation) until it is infinite and the iteration
is (nearly) Newton's method, with its fast convergence. The pseudo-inertia bounds every step
while the motion is large, follows the stable (energy-decreasing) branch, and makes the matrix
regular; a step whose residual explodes is retried with a quarter of ``h``. Arc lengths move
at most a quarter element per iteration. ``h`` stops at ``max_pseudo_time``, where ``M / h^2``
is a negligible stiffness that still keeps neutral directions (a body spinning freely about its
contact point) regular.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..assembly.multibody import MultibodyModel
from ..dae.formulation import Formulation
from ..errors import SolverError
from ..integrate.results import joint_reactions


@dataclass
class EquilibriumResult:
    """Outcome of :func:`solve_equilibrium`.

    Attributes
    ----------
    q : ndarray (n_q,)
        All generalized coordinates at equilibrium (fixed ones included).
    s_m, sc_m : ndarray
        Arc lengths (m) of the sliding joints and of the penalty contacts.
    multipliers : ndarray (n_c,)
        Lagrange multipliers (``row_names`` of the model).
    residual_N : float
        Max-norm of the force rows ``Q - C_q^T lambda`` (N, N m).
    constraint_residual : float
        Max-norm of ``C`` and of the tangency conditions (m).
    iterations : int
    wall_s : float
    history : list of (iteration, h, force residual, accepted)
    reactions_N : dict
        Joint name -> constraint force (global, N) on the joint's ``body`` (sliding, driving)
        or ``body_j``, as in :class:`symcat.integrate.SimulationResult`.
    contact_gap_m, contact_force_N : dict
        Penalty contact name -> normal gap (m) and normal force (N).
    """

    q: np.ndarray
    s_m: np.ndarray
    sc_m: np.ndarray
    multipliers: np.ndarray
    residual_N: float
    constraint_residual: float
    iterations: int
    wall_s: float
    history: list = field(default_factory=list)
    reactions_N: dict = field(default_factory=dict)
    contact_gap_m: dict = field(default_factory=dict)
    contact_force_N: dict = field(default_factory=dict)

    def apply(self, model: MultibodyModel) -> None:
        """Make this equilibrium the initial state of ``model`` (positions and arc lengths)."""
        model.q0 = self.q.copy()
        model.s0 = self.s_m.copy()
        model.sc0 = self.sc_m.copy()
        for sl, s in zip(model.windowed(), np.r_[self.s_m, self.sc_m]):
            model.set_window(sl, s)

    def stats(self) -> dict:
        return {"iterations": self.iterations, "residual_N": self.residual_N,
                "constraint_residual_m": self.constraint_residual, "wall_s": self.wall_s}


class _StepSystem:
    """The static residual ``R(u)`` and the pseudo-transient solve ``(J - M / h^2) du = rhs`` on
    generalized-alpha's step equations (:class:`~symcat.integrate.alpha_step.StepEquations`,
    index-3 form): a step from rest (``v_pred = 0``, ``b = 0``, ``gamma h = 0``, ``c_m = 1``,
    ``beta h^2 = h^2``) from the current point has the residual ``M du - h^2 R`` on the force
    rows and the Jacobian ``-h^2 (J - M / h^2)`` there (the constraint and tangency rows as they
    are, the multipliers scaled by ``h^2``). So the statics shares the step's linear algebra
    (the wires' banded Cholesky, the rest's Woodbury update, its compiled or expanded rest, the
    proxy elements of moving contacts) instead of differentiating the whole model once more:
    on a line, a fraction of a second to build and milliseconds per iteration."""

    def __init__(self, model: MultibodyModel, t: float):
        from ..integrate.alpha_integrator import step_equations

        form = Formulation(model, "augmented", "1")
        self.form, self.t = form, float(t)
        n_f, n_s, n_sc, n_c = form.n_f, form.n_s, form.n_sc, form.n_c
        self.sizes = (n_f, n_s, n_sc, n_c)
        self.n_force = n_f + n_s
        self.step = step_equations(form, "index3", compiled=None)
        self.windows = [sl.window for sl in model.windowed()]
        self._extras = None

    def _step_point(self, u: np.ndarray, bh2: float, cm: float = 1.0):
        """Step unknowns ``y`` and data ``p`` of a step from rest from the point ``u``."""
        n_f, n_s, n_sc, n_c = self.sizes
        n_u = n_f + n_s
        y = np.empty(n_u + n_c + n_sc)
        y[:n_u] = u[:n_u]
        y[n_u : n_u + n_c] = bh2 * u[n_u + n_sc :]
        y[n_u + n_c :] = u[n_u : n_u + n_sc]
        p = np.concatenate([u[:n_u], np.zeros(2 * n_u), [self.t, bh2, 0.0, cm]])
        return y, p

    def residual(self, u: np.ndarray) -> np.ndarray:
        """``R(u) = [Q - C_q^T lambda, -C_s^T lambda, C, T]`` (N, m): the step's rows, whose
        order it shares, at ``du = 0`` with ``h = 1``."""
        n_u = self.n_force
        g = self.step.residual(*self._step_point(u, 1.0))
        g[:n_u] *= -1.0
        return g

    def solve(self, u: np.ndarray, h: float, rhs: np.ndarray) -> np.ndarray:
        """``du`` with ``(J(u) - M / h^2) du = rhs`` (``J = dR/du``; ``M`` on the coordinates)."""
        n_f, n_s, n_sc, n_c = self.sizes
        n_u = n_f + n_s
        bh2 = h * h
        y, p = self._step_point(u, bh2)
        self.step.linear.factorize(y, p)
        # rows: -h^2 on the force rows, 1 on C and T; the step's order [forces, C, T]
        r = np.concatenate([-bh2 * rhs[:n_u], rhs[n_u : n_u + n_c], rhs[n_u + n_c :]])
        dy = self.step.linear.solve(r)
        return np.concatenate([dy[:n_u], dy[n_u + n_c :], dy[n_u : n_u + n_c] / bh2])

    def stiffness_diagonal(self, u: np.ndarray) -> np.ndarray:
        """``|diag dR/dq|`` on the coordinates (N/m): the round-off floor of the force residual."""
        y, p = self._step_point(u, 1.0, cm=0.0)
        return np.abs(self.step.jacobian(y, p).diagonal()[: self.sizes[0]])

    def extras(self, u: np.ndarray):
        """``C_q`` (dense, free columns), contact gaps (m) and normal forces (N) at ``u``."""
        n_f, n_s, n_sc, n_c = self.sizes
        if self._extras is None:  # the constraints alone (the whole terms' graph on a line takes long)
            form = self.form
            q, s = ca.MX.sym("q", n_f), ca.MX.sym("s", n_s)
            c = form.model.constraints(form.q_fixed + ca.mtimes(form.P, q), ca.MX.zeros(form.model.n_q), s,
                                       ca.MX.zeros(n_s), ca.MX(self.t))
            self._extras = ca.Function("extras", [q, s], [ca.mtimes(c["c_q"], form.P)])
        n_u = n_f + n_s
        cq = np.asarray(ca.densify(self._extras(u[:n_f], u[n_f:n_u])))
        gap, force = self.step.contacts(u[:n_u], np.zeros(n_u), u[n_u : n_u + n_sc], self.t)
        return cq, gap, force


def solve_equilibrium(model: MultibodyModel, t: float = 0.0, rtol: float = 1e-9, max_iterations: int = 200,
                      pseudo_time_step: float = 1e-2, max_pseudo_time: float = 1e3) -> EquilibriumResult:
    """Static equilibrium of ``model`` at time ``t`` (driving constraints evaluated at ``t``).

    Parameters
    ----------
    model : MultibodyModel
        Starts from its initial state (``q0``, ``s0``, ``sc0``); call
        :meth:`EquilibriumResult.apply` to start a simulation from the result.
    t : float
        Time (s) of the driving constraints.
    rtol : float
        Convergence: force residual below ``rtol`` times the initial one (N) and constraint
        residual below ``rtol`` times the model size (m).
    max_iterations : int
        Iterations allowed.
    pseudo_time_step : float
        Initial pseudo time step ``h`` (s): the first step moves a free body about ``g h^2``.
    max_pseudo_time : float
        Largest ``h`` (s): ``M / h^2`` is then a negligible stiffness that keeps neutral
        directions (a body spinning freely about its contact point) regular.

    Raises
    ------
    SolverError
        Naming the largest residual row.
    """
    from ..threads import serial_blas

    t0 = time.perf_counter()
    saved = [sl.window for sl in model.windowed()]
    try:
        model.center_windows()
        system = _StepSystem(model, t)
        with serial_blas():
            return _relaxation(model, system, rtol, max_iterations, max_pseudo_time, pseudo_time_step, t0, t)
    finally:
        for sl, w in zip(model.windowed(), saved):
            sl.window = w


def _moved_windows(model, system, u, t):
    """The step system of windows centred on the arc lengths of ``u`` when a point nears its
    window's edge (a window over the whole line would make the contact's Jacobian block dense
    over every element), else ``system``: only when the step has no proxy elements (with them
    the windows never need to move)."""
    n_f, n_s, n_sc, _ = system.sizes
    if not model.windowed() or system.step.proxies is not None:
        return system
    s = np.r_[u[n_f : n_f + model.n_sliding], u[n_f + n_s : n_f + n_s + n_sc]]
    if model.window_margin(s) >= 2:
        return system
    for sl, s_k in zip(model.windowed(), s):
        model.set_window(sl, float(s_k))
    return _StepSystem(model, t)


def _relaxation(model, system, rtol, max_iterations, max_pseudo_time, h0, t0, t):
    form = system.form
    n_f, n_s, n_sc, n_c = system.sizes
    u = np.r_[form.to_internal(model.q0[model.free]), model.s0, model.sc0, np.zeros(n_c)]
    r = system.residual(u)
    nf = system.n_force
    force_tol = rtol * max(np.abs(r[:nf]).max(initial=0.0), 1.0)
    geo_tol = rtol * (1.0 + np.abs(model.q0).max(initial=0.0))
    # Round-off floor of the force residual: stiff wires (EA ~ 1e9 N) cannot get below ~1e-15 EA/L.
    force_tol = max(force_tol, 1e-15 * system.stiffness_diagonal(u).max(initial=0.0)
                    * (1.0 + np.abs(model.q0).max(initial=0.0)))
    limits = _arc_limits(model)
    h, history = h0, []
    f_norm = np.abs(r[:nf]).max(initial=0.0)
    for it in range(1, max_iterations + 1):
        g_norm = np.abs(r[nf:]).max(initial=0.0)
        if f_norm <= force_tol and g_norm <= geo_tol:
            break
        try:
            with np.errstate(all="ignore"):
                du = system.solve(u, h, -r)
        except SolverError:
            du = np.full_like(u, np.nan)
        if not np.all(np.isfinite(du)):
            h /= 4
            continue
        arc = du[n_f : n_f + n_s + n_sc]
        if arc.size and np.any(np.abs(arc) > limits):
            du *= np.min(limits / np.maximum(np.abs(arc), 1e-300))
        r_new = system.residual(u + du)
        f_new = np.abs(r_new[:nf]).max(initial=0.0)
        if not np.isfinite(f_new) or f_new > 1e3 * max(f_norm, force_tol):
            h /= 4  # rejected: more pseudo-inertia
            history.append((it, h, f_norm, False))
            continue
        u, r = u + du, r_new
        moved = _moved_windows(model, system, u, t)
        if moved is not system:
            system = moved
            r = system.residual(u)
        # The pseudo time step doubles while the force residual falls, up to max_pseudo_time,
        # where the iteration is Newton's method with a negligible M / h^2 that keeps neutral
        # directions (a free spin) regular.
        if f_new < f_norm:
            h = min(2 * h, max_pseudo_time)
        f_norm = f_new
        history.append((it, h, f_norm, True))
    else:
        raise SolverError(_failure_message(model, system, u, max_iterations))
    q = model.q0.copy()
    q[model.free] = form.to_physical(u[:n_f])
    lam = u[n_f + n_s + n_sc :].copy()
    cq, gap, fc = system.extras(u)
    names = [ct.joint.name for ct in model.contacts]
    return EquilibriumResult(
        q=q, s_m=u[n_f : n_f + n_s].copy(), sc_m=u[n_f + n_s : n_f + n_s + n_sc].copy(),
        multipliers=lam, residual_N=float(f_norm),
        constraint_residual=float(np.abs(r[nf:]).max(initial=0.0)), iterations=len(history),
        wall_s=time.perf_counter() - t0, history=history, reactions_N=joint_reactions(model, cq, lam),
        contact_gap_m=dict(zip(names, np.ravel(gap).tolist())), contact_force_N=dict(zip(names, np.ravel(fc).tolist())))


def _arc_limits(model) -> np.ndarray:
    """Largest arc-length change per iteration: a quarter of the shortest element."""
    return np.array([0.25 * np.diff(sl.element_start).min() for sl in model.windowed()])


def _failure_message(model, system, u, iterations) -> str:
    r = np.abs(system.residual(u))
    n_f, n_s, n_sc, n_c = system.sizes
    coords = [model.coordinate_names()[i] for i in model.free]
    names = ([f"force on {c}" for c in coords] + [f"C_s^T lambda of {sl.joint.name}" for sl in model.sliding]
             + [f"constraint {n}" for n in model.row_names] + [f"tangency of contact {ct.joint.name}" for ct in model.contacts])
    worst = int(np.argmax(r))
    return (f"static equilibrium not found in {iterations} iterations; largest residual: {names[worst]} "
            f"({r[worst]:.3g}). Check for a mechanism without stiffness, a body that loses its support, or a contact "
            "point that leaves its wire")
