"""The stepping driver of models with events between integrator calls (e.g. wheel/rail contact
jumps, lift-off and touchdown): short IDAS calls, the events decided between them by plug-in
handlers (:class:`.events.EventHandler`; the wheel/rail contacts' in
:mod:`symcat.wheelrail_events`).

The calls are many (tens to hundreds per simulated second while a contact point crosses a nearly
conformal region) and building an integrator costs a few steps' work (2 ms for the seed vehicle,
:class:`.shifted.SharedDerivatives`; 9 ms when each derived the DAE's Jacobian anew), so the call
lengths are binary fractions ``dt / 2^k`` of the driver's span (output intervals grouped to
about 0.1 s; the output times inside a call are interpolated by IDAS), aligned so that they add
up to it exactly, and one integrator per call grid serves all calls on that grid. IDAS needs a
consistent ``x_dot`` at each start, which CasADi takes from a construction option: the
integrator therefore solves for the state's departure from its linear extrapolation,
``x = x_a + (t - t_a) x_dot_a + D xi`` (:func:`.shifted.shifted_dae`), whose consistent start is
``xi = 0``, ``xi_dot = 0`` for every call; ``x_a``, ``x_dot_a`` (the DAE's own, exact for a
consistent ``z``) and ``D`` are parameters. The scaling ``D = 1 + rtol |x_a| / atol`` keeps
IDAS's error weights those of ``x`` (its relative part measured on ``xi`` alone would tighten
the test on large coordinates). This spares both a fresh integrator per call (then 10 ms for a
compiled DAE, 50 ms over the graph) and IDACalcIC (30 % of the wall time of an S1002 vehicle),
which remains the last resort (:meth:`EventStepper._attempts`).

Two kinds of call leave the binary grid (*free* calls): a call that ends exactly at a predicted
event (on the grid, the calls would close in on it by halves: six to eight calls and checks per
contact jump), and, from such an end, one call back to the grid at the level the span allows
(on the grid, the calls would double from the finest level up). On an S1002 vehicle this halves
the calls (170 -> 93 per simulated second). Every call runs in the normalized time
``tau = (t - t_a) / h``, so that one integrator serves all calls with the same output fractions
and first-step level, whatever their length (grid calls keep seconds under a step limit
``max_step``, which is in seconds): 32 -> 24 integrators built in the first simulated second of
the S1002 vehicle. A call with one output inside runs in a warped time that puts the output on
one of a few fixed fractions (:func:`.shifted.warped_grid`), so that such calls share
integrators too.

A continuing call starts with about IDAS's last step (GGL, :meth:`EventStepper._first_step`),
not 1e-3 of the call; an event found late is redone once, to its estimated time, from the
call's last output before it if there is one (:meth:`.events.EventHandler.late`,
:meth:`~.events.EventHandler.kept_output`). S1002 vehicle, rtol 1e-4: 1859 steps, 1081
Jacobian set-ups and 109 calls per simulated second became 1098, 534 and 89.
"""
from __future__ import annotations

import contextlib
import io
import math

import casadi as ca
import numpy as np

from ..errors import ParameterError, SolverError
from .shifted import CallIntegrators, call_grid

#: IDAS steps allowed in one call (the driver's ``max_steps`` if smaller).
MAX_CALL_STEPS = 20000
#: Largest level ``k`` of a suggested first step ``2^-k`` of the call (about 1e-3).
FIRST_STEP_LEVELS = 10
#: The first step of a call that continues the last one (:meth:`EventStepper._first_step`)
#: is rounded down to ``2^-k`` of the call with ``k`` a multiple of this: one integrator per
#: level and grid (about 2 ms to build). With levels 1 apart, S1002 vehicle at rtol 1e-4: 5 %
#: fewer steps, 12 more integrators, no less wall time.
FIRST_STEP_LEVEL_STEP = 3
#: Longest call (s) that falls back to other linear solvers or IDACalcIC when IDAS fails
#: (:meth:`EventStepper._attempts`).
FALLBACK_SPAN_S = 1e-3
#: A run stalls when this many calls fail within :data:`STALL_SPAN_S` of simulated time.
STALL_FAILURES = 60
STALL_SPAN_S = 1e-4
#: Shortest integrator call (s): the floor of the predicted spans and of retries after a failure.
MIN_SPAN_S = 1e-6
#: A call that passed an event unpredicted is redone to this fraction of the event's estimated
#: time (:meth:`.events.EventHandler.overshoot`, :meth:`~.events.EventHandler.late`): the event
#: is then ahead, and predicted.
REDO_FRACTION = 0.9


class CallFailed(RuntimeError):
    """An integrator call failed at the shortest span: the last good state and IDAS's error."""

    def __init__(self, t: float, x, z, error: Exception):
        super().__init__(str(error))
        self.t, self.x, self.z, self.error = t, x, z, error


class EventStepper:
    """Integrates a model with events between output times, the events decided by ``handler``.

    Parameters
    ----------
    form : Formulation
    dae_fn : casadi.Function
        ``(t, x, z, p, u) -> (ode, alg, ...)`` with ``t`` relative to ``p`` (the driver's DAE;
        ``p`` is ``[t_a, *handler.mode()]``).
    opts : dict
        IDAS options.
    x, z : ndarray
        The consistent initial state.
    stats : dict
        Summed IDAS statistics (``stat_keys``) and the handler's counts
        (:attr:`.events.EventHandler.stat_keys`), among them the driver's own under the
        handler's :attr:`~.events.EventHandler.counter_names`.
    stat_keys : tuple of str
        The IDAS statistics summed.
    handler : EventHandler
        Attached to ``form`` and ``stats`` (:meth:`~.events.EventHandler.attach`).
    calls : object, optional
        Another integrator behind the calls: an object whose ``call(x, z, t_a, h, inner,
        free)`` does what :meth:`call` does (e.g. generalized-alpha,
        :class:`.alpha_events.AlphaCalls`); ``dae_fn`` and the IDAS options are then unused but
        for the tolerances in ``opts`` that the handler's :meth:`~.events.EventHandler.start`
        receives.
    """

    def __init__(self, form, dae_fn, opts: dict, x, z, stats: dict, stat_keys, handler, calls=None):
        self.form = form
        self.stats = stats
        self.stat_keys = stat_keys
        self.handler = handler
        self.counts = handler.counter_names
        # IDAS's own messages on calls the driver retries would only alarm (failures it cannot
        # recover from are reported with the time and the worst residual).
        self.opts = {**{k: v for k, v in opts.items() if k != "init_xdot"}, "calc_ic": True,
                     "disable_internal_warnings": True}
        self.opts.setdefault("reltol", 1e-6)
        # A call is at most one output interval: this many steps mean a singularity (a fold
        # passed unnoticed), and the retry, shorter and after an event check, beats waiting.
        self.opts["max_num_steps"] = min(int(opts.get("max_num_steps", MAX_CALL_STEPS)), MAX_CALL_STEPS)
        if calls is None:
            self.set_dae(dae_fn)
        else:
            self.call = calls.call
        self.step_hint = None  # IDAS's last step in the last call (s), see _first_step
        self.idas_said: list[str] = []  # IDAS's last message on a failed call
        self._start = None  # (t, x_dot) at the last call's start, see _first_step
        self.span, self.event = handler.start(x, z, self._atol(len(x)))

    def set_dae(self, dae_fn) -> None:
        """Use ``dae_fn`` from now on (e.g. after a window moved)."""
        self.dae_fn = dae_fn
        self.integrators = CallIntegrators(dae_fn, self.opts)

    def call(self, x, z, t_a: float, h: float, inner=(), free: bool = False):
        """States at ``t_a + inner`` and at ``t_a + h``: ``(x, z)``, one column per time (one
        IDAS call; ``RuntimeError`` on failure). ``inner``: offsets (s) in ``(0, h)`` of output
        times inside the call (IDAS interpolates them: they do not limit its steps). The
        integrator, cached per grid, solves the shifted DAE (:func:`.shifted.shifted_dae`) from the
        DAE's own ``x_dot``, in time normalized by ``h`` (one integrator serves every length;
        in seconds for calls on the binary grid under a step limit); ``free``: a call off the
        binary grid; see :meth:`_attempts` for the fallbacks."""
        p = np.r_[t_a, self.handler.mode()]
        grid = [float(v) for v in inner] + [h]
        x = np.asarray(x, float)
        x_dot = np.asarray(self.dae_fn(0.0, x, z, p, ca.DM(0, 1))[0]).ravel()
        scale = 1.0 + self.opts["reltol"] * np.abs(x) / self._atol(len(x))
        first = self._first_step(t_a, x, x_dot)
        exc = None
        for n, (solver, shifted) in enumerate(self._attempts(h)):
            if n:
                self.stats[self.counts["fallbacks"]] += 1
            # In time normalized by the call's length, one integrator serves calls of every
            # length with the same output fractions (a step limit in seconds would not).
            limited = "max_step_size" in self.opts
            normalized = shifted and (free or not limited)
            tau_grid, warp = call_grid(grid, h, normalized, not limited)
            # The call starts at (1 + warp) times the plain time rate.
            level = self._first_step_level(h * (1 + warp), first) if shifted else None
            integ = self.integrators.get(tau_grid, solver, shifted, normalized, level, h if normalized else 1.0)
            # IDAS prints its errors (through CasADi, to sys.stderr): the driver retries failed
            # calls, so a message is kept for the report of a failure the driver cannot recover.
            with contextlib.redirect_stderr(io.StringIO()) as said:
                try:
                    if shifted:
                        p_ext = np.r_[p, x, x_dot, scale, h, warp] if normalized else np.r_[p, x, x_dot, scale]
                        out = integ(x0=np.zeros(len(x)), z0=z, p=p_ext)
                    else:
                        out = integ(x0=x, z0=z, p=p)
                except RuntimeError as err:
                    if exc is None:  # the first attempt's reason: the fallbacks' are consequences
                        exc, self.idas_said = err, said.getvalue().strip().splitlines()[-1:]
                        if normalized and self.idas_said:  # IDAS's t and h are fractions of the call
                            self.idas_said[0] += f" [in the call's normalized time; the call: {h:.6g} s from t = {t_a:.6g} s]"
                    continue
            st = integ.stats()
            for k in self.stat_keys:
                self.stats[k] += int(st.get(k, 0))
            last = float(st.get("hlast", math.nan)) * (h * (1 - warp) if normalized else 1.0)  # the rate at the end
            self.step_hint = last if n == 0 and math.isfinite(last) and last > 0 else None
            xs = np.asarray(out["xf"])
            if shifted:
                xs = x[:, None] + np.outer(x_dot, grid) + scale[:, None] * xs
            return xs, np.asarray(out["zf"])
        raise exc

    def _first_step(self, t_a: float, x, x_dot) -> float | None:
        """IDAS's first step (s) in a call from ``(t_a, x)`` that continues the last one: its
        last step there (:attr:`step_hint`), at most the step whose order-1 error is half the
        tolerance, ``sqrt(||x''||^-1)`` in IDAS's weighted RMS norm, with ``x''`` the change of
        ``x_dot`` since the last call's start (none across an event: ``_start`` is cleared). IDAS
        restarts at order 1, whose error test a last step taken at order 3 to 5 fails: on the
        conical vehicle the bare last step took 603 steps per simulated second instead of 417.
        ``None``: no hint (first call, after a failure, index 1: :meth:`_first_step_level`)."""
        last, self._start = self._start, (t_a, x_dot)
        hint = self.step_hint if self.form.index == "ggl" else None
        if hint is None or last is None or not t_a > last[0]:
            return hint
        x_dd = (x_dot - last[1]) / (t_a - last[0])
        weights = 1.0 / (self.opts["reltol"] * np.abs(x) + self._atol(len(x)))
        norm = float(np.sqrt(np.mean((x_dd * weights) ** 2)))
        return min(hint, 1.0 / math.sqrt(norm)) if norm > 0 else hint

    def _first_step_level(self, h: float, first: float | None) -> int | None:
        """``k`` of IDAS's first step ``h / 2^k`` in a call of length ``h`` (s): ``first``
        (:meth:`_first_step`) rounded down to a level, else ``None`` (:data:`.shifted.INITIAL_STEP`).
        Restarting from about 1e-3 of the call, IDAS takes ten steps, each with a Jacobian
        set-up, to double its step back up: most of the steps of a model with a hundred calls
        per simulated second. Only with GGL stabilization: index 1 leaves the position
        constraints to drift, and its first steps at order 1 and the last step's size drift
        more (the cant-ramp wheelset: 1.05e-4 m over 0.8 s instead of 3.9e-5 m)."""
        if first is None:
            return None
        k = max(0, math.ceil(math.log2(h / first) - 1e-9))
        return min(FIRST_STEP_LEVELS, FIRST_STEP_LEVEL_STEP * math.ceil(k / FIRST_STEP_LEVEL_STEP))

    def _atol(self, n_x: int) -> np.ndarray:
        """Absolute tolerances of the differential states."""
        if "abstolv" in self.opts:
            return np.asarray(self.opts["abstolv"][:n_x], float)
        return np.full(n_x, float(self.opts.get("abstol", 1e-8)))

    def _attempts(self, h: float):
        """``(linear solver, shifted)`` to try in turn for a call of ``h`` seconds. IDAS's first
        steps of a microsecond call have ``cj = 1/h`` near 1e7, where the QR solver of the GGL
        form has failed on consistent states that LU integrates; IDACalcIC (not shifted) last:
        its Newton matrix is singular with GGL's position rows (they hold no algebraic unknown)
        and it may fail on a state consistent to the tolerance. The fallbacks rescue calls that
        cannot start; a call longer than :data:`FALLBACK_SPAN_S` gets none: it fails mostly at
        a fold met on the way (a contact point vanishing with a rival born inside the call),
        which every fallback meets again after as many steps (S1002 vehicle: one 0.1 s call
        cost 1.1 s in three attempts), and the driver's shorter retry, checked first, either
        starts or is short enough for them."""
        solver = self.opts.get("linear_solver")
        if h > FALLBACK_SPAN_S:
            return [(solver, True)]
        return [(solver, True), ("csparse", True), (solver, False)]

    def _after(self, x, z, t, checks=None):
        """The handler's events at ``(t, x, z)``, the next call's limits set (:meth:`.events.EventHandler.after`)."""
        x, z, changed, self.span, self.event = self.handler.after(x, z, t, checks)
        if changed:
            self._start = None  # x_dot jumped: no second derivative across
        return x, z, changed

    def _next_end(self, pos, end: int, k_max: int, dt: float):
        """``(end position, free)`` of the next call from ``pos`` (in units of ``dt / end``, see
        :meth:`advance`; an integer, but for an output time a call was kept up to). On the binary grid: ``dt / 2^k``, the longest not
        beyond the span, from a multiple of it (one integrator per grid serves all such calls).
        A predicted event (the handler's ``event``) that binds the span is
        called to exactly (a free call, :meth:`call`), where calls on the grid would close in on
        it by halves. From off the grid (after such a call), a free call goes to the next
        multiple of the level, or to the one after it when the first is less than a quarter
        level away and the span allows (no needlessly short call)."""
        k = min(k_max, max(0, math.ceil(math.log2(dt / self.span)))) if self.span < dt else 0
        unit = 2 ** (k_max - k)
        if math.isfinite(self.event) and self.event <= self.span * (1 + 1e-9):
            # On the finest grid (dt / end <= MIN_SPAN_S), so that positions stay integers.
            event_end = max(pos + 1, round(pos + self.event / dt * end))
            if event_end < end:
                return event_end, True
        if pos % unit == 0:
            return pos + unit, False
        b = (math.floor(pos / unit) + 1) * unit
        if b - pos < 0.25 * unit and b + unit <= end and (b + unit - pos) * dt / end <= self.span:
            b += unit
        return b, True

    def advance(self, x, z, t0: float, times, emit=None):
        """State at ``times[-1]`` from ``(x, z)`` at ``t0``, with the handler's events checked
        after every call; ``emit(j, x, z)`` receives the state at each of the increasing output
        ``times`` (> ``t0``) as soon as it is known. The output times do not end calls: a call
        spans as many of them as the handler allows (:meth:`call`), so that dense output costs
        no event checks and no IDAS restarts.

        A failed call is retried from the state the handler's :meth:`~.events.EventHandler.recover`
        gives if it changed it, else four times shorter.

        Raises
        ------
        CallFailed
            If a call of the shortest length (:data:`MIN_SPAN_S` or just above) fails without an
            event to try, or :data:`STALL_FAILURES` calls fail within :data:`STALL_SPAN_S`.
        SolverError
            If the handler ends the run (:meth:`~.events.EventHandler.verify`).
        """
        times = np.atleast_1d(np.asarray(times, float))
        t1 = float(times[-1])
        dt = t1 - t0
        k_max = max(0, math.ceil(math.log2(dt / MIN_SPAN_S)))
        # The position in units of dt / 2^k_max and the length in levels k (dt / 2^k).
        pos, end = 0, 2**k_max
        shortest = dt / end * (1 + 1e-9)
        failures = 0
        stall_t, stalled = t0, 0
        emitted = 0
        while pos < end:
            pos_b, free = self._next_end(pos, end, k_max, dt)
            t = t0 + dt * pos / end
            t_b = t0 + dt * pos_b / end
            h = t_b - t
            redo_end = -math.inf  # end (s) of a late event's redo if the call is kept up to an output
            # Output times strictly inside the call (those within rounding of its end are its end).
            inside = [j for j in range(emitted, len(times) - 1) if times[j] < t_b - 1e-12 * max(1.0, abs(t_b))]
            try:
                inner = [times[j] - t for j in inside]
                xs_new, zs_new = self.call(x, z, t, h, inner, free)
            except RuntimeError as exc:
                self.step_hint = None
                self.stats[self.counts["retries"]] += 1
                failures += 1
                if t - stall_t > STALL_SPAN_S:
                    stall_t, stalled = t, 0
                stalled += 1
                if stalled > STALL_FAILURES:
                    reason = self.handler.stall_reason(exc, STALL_FAILURES, STALL_SPAN_S)
                    raise CallFailed(t, x, z, RuntimeError(reason)) from None
                x, z, retry, self.span, self.event = self.handler.recover(x, z, t, failures)
                if retry:
                    self._start = None  # a state the handler changed: no second derivative across
                    continue
                if h <= shortest:
                    said = f" (IDAS: {self.idas_said[0]})" if self.idas_said else ""
                    raise CallFailed(t, x, z, RuntimeError(f"{exc}{said}{self.handler.failure_hint()}")) from None
                self.span, self.event = h / 4, math.inf
                continue
            except (SolverError, ParameterError) as exc:
                raise CallFailed(t, x, z, exc) from None
            self.stats[self.counts["calls"]] += 1
            failures = 0
            if h > shortest:
                offsets = inner + [h]
                t_passed = self.handler.overshoot(z, offsets, xs_new, zs_new)
                if t_passed is not None:
                    # An event passed unpredicted: redo the call up to just before it.
                    self.stats[self.counts["overshoot_redos"]] += 1
                    self.span, self.event = max(REDO_FRACTION * t_passed, MIN_SPAN_S), math.inf
                    continue
            checks_end = self.handler.check(xs_new[:, -1], zs_new[:, -1])
            if h > shortest:
                t_late = self.handler.late(checks_end, h, t)
                redo = None if t_late is None else max(REDO_FRACTION * t_late, MIN_SPAN_S)
                if redo is not None and max(1, round(redo / dt * end)) >= pos_b - pos:
                    # The redo, rounded to the finest grid as :meth:`_next_end` rounds an event,
                    # would be this call again (a crossing a unit or two after its start): keep
                    # the call, and the check at its end handles the event.
                    redo = None
                if redo is not None:
                    # An event came unpredicted inside the call: redo up to before it.
                    self.stats[self.counts["late_redos"]] += 1
                    # A free call to just before it (then ahead, and predicted), from the last
                    # output inside the call before it if there is one.
                    self.span = self.event = redo
                    kept = self.handler.kept_output(t, inner, xs_new, zs_new, self.span)
                    if kept is None:
                        continue
                    self.stats[self.counts["late_redos_kept"]] += 1
                    col, checks_col = kept
                    for c in range(col):
                        if emit is not None:
                            emit(inside[c], xs_new[:, c], zs_new[:, c])
                    j = inside[col]
                    emitted, redo_end = j, t + self.span
                    pos_b, t_b = (times[j] - t0) / dt * end, float(times[j])  # the output's own time
                    xs_new, zs_new, checks_end, inside = xs_new[:, : col + 1], zs_new[:, : col + 1], checks_col, []
            pos = pos_b
            for col, j in enumerate(inside):
                if emit is not None:
                    emit(j, xs_new[:, col], zs_new[:, col])
            emitted += len(inside)
            x, z, _ = self._after(xs_new[:, -1], zs_new[:, -1], t_b, checks=checks_end)
            if redo_end - t_b > MIN_SPAN_S:
                # Kept up to an output before a late event: on to the redo's end, as from the start.
                self.span, self.event = min(self.span, redo_end - t_b), min(self.event, redo_end - t_b)
            # A call ending on an output time emits the state after the event check.
            while emitted < len(times) and abs(times[emitted] - t_b) <= 1e-12 * max(1.0, abs(t_b)):
                if emit is not None:
                    emit(emitted, x, z)
                emitted += 1
            reason = self.handler.verify(x, z)
            if reason is not None:
                raise SolverError(f"at t = {t_b:.6g} s {reason}")
        return x, z

