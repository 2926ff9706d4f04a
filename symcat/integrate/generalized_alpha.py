"""Generalized-alpha time integration of a multibody model (fixed step), the second integrator
next to IDAS (:func:`symcat.integrate.simulate`) for the same :class:`~symcat.dae.Formulation`.

Why: IDAS's BDF resolves the undamped high-frequency axial content of ANCF wires with tens of
thousands of steps per simulated second; a fixed-step generalized-alpha method with a little
numerical dissipation (``rho_inf < 1``) damps it and takes one step per ``dt``, with a Jacobian
that is refactorized only when the Newton iteration slows down.

The method is the generalized-alpha scheme of Chung and Hulbert (1993) applied, as in Arnold and
Brüls (2007), to the constrained equations of motion in the augmented form (the sliding-joint arc
lengths ``s`` are generalized coordinates of zero mass, ``u = [q, s]``):

    M(q) v_dot + C_q^T lambda = Q(q, v, t),   C_s^T lambda = 0,   C(q, s, t) = 0,

enforced at the end of each step, with the Newmark updates and the acceleration-like variable
``a`` (not the acceleration ``v_dot``):

    u_{n+1} = u_n + h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}   [+ G^T nu_{n+1}]
    v_{n+1} = v_n + h (1 - gamma) a_n + h gamma a_{n+1}
    (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) v_dot_{n+1} + alpha_f v_dot_n

Two variants (``variant``):

``index3``
    Arnold and Brüls (2007), "Convergence of the generalized-alpha scheme for constrained
    mechanical systems", Multibody Syst Dyn 18:185-202: only ``C = 0`` is imposed. Order 2 in
    every variable once the start-up transient has decayed; that transient is large in the
    multipliers when the system starts moving (an error of order 1 N on 10-40 N over the first
    0.1 s of a spinning pendulum at rho_inf = 0.9, whatever dt) and decays over the steps.
``stabilized``
    The stabilized index-2 form (Gear-Gupta-Leimkuhler) of Arnold, Brüls and Cardona (2015),
    "Error analysis of generalized-alpha Lie group time integration methods for constrained
    mechanical systems", Numer Math 129:149-179, and Brüls, Cardona and Arnold (2012),
    "Lie group generalized-alpha time integration of constrained flexible multibody systems",
    Mech Mach Theory 48:121-137: the velocity constraint ``G v + C_t = 0`` (``G = [C_q, C_s]``)
    is imposed as well, with the multiplier ``nu`` of the bracketed term; order 2 in positions,
    velocities and multipliers, at the price of ``n_c`` more unknowns.

Penalty contacts (:class:`symcat.scene.PenaltyContact`) add their arc lengths ``s_c`` as
algebraic unknowns of each step with their tangency equations ``0 = T(q, s_c)`` (no multiplier;
the normal forces are part of ``Q``), as in :class:`~symcat.dae.Formulation`. Wheel/rail contacts
are constraints like any other (their surface parameters among the zero-mass ``s``, their creep
forces in ``Q`` as functions of the multipliers and of ``s_dot``, an open contact's gap rows
replaced by its multipliers); their events (contact-point jumps, lift-off, touchdown) are decided
between steps by the same :class:`~.events.EventHandler` as under IDAS, the steps running inside
the calls of the event driver (:mod:`.alpha_events`).

The Newton iteration solves for ``y = [u_{n+1}, beta h^2 lambda_{n+1} (, nu_{n+1}), s_c]`` with the
scaling of Bottasso, Bauchau and Cardona (2007, "Time-step-size-independent conditioning and
sensitivity to perturbations in the numerical solution of index three differential algebraic
equations", SIAM J Sci Comput 29:397-414): the dynamic rows are multiplied by ``beta h^2`` and
the velocity rows by ``beta h / gamma``, so every block of the iteration matrix is O(1) whatever
``h`` (unscaled, its condition number grows like a negative power of ``h``). The residual and its
exact sparse Jacobians are CasADi functions of the step's unknowns and data, built once per
element window through :meth:`Formulation.terms` and evaluated in place on NumPy memory. The
iteration is a modified Newton one with the iteration matrix split in two
(:mod:`.alpha_step`): the bulk (the ANCF structure: thousands of unknowns on a line) is
factorized (SuperLU) once and kept across steps and window moves, the rest (bodies, joints,
contacts, multipliers) enters by a low-rank update, re-evaluated when the iteration slows. The predictor extrapolates ``a``,
``lambda`` and ``s_c`` linearly from the last two steps. A step whose iteration fails (even with
a fresh matrix) is retried as two steps of half the size, each halved again on failure, down to
``dt / 2**max_halvings``; the next step has the full size again (the Newmark variables are
carried over unchanged across a change of step size).

The starting value ``a_0 = v_dot(t_0 + (alpha_m - alpha_f) h)`` (order 2 from the first step) is
filtered through the step's iteration matrix, so that modes the step does not resolve do not
enter it (:meth:`.alpha_integrator.Integrator.starting_acceleration`; unfiltered, the cross-section modes of a
beam3d wire made the first step of the seed paper's catenary diverge at dt = 1 ms).

The states are mapped into the layout of the augmented index-1 form (``x = [q, s, v, w]``,
``z = [v_dot, s_ddot, lambda]``), so :func:`symcat.integrate.results.collect_result` makes the
same :class:`SimulationResult` as :func:`simulate` (its multipliers and joint reactions are
recomputed from the KKT system of each output state, as for IDAS; the integrator's own
multipliers are in :attr:`AlphaRun.multipliers`).
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..assembly.multibody import MultibodyModel
from ..dae.formulation import Formulation
from ..dae.initial import consistent_state
from ..errors import ParameterError, SolverError
from ..progress import Progress
from ..run_control import check_interrupt, integrating
from .alpha_chunk import CompiledSteps
from .alpha_chunk_cache import one_run
from .alpha_coefficients import AlphaCoefficients
from .alpha_events import integrate_alpha_events
from .alpha_integrator import Integrator, StepFailure
from .alpha_run import AlphaRun, StepStates
from .results import SimulationResult
from .simulate import one_handler

VARIANTS = ("index3", "stabilized")
#: Steps from which a run with wheel/rail contacts compiles the rest of its steps to C when no
#: compiled one is cached (:class:`~.alpha_step.StepEquations`); a shorter run uses a cached one
#: or the expanded functions, and leaves the compiling to a background job for the model's next
#: runs (:func:`.alpha_rest.compile_later`). Compiling the seed scene's takes about 30 s (once
#: per machine and model); its compiled step then runs the scene about 1.5 times faster.
COMPILE_STEPS = 2000
#: Steps from which a run compiles its steps (:mod:`.alpha_chunk`) when they are not cached: the
#: compiler's 5 to 50 s (once per model) against the Python steps' extra 0.5 to 2 ms each.
CHUNK_COMPILE_STEPS = 20_000



def integrate_alpha(model: MultibodyModel, t_end: float, dt: float, rho_inf: float = 0.9,
                    variant: str = "stabilized", tol: float = 1e-10, max_iterations: int = 20, n_out: int = 200,
                    progress: bool = True, expand: bool = False, max_halvings: int = 4, monitor=None,
                    handlers=None, compiled: bool | None = None) -> AlphaRun:
    """Integrate ``model`` from its consistent initial state to ``t_end`` with fixed steps.

    Parameters are those of :func:`generalized_alpha`.

    Returns
    -------
    AlphaRun
        On failure a :class:`SolverError` carries the :class:`AlphaRun` so far as ``partial``.
    """
    if not (isinstance(t_end, (int, float)) and t_end > 0):
        raise ParameterError(f"t_end={t_end!r}: must be > 0 s")
    if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
        raise ParameterError(f"dt={dt!r}: the time step must be > 0 s")
    coef = AlphaCoefficients(rho_inf)
    if variant not in VARIANTS:
        raise ParameterError(f"variant={variant!r}: must be one of {', '.join(VARIANTS)}")
    if not 0 < tol < 1:
        raise ParameterError(f"tol={tol!r}: the Newton tolerance must be in (0, 1)")
    if int(n_out) < 1:
        raise ParameterError(f"n_out={n_out!r}: must be >= 1")
    if int(max_iterations) < 1:
        raise ParameterError(f"max_iterations={max_iterations!r}: must be >= 1")
    if not (isinstance(max_halvings, int) and 0 <= max_halvings <= 20):
        raise ParameterError(f"max_halvings={max_halvings!r}: must be an integer in 0..20")
    handler = one_handler(model, handlers)
    if handler is not None and monitor is not None:
        raise ParameterError("monitor: not with event handlers (the steps inside the event driver's calls are not "
                             "recorded one by one); use the outputs (n_out)")
    wall0 = time.perf_counter()
    model.center_windows()
    form = Formulation(model, "augmented", "1")
    if handler is not None:
        stats = {"steps": 0, "nsteps": 0, "newton_iterations": 0, "factorizations": 0, "rebuilds": 0, "halvings": 0,
                 "build_s": 0.0, "dt": dt, "rho_inf": coef.rho_inf, "variant": variant, "restarts": 0}
        # A short run uses a compiled step if one is cached, else compiles one in the background.
        rest = (True if compiled or t_end / dt >= COMPILE_STEPS else None) if compiled is not False else False
        integ = Integrator(model, form, coef, variant, tol, int(max_iterations), max_halvings, expand, stats, rest)
        try:
            return integrate_alpha_events(integ, form, handler, t_end, dt, int(n_out), tol, progress, wall0)
        finally:
            stats["factorizations"] = integ.stepper.bulk.factorizations
    x, z = consistent_state(form, 0.0)
    # Equal steps no longer than dt, a whole number of them per output interval.
    n_steps = max(1, math.ceil(t_end / dt - 1e-9))
    per = max(1, math.ceil(n_steps / int(n_out)))
    n_outputs = math.ceil(n_steps / per)
    n_steps = n_outputs * per
    h = t_end / n_steps

    t_s = np.linspace(0.0, t_end, n_outputs + 1)
    run = AlphaRun(form, t_s, [x], [z], np.zeros((n_outputs + 1, form.n_c)), walls=[time.perf_counter() - wall0])
    stats = run.stats
    stats.update(steps=0, nsteps=0, newton_iterations=0, factorizations=0, rebuilds=0, halvings=0, build_s=0.0,
                 dt=h, rho_inf=coef.rho_inf, variant=variant)
    integ = Integrator(model, form, coef, variant, tol, int(max_iterations), max_halvings, expand, stats)
    state = integ.start(x, z, h)
    # The steps run compiled, many per call (recording each step's state for a monitor); a
    # short run compiles them only if asked (``compiled=True``), else uses them if cached; a
    # long one ("long") as its model and $SYMCAT_OPTIMIZE allow (alpha_chunk._compiled).
    chunks = (CompiledSteps(integ, h, per,
                            build=True if compiled else "long" if n_steps >= CHUNK_COMPILE_STEPS else False)
              if compiled is not False else None)
    run.multipliers[0] = state.lam

    def contacts(t):
        if form.n_sc:
            run.contacts.append(integ.stepper.contacts(state.u, state.v, state.sc, t))

    contacts(0.0)

    def record(states: list):
        """The monitor's values of the states after some steps (one call, all of them)."""
        batch = StepStates.stacked(states)
        values = monitor(batch)
        run.monitored.setdefault("t_s", []).append(batch.t_s)
        for key, value in values.items():
            if len(value) != len(batch):
                raise ValueError(f"monitor: its value {key!r} has {len(value)} entries for {len(batch)} steps (the "
                                 "monitor gets the states of several steps, its values one entry per step)")
            run.monitored.setdefault(key, []).append(value)

    if monitor is not None:
        record([integ.step_state(state, 0.0)])
    bar = Progress("generalized-alpha", t_end, "s", enabled=progress)
    step = 0
    try:
        with integrating():
            for out in range(1, n_outputs + 1):
                try:
                    states = None if monitor is None else []
                    if chunks is not None:
                        state = chunks.advance(state, step * h, per, states)
                        step += per
                    else:
                        for _ in range(per):
                            state = integ.advance(state, step * h, h)
                            step += 1
                            if states is not None:
                                states.append(integ.step_state(state, step * h))
                    if states is not None:
                        record(states)
                except StepFailure as fail:
                    t1 = (math.floor(fail.t0 / h + 1e-9) + 1) * h
                    tried = (f"nor with the step halved {max_halvings} times (the last try, {fail.h:.3g} s "
                             f"from t = {fail.t0:.6g} s, failed too)" if max_halvings else
                             "and halving the step was not allowed (max_halvings=0)")
                    raise SolverError(f"generalized-alpha: Newton did not converge in the step to t = {t1:.6g} s "
                                      f"(dt = {h:.3g} s) even with a fresh Jacobian, {tried}; try a smaller dt "
                                      "or a smaller rho_inf") from None
                x, z = integ.layout(state)
                run.xs.append(x)
                run.zs.append(z)
                run.multipliers[out] = state.lam
                contacts(t_s[out])
                run.walls.append(time.perf_counter() - wall0)
                bar.update(t_s[out])
                check_interrupt(t_s[out], t_end)
    except SolverError as err:
        bar.close()
        stats["factorizations"] = integ.factorizations
        if run.stopped(err, wall0, t_end):
            return run
        raise
    bar.close()
    stats["factorizations"] = integ.factorizations
    stats["wall_s"] = time.perf_counter() - wall0
    return run


@one_run
def generalized_alpha(model: MultibodyModel, t_end: float, dt: float, rho_inf: float = 0.9,
                      variant: str = "stabilized", tol: float = 1e-10, max_iterations: int = 20, n_out: int = 200,
                      progress: bool = True, expand: bool = False, max_halvings: int = 4,
                      multipliers: str = "kkt", monitor=None, handlers=None,
                      compiled: bool | None = None) -> SimulationResult:
    """Simulate ``model`` from 0 to ``t_end`` seconds by the generalized-alpha method (fixed step).

    Parameters
    ----------
    model : MultibodyModel
        Rigid bodies, ANCF wires, joints, sliding joints and penalty contacts (element windows
        move between steps, as in :func:`simulate`); not yet wheel/rail contacts.
    t_end : float
        Simulated time (s), > 0.
    dt : float
        Time step (s), > 0; the run takes equal steps no longer than ``dt``, a whole number of
        them per output interval (a step that fails is halved, see ``max_halvings``).
    rho_inf : float
        Spectral radius at infinite frequency, 0..1: 1 keeps every frequency undamped (and
        energy bounded), smaller values damp the content the step does not resolve (0.9 costs
        little accuracy on the resolved motion).
    variant : {"stabilized", "index3"}
        Stabilized index-2 (order 2 in every variable) or index-3 (order 2 in positions; an O(h)
        transient in velocities and multipliers); see the module's notes.
    tol : float
        Newton tolerance on the coordinates (absolute: m, or the dimensionless slopes and Euler
        parameters; multipliers counted as the position change they cause, see
        :func:`~.alpha_newton.solve_step`). The iteration stops on the same side
        every step, so its error adds up over the steps: keep ``tol`` well below the step's local
        error (on the double pendulum at dt = 1 ms, 1e-8 tripled the error at 2 s; 1e-10 left it).
    max_iterations : int
        Newton iterations per step; past them the matrix is refreshed once, then the step fails.
    max_halvings : int
        A step whose Newton iteration fails is retried as two steps of half the size, each
        halved again on failure, down to ``dt / 2**max_halvings`` (default 1/16); the next step
        has the full size again, so the outputs stay on the ``dt`` grid. 0: no retry.
    n_out : int
        Output intervals (at most one per step).
    progress : bool
        Progress bar on long runs.
    expand : bool
        Expand the bulk's functions (the wires) to scalar operations (CasADi SX) when their
        kernels allow it (the rest's always are): slow to build on a line, rarely worth it.
    multipliers : {"kkt", "integrator"}
        Multipliers and accelerations of the result: ``"kkt"`` solves the KKT system at each
        output (as for IDAS; exact for the state, a sparse factorization of the mass matrix per
        output); ``"integrator"`` keeps the integrator's own ``lambda_{n+1}`` and ``v_dot_{n+1}``
        (order 2 under the stabilized variant, an O(h) start-up transient under index3):
        for long runs with many outputs, whose post-processing the KKT solves dominate.
    monitor : callable, optional
        ``monitor(StepStates) -> dict`` of the states at the start and after every step, called
        with the states of several steps at once (:class:`~.alpha_run.StepStates`: the steps of
        an output interval, which the compiled steps record in their calls): each value has
        one entry per step (first axis); they are joined over the run in ``result.monitored``
        (with ``t_s``). What a passage records at every step (a contact force, a few heights)
        without a full output per step, whose post-processing (energies, every contact over
        the whole wire) costs more than the step. Not with ``handlers``.
    handlers : sequence of EventHandler, optional
        Events between the steps (:mod:`.events`; one handler for now), required for a model
        with wheel/rail contacts (:func:`symcat.simulation.integrate_model` attaches them): the
        run then goes through the event-stepping driver, generalized-alpha steps inside its
        calls (:mod:`.alpha_events`), with outputs every ``t_end / n_out``.
    compiled : bool, optional
        Without ``handlers``, run the steps as compiled C, many per call
        (:mod:`.alpha_chunk`: the same steps to the Newton tolerance); with
        ``handlers``, compile the rest of each step. The
        code is compiled once per model and cached. None (default): compiled if cached or if
        the run has at least :data:`CHUNK_COMPILE_STEPS` steps (the rest of wheel/rail steps:
        :data:`COMPILE_STEPS`, and a shorter one has it compiled in the background for the
        next runs); True: compiled now if not cached; False: every step evaluated from Python.

    Returns
    -------
    SimulationResult
        As :func:`simulate` returns it; ``stats`` has ``steps``, ``newton_iterations``,
        ``factorizations``, ``rebuilds``, ``halvings``, ``build_s``, ``dt``, ``rho_inf``,
        ``variant``, ``wall_s`` (see :class:`AlphaRun`).

    Raises
    ------
    ParameterError
        Naming the parameter out of range.
    SolverError
        When a step's Newton iteration fails at every size down to ``dt / 2**max_halvings``
        (the message names the step and the last size tried); ``partial`` holds the result so far.
    """
    wall0 = time.perf_counter()
    if multipliers not in ("kkt", "integrator"):
        raise ParameterError(f"multipliers={multipliers!r}: must be 'kkt' or 'integrator'")
    from ..threads import serial_blas

    try:
        with serial_blas():
            run = integrate_alpha(model, t_end, dt, rho_inf, variant, tol, max_iterations, n_out, progress, expand,
                                  max_halvings, monitor, handlers, compiled)
    except SolverError as err:
        if isinstance(err.partial, AlphaRun):
            err.partial = err.partial.result(wall0, multipliers)
        raise
    return run.result(wall0, multipliers)
