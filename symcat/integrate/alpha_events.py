"""Generalized-alpha behind the event-stepping driver: models whose events an
:class:`~.events.EventHandler` decides between integrator calls (the wheel/rail contacts' jumps,
lift-offs and touchdowns, :mod:`symcat.wheelrail_events`) run on the same driver as under IDAS
(:class:`.event_stepping.EventStepper`: call lengths from the handler's predictions, redoing a
call that passed an event, recovery after a failed call), with generalized-alpha steps inside
the calls instead of an IDAS integrator.

A call continues the method's own state (its acceleration-like variable ``a`` and the last two
steps the predictor extrapolates from) when it starts where the last call ended, or where the
last call started (a call redone shorter); from a state an event changed it restarts with ``a``
the state's acceleration, as after any discontinuity. Inside a call the steps are at most
``dt``, end exactly at the call's output times and at its end, and are equal between them.
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..dae.formulation import Formulation
from ..dae.initial import consistent_state
from ..errors import SolverError
from ..progress import Progress
from ..run_control import check_interrupt, integrating
from .alpha_integrator import StepFailure
from .alpha_run import AlphaRun
from .event_stepping import CallFailed, EventStepper
from .simulate import CONTACT_GROUP_S



class AlphaCalls:
    """The integrator calls of :class:`.event_stepping.EventStepper` made by generalized-alpha.

    Parameters
    ----------
    integ : alpha_integrator.Integrator
        The steps (its :class:`~.alpha_step.StepEquations` take the handler's open flags).
    dt : float
        Largest step (s).
    mode : callable
        ``mode() -> ndarray``: the handler's open flags now (:meth:`~.events.EventHandler.mode`).
    t0, x0, z0, state0
        The run's start and the method's state there (with its filtered starting acceleration).
    """

    def __init__(self, integ, dt: float, mode, t0: float, x0, z0, state0):
        self.integ, self.dt, self.mode = integ, float(dt), mode
        self._saved = [(t0, np.array(x0, float), np.array(z0, float), state0)]

    def _state(self, x, z, t: float):
        """The method's state at ``(t, x, z)``: a saved one (the end or the start of the last
        call) if the state is that one, else a restart from it."""
        for t_s, x_s, z_s, state in self._saved:
            if abs(t_s - t) <= 1e-12 * max(1.0, abs(t)) and np.array_equal(x_s, x) and np.array_equal(z_s, z):
                return state
        self.integ.stats["restarts"] = self.integ.stats.get("restarts", 0) + 1
        return self.integ.restart(np.asarray(x, float), np.asarray(z, float), self.dt)

    def _steps(self, t_a: float, outputs: list):
        """``(t, t_next)`` of the steps from ``t_a`` through the times ``outputs`` (the last
        one the call's end): on the run's grid of multiples of ``dt`` wherever possible (a step
        of another size refactorizes the wires' matrix), with the output times and the end
        inserted (an output or an end off the grid: one shorter step to it and one back)."""
        dt = self.dt
        end = outputs[-1]
        eps = 1e-9 * dt
        first, last = math.floor(t_a / dt + 1e-9) + 1, math.ceil(end / dt - 1e-9)
        times = sorted({*(k * dt for k in range(first, last)), *outputs})
        # An output within rounding of a grid time replaces it.
        kept = [t for t in times if t in outputs or all(abs(t - o) > eps for o in outputs)]
        starts = [t_a] + kept[:-1]
        return [(a, b) for a, b in zip(starts, kept) if b - a > eps or b in outputs]

    def call(self, x, z, t_a: float, h: float, inner=(), free: bool = False):
        """The states at ``t_a + inner`` and at ``t_a + h`` (columns of ``(xs, zs)``), as
        :meth:`.event_stepping.EventStepper.call`; ``RuntimeError`` if a step fails at every
        allowed size (the driver then recovers and retries shorter)."""
        integ = self.integ
        integ.open_rows = integ.form.open_rows(self.mode())
        state = self._state(x, z, t_a)
        start = (t_a, np.array(x, float), np.array(z, float), state)
        xs, zs = [], []
        outputs = [t_a + float(v) for v in inner] + [t_a + float(h)]
        for t, t_next in self._steps(t_a, outputs):
            integ.stepper.mode[:] = self.mode()
            step = t_next - t
            if abs(step - self.dt) <= 1e-9 * self.dt:
                step = self.dt  # exactly: the wires' matrix is kept for this step size
            try:
                state = integ.advance(state, t, step)
            except StepFailure as fail:
                raise RuntimeError(f"generalized-alpha: Newton did not converge in the step from t = "
                                   f"{fail.t0:.6g} s (the last try {fail.h:.3g} s long)") from None
            if t_next in outputs:
                x_o, z_o = integ.layout(state)
                xs.append(x_o)
                zs.append(z_o)
        self._saved = [(t_a + h, xs[-1].copy(), zs[-1].copy(), state), start]
        return np.column_stack(xs), np.column_stack(zs)


def integrate_alpha_events(integ, form: Formulation, handler, t_end: float, dt: float, n_out: int, tol: float,
                           progress: bool, wall0: float) -> AlphaRun:
    """Integrate by generalized-alpha steps (``integ``) inside the calls of the event-stepping
    driver, ``handler`` deciding the events (attached here); outputs every ``t_end / n_out``.

    Returns
    -------
    AlphaRun
        With the open flags at each output (``modes``) and the handler's events. On failure a
        :class:`SolverError` carries the run so far as ``partial``.
    """
    stats = integ.stats
    integ.singular_fails_step = True
    handler.attach(form, stats)
    integ.open_rows = handler.open_rows()
    integ.stepper.mode[:] = handler.mode()
    x, z = consistent_state(form, 0.0, open_rows=integ.open_rows)
    state = integ.start(x, z, dt)
    t_s = np.linspace(0.0, t_end, int(n_out) + 1)
    run = AlphaRun(form, t_s, [x], [z], np.zeros((t_s.size, form.n_c)), stats, walls=[time.perf_counter() - wall0])
    run.multipliers[0] = state.lam
    run.modes, run.events = [handler.mode().copy()], handler.events
    calls = AlphaCalls(integ, dt, handler.mode, 0.0, x, z, state)
    # The handler's early jumps are measured against the state's absolute tolerance: the
    # Newton tolerance on the coordinates here.
    opts = {"reltol": 1e-6, "abstol": tol}
    stepper = EventStepper(form, None, opts, x, z, stats, (), handler, calls=calls)
    lam_slice = form.blocks()[1]["lambda"].slice
    bar = Progress("generalized-alpha", t_end, "s", enabled=progress)
    group = max(1, int(CONTACT_GROUP_S / (t_s[1] - t_s[0]) + 1e-9))  # as under IDAS

    def emit(j, x_j, z_j):
        run.xs.append(np.array(x_j, float))
        run.zs.append(np.array(z_j, float))
        run.multipliers[len(run.xs) - 1] = z_j[lam_slice]
        run.modes.append(handler.mode().copy())
        run.walls.append(time.perf_counter() - wall0)
        bar.update(t_s[len(run.xs) - 1])

    a = 0
    try:
        with integrating():
            while a < n_out:
                b = min(int(n_out), a + group)
                try:
                    x, z = stepper.advance(x, z, t_s[a], t_s[a + 1 : b + 1], emit)
                except CallFailed as exc:
                    raise SolverError(f"generalized-alpha with events: at t = {exc.t:.6g} s {exc.error}; the state "
                                      "there is the partial result's last (try a smaller dt)") from None
                a = b
                check_interrupt(t_s[a], t_end)
    except SolverError as err:
        bar.close()
        if run.stopped(err, wall0, t_end):
            return run
        raise
    bar.close()
    stats["wall_s"] = time.perf_counter() - wall0
    return run
