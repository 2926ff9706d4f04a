"""The steps of the generalized-alpha method (:mod:`.generalized_alpha`, whose module docstring
explains the method): the integrator's state between steps, one step and its retries at half
the size, the starting acceleration, and the state in the formulation's layout. The runs
(:func:`.generalized_alpha.integrate_alpha`, and inside the event driver's calls
:mod:`.alpha_events`) drive an :class:`Integrator`."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from ..dae.formulation import Formulation
from ..dae.initial import consistent_state
from ..errors import SolverError
from .alpha_run import StepStates
from .alpha_newton import solve_step
from .alpha_step import StepEquations
from .simulate import update_windows


@dataclass
class State:
    """The integrator's state at one instant: ``u = [q, s]``, ``v``, ``v_dot``, the
    acceleration-like ``a``, the multipliers ``lam`` and the contact arc lengths ``sc``; ``prev``
    is ``(a, lam, sc)`` of the step before and ``h`` the step that led here (the predictor
    extrapolates from them)."""

    u: np.ndarray
    v: np.ndarray
    v_dot: np.ndarray
    a: np.ndarray
    lam: np.ndarray
    sc: np.ndarray
    prev: tuple
    h: float


class StepFailure(Exception):
    """A step whose Newton iteration failed at every allowed step size (from ``t0``, ``h`` the
    smallest size tried)."""

    def __init__(self, t0: float, h: float):
        super().__init__(t0, h)
        self.t0, self.h = t0, h


def step_equations(form: Formulation, variant: str, expand: bool = False,
                   compiled: bool | None = True) -> StepEquations:
    """The :class:`StepEquations` of ``form``, reused (:meth:`StepEquations.reset`) when an
    equivalent one was built for the same model: a static solve and the run that starts from
    it (:func:`symcat.analysis.solve_equilibrium` then generalized-alpha, as a passage does)
    share one build, a few tenths of a second on a line. Equivalent: the same formulation,
    variant, fixed coordinates and element windows (``compiled`` counts only with wheel/rail
    contacts)."""
    model = form.model
    key = (variant, bool(expand), compiled if model.wheelrail else None, form.formulation, form.index,
           form.cholesky, np.asarray(form.q_fixed).tobytes())
    windows = tuple(sl.window for sl in model.windowed())
    built = model.__dict__.setdefault("_step_equations", {}).setdefault(key, [])
    for step, at in built:  # with proxy elements the windows do not matter
        if step.proxies is not None or at == windows:
            step.reset()
            return step
    step = StepEquations(form, variant, expand, compiled=compiled)
    built.append((step, windows))
    return step


class Integrator:
    """Steps of the generalized-alpha method on ``form`` (its :class:`StepEquations`, rebuilt when an
    element window moves), halving a step whose Newton iteration fails.

    The step equations (:attr:`stepper`) are built at their first use: a run whose steps all
    run compiled from a cached library (:mod:`.alpha_chunk`) and that starts without them
    (``rho_inf = 1``) never builds them."""

    def __init__(self, model, form, coef, variant, tol, max_iterations, max_halvings, expand, stats,
                 compiled: bool | None = True):
        self.model, self.form, self.coef, self.variant = model, form, coef, variant
        self.compiled = compiled
        self.tol, self.max_iterations, self.max_halvings, self.expand = tol, max_iterations, max_halvings, expand
        self.stats = stats
        self.xb, self.zb = form.blocks()
        # the blocks' names in their order in x and z (layout() concatenates them at every output)
        self._order = [sorted(blocks, key=lambda name: blocks[name].start) for blocks in (self.xb, self.zb)]
        self.open_rows = []  # the constraint rows an event handler released (lifted wheels)
        self.singular_fails_step = False  # a singular iteration matrix: a failed step, not the run's end
        self.compiled_factorizations = 0  # of the compiled steps' iteration matrix (.alpha_chunk)
        self._stepper = None

    @property
    def stepper(self) -> StepEquations:
        """The step equations, built at the first use."""
        if self._stepper is None:
            self._stepper = self._build()
        return self._stepper

    @stepper.setter
    def stepper(self, value: StepEquations) -> None:
        self._stepper = value

    @property
    def built_stepper(self) -> StepEquations | None:
        """The step equations if built, else None (without building them)."""
        return self._stepper

    @property
    def factorizations(self) -> int:
        """Factorizations of the iteration matrices so far: the Python steps' and the compiled
        ones'."""
        return self.compiled_factorizations + (self._stepper.bulk.factorizations if self._stepper is not None else 0)

    def _build(self, previous: StepEquations | None = None) -> StepEquations:
        build = time.perf_counter()
        if previous is None:
            stepper = step_equations(self.form, self.variant, self.expand, compiled=self.compiled)
        else:  # a window moved: the bulk matrix does not depend on it
            stepper = StepEquations(self.form, self.variant, self.expand, previous.bulk, previous.mass_scale,
                                    compiled=self.compiled)
        self.stats["build_s"] = self.stats.get("build_s", 0.0) + time.perf_counter() - build
        return stepper

    def data(self, s: State, t0: float, h: float) -> np.ndarray:
        """The step's data ``p`` (see :class:`StepEquations`) from ``s`` at ``t0`` over ``h``."""
        c = self.coef
        u_pred = s.u + h * s.v + h * h * (0.5 - c.beta) * s.a
        v_pred = s.v + h * (1 - c.gamma) * s.a
        b = (c.alpha_m * s.a - c.alpha_f * s.v_dot) / (1 - c.alpha_f)
        return np.concatenate([u_pred, v_pred, b, [t0 + h, c.beta * h * h, c.gamma * h,
                                                    (1 - c.alpha_m) / (1 - c.alpha_f)]])

    def predictor(self, s: State, p: np.ndarray, h: float) -> np.ndarray:
        """``a``, ``lambda`` and ``s_c`` extrapolated linearly from the last two steps (one Newton
        iteration fewer than ``a_{n+1} = a_n``), ``nu = 0``."""
        st = self.stepper
        n_u, n_c, n_sc = st.n_u, st.n_c, st.n_sc
        bh2 = self.coef.beta * h * h
        ratio = h / s.h
        a_prev, lam_prev, sc_prev = s.prev
        y = np.zeros(st.n_y)
        y[:n_u] = p[:n_u] + bh2 * (s.a + ratio * (s.a - a_prev))
        y[n_u : n_u + n_c] = bh2 * (s.lam + ratio * (s.lam - lam_prev))
        if n_sc:
            y[st.n_y - n_sc :] = s.sc + ratio * (s.sc - sc_prev)
        return y

    def attempt(self, s: State, t0: float, h: float) -> State | None:
        """One step of size ``h`` from ``s`` at ``t0``; None if its Newton iteration fails."""
        st = self.stepper
        p = self.data(s, t0, h)
        try:
            done = solve_step(st, self.predictor(s, p, h), p, self.tol, self.max_iterations, self.stats)
        except SolverError:
            if not self.singular_fails_step:
                raise
            # Under events (a contact point nearing a fold of its gap, where its constraint
            # rows lose rank): a shorter step, or the event driver's recovery, gets past it.
            return None
        if done is None:
            return None
        y, a, v, v_dot = done
        bh2 = p[3 * st.n_u + 1]
        sc = y[st.n_y - st.n_sc :].copy() if st.n_sc else np.zeros(0)
        return State(y[: st.n_u].copy(), v, v_dot, a, y[st.n_u : st.n_u + st.n_c] / bh2, sc, (s.a, s.lam, s.sc), h)

    def advance(self, s: State, t0: float, h: float, depth: int = 0) -> State:
        """The state at ``t0 + h``: one step, or, when its Newton iteration fails, two steps of
        ``h / 2`` (each halved again on failure, at most :attr:`max_halvings` times in all)."""
        new = self.attempt(s, t0, h)
        if new is None:
            if depth >= self.max_halvings:
                raise StepFailure(t0, h)
            self.stats["halvings"] += 1
            mid = self.advance(s, t0, 0.5 * h, depth + 1)
            return self.advance(mid, t0 + 0.5 * h, 0.5 * h, depth + 1)
        self.stats["steps"] += 1
        self.stats["nsteps"] = self.stats["steps"]
        self.move_windows(new)
        return new

    def move_windows(self, s: State) -> bool:
        """Move the element windows with their points at ``s``; True if the step's equations
        were rebuilt (without proxy elements the windows are part of their graph)."""
        if self.stepper.proxies is not None or not self.model.windows_move():
            return False
        x, z = self.layout(s)
        if not update_windows(self.model, self.form, x, z):
            return False
        self.stepper = self._build(self.stepper)
        self.stats["rebuilds"] += 1
        return True

    def step_state(self, s: State, t: float) -> StepStates:
        """The :class:`StepStates` (one) of ``s`` at time ``t`` (physical, all coordinates)."""
        gap, force = self.stepper.contacts(s.u, s.v, s.sc, t)
        return self.step_states(np.array([t]), s.u[None], s.v[None], s.v_dot[None], s.lam[None], s.sc[None],
                                gap[None], force[None])

    def step_states(self, t, u, v, v_dot, lam, sc, gap, force) -> StepStates:
        """The :class:`StepStates` of the step unknowns' values after consecutive steps (each
        array's first axis the steps, as the compiled steps record them)."""
        model, form = self.model, self.form
        n_f, k = form.n_f, len(t)
        q, vel, acc = np.tile(model.q0, (k, 1)), np.zeros((k, model.n_q)), np.zeros((k, model.n_q))
        q[:, model.free] = form.to_physical(u[:, :n_f].T).T
        vel[:, model.free] = form.to_physical(v[:, :n_f].T).T
        acc[:, model.free] = form.to_physical(v_dot[:, :n_f].T).T
        return StepStates(np.asarray(t, float), q, vel, acc, u[:, n_f:].copy(), lam.copy(), sc.copy(), gap.copy(),
                          force.copy())

    def layout(self, s: State):
        """The state in the augmented index-1 layout ``x = [q, s, v, w]``, ``z = [a, s_dd, lambda(, sc)]``."""
        n_f = self.form.n_f
        values = {"q": s.u[:n_f], "s": s.u[n_f:], "v": s.v[:n_f], "w": s.v[n_f:], "a": s.v_dot[:n_f],
                  "s_dd": s.v_dot[n_f:], "lambda": s.lam, "sc": s.sc}
        return tuple(np.concatenate([values[name] for name in order]) if order else np.zeros(0)
                     for order in self._order)

    def start(self, x, z, h: float) -> State:
        """The state of the consistent ``(x, z)`` at t = 0, with the starting value of ``a``
        (:meth:`starting_acceleration`) for steps of ``h``."""
        xb, zb = self.xb, self.zb
        u = np.r_[x[xb["q"].slice], x[xb["s"].slice]]
        v = np.r_[x[xb["v"].slice], x[xb["w"].slice]]
        v_dot = np.r_[z[zb["a"].slice], z[zb["s_dd"].slice]]
        lam = z[zb["lambda"].slice].copy()
        sc = z[zb["sc"].slice].copy() if "sc" in zb else np.zeros(0)
        s = State(u, v, v_dot, v_dot, lam, sc, (v_dot, lam, sc), h)
        s.a = self.starting_acceleration(s, x, z, h)
        s.prev = (s.a, lam, sc)
        return s

    def restart(self, x, z, h: float) -> State:
        """The state of ``(x, z)`` (consistent, e.g. just changed by an event) with ``a =
        v_dot``: an event is a discontinuity, across which the method restarts at order 1."""
        xb, zb = self.xb, self.zb
        v_dot = np.r_[z[zb["a"].slice], z[zb["s_dd"].slice]]
        lam = z[zb["lambda"].slice].copy()
        sc = z[zb["sc"].slice].copy() if "sc" in zb else np.zeros(0)
        return State(np.r_[x[xb["q"].slice], x[xb["s"].slice]], np.r_[x[xb["v"].slice], x[xb["w"].slice]], v_dot,
                      v_dot.copy(), lam, sc, (v_dot, lam, sc), h)

    def starting_acceleration(self, s: State, x, z, h: float) -> np.ndarray:
        """``a_0 = v_dot(t_0 + Delta)``, ``Delta = (alpha_m - alpha_f) h``: ``a_n`` approximates
        ``v_dot`` at ``t_n + Delta`` to O(h^2) (Arnold and Brüls 2007), and starting it from
        ``v_dot_0`` instead leaves an O(h) start-up error that decays slowly for rho_inf near 1
        (measured on a spinning double pendulum, stabilized form: multiplier errors of order 1 in
        dt instead of 2 over the first steps).

        The correction ``delta = v_dot(t_0 + Delta) - v_dot_0`` is computed as the accelerations
        of the consistent state at the Taylor-extrapolated positions and velocities (an O(h^2)
        error), then filtered by the step's own iteration matrix: ``delta`` is replaced by the
        solution of ``[J_uu, G^T; G, 0] [d; mu] = [c_m M delta; G delta]`` (``J_uu = c_m M +
        gamma h D + beta h^2 K`` with the tangency rows of the penalty contacts, ``c_m = (1 -
        alpha_m)/(1 - alpha_f)``), which passes what the step resolves (``omega h << 1``) to
        O(h) and damps an unresolved mode by ``1 / (beta (omega h)^2)``. Unfiltered, a mode the
        step cannot resolve makes ``a_0`` its jerk times ``Delta``: on the seed paper's
        catenary (beam3d wire, cross-section gradient modes near 1e6 rad/s set vibrating by the
        projected initial velocities, a jerk of 8e11 m/s^3) that was 4e7 m/s^2 at dt = 1 ms,
        moved the predicted cross-section gradients (unit vectors) by 10, and the first step's
        Newton iteration diverged."""
        form, xb, zb, c = self.form, self.xb, self.zb, self.coef
        shift = (c.alpha_m - c.alpha_f) * h
        if shift == 0:
            return s.v_dot
        part = {name: x[blk.slice] for name, blk in xb.items()}
        acc = {"q": z[zb["a"].slice], "s": z[zb["s_dd"].slice]}
        start = {"q": part["q"] + shift * part["v"] + 0.5 * shift**2 * acc["q"], "v": part["v"] + shift * acc["q"],
                 "s": part["s"] + shift * part["w"] + 0.5 * shift**2 * acc["s"], "w": part["w"] + shift * acc["s"],
                 "sc": s.sc}
        z1 = consistent_state(form, shift, start=start, positions=False, open_rows=self.open_rows)[1]
        delta = np.r_[z1[zb["a"].slice], z1[zb["s_dd"].slice]] - s.v_dot
        st = self.stepper
        n_u, n_c, n_sc, n_f = st.n_u, st.n_c, st.n_sc, form.n_f
        p = self.data(s, 0.0, h)
        y = self.predictor(s, p, h)
        keep = np.r_[np.arange(n_u + n_c), np.arange(st.n_y - n_sc, st.n_y)]
        jac = st.jacobian(y, p).tocsr()[keep][:, keep].tocsc()
        rhs = np.zeros(keep.size)
        rhs[:n_f] = p[-1] * (st.mass(y) @ delta[:n_f])
        rhs[n_u : n_u + n_c] = jac[n_u : n_u + n_c, :n_u] @ delta  # G delta
        try:
            filtered = spla.splu(jac).solve(rhs)[:n_u]
        except RuntimeError:
            raise SolverError("generalized-alpha: singular iteration matrix at the start (redundant constraints, "
                              "or a sliding joint at a point where its wire has no tangent?)") from None
        return s.v_dot + filtered
