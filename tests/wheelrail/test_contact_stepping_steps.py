"""The contact driver's choices between calls (:class:`symcat.integrate.event_stepping.EventStepper`
with the wheel/rail handler :class:`symcat.wheelrail_events.contact_events.ContactEvents`):
IDAS's first step in a call that continues the last one, the time a late jump is redone at and
the output its call is kept up to, and the fallbacks of a failed call."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from symcat.integrate.event_stepping import FALLBACK_SPAN_S, FIRST_STEP_LEVEL_STEP, FIRST_STEP_LEVELS, EventStepper
from symcat.wheelrail_events.contact_events import ContactEvents
from symcat.wheelrail_events.contact_jumps import ContactCheck, Rival
from symcat.wheelrail_events.late_jumps import kept_output


def _stepper(hint=None):
    stepper = object.__new__(EventStepper)  # the choices need no model
    stepper.step_hint = hint
    return stepper


def _handler(checks=()):
    handler = object.__new__(ContactEvents)  # the choices need no model
    handler.checks, handler.refused, handler.early_m = list(checks), {}, 0.0
    return handler


@pytest.mark.parametrize("hint, level", [(None, None), (1.0, 0), (2.0, 0), (0.5, FIRST_STEP_LEVEL_STEP),
                                         (1 / 9, 2 * FIRST_STEP_LEVEL_STEP), (1e-9, FIRST_STEP_LEVELS)])
def test_first_step_is_the_last_one_rounded_down_to_a_level(hint, level):
    """IDAS's first step ``h / 2^k``: the previous call's last step rounded down to a level
    (never above it, never above the call), the default without one."""
    h = 1e-2
    k = _stepper()._first_step_level(h, None if hint is None else hint * h)
    assert k == level
    if k is not None and k < FIRST_STEP_LEVELS:
        assert h / 2**k <= min(hint, 1.0) * h * (1 + 1e-12)


def _check(gap_rate=0.0, rivals=()):
    return ContactCheck("w", 0.0, gap_rate, 1.0, math.inf, np.zeros(4), list(rivals))


def _rival(s1, gap, rate=0.0):
    return Rival(SimpleNamespace(s=np.array([s1, 0.0, 0.0, 0.0]), gap_m=gap), 1.0, rate)


def test_a_late_jump_is_redone_at_the_secant_zero_of_the_margin():
    """A rival 3 um above at the start and 1 um below at the end crossed at 3/4 of the call;
    the nearest rival along the wheel is the one followed, not the lowest."""
    start = _check(rivals=[_rival(0.030, 0.5e-6), _rival(0.001, 3e-6)])
    end = _check(rivals=[_rival(0.0012, -1e-6)])
    assert _handler(checks=[start]).late([end], 2e-3, 0.0) == pytest.approx(0.75 * 2e-3)


def test_a_rival_born_inside_a_call_is_traced_back_along_its_rate():
    """No rival at the start: the crossing is extrapolated back from the end's margin rate
    (1 um below, closing at 1 mm/s: 1 ms before the end); without a closing rate, half."""
    end = _check(gap_rate=0.0, rivals=[_rival(0.001, -1e-6, rate=-1e-3)])
    assert _handler(checks=[_check()]).late([end], 4e-3, 0.0) == pytest.approx(3e-3)
    level = _check(gap_rate=0.0, rivals=[_rival(0.001, -1e-6, rate=0.0)])
    assert _handler(checks=[_check()]).late([level], 4e-3, 0.0) == pytest.approx(2e-3)
    # A rival only nanometres below is no late jump (the next check jumps to it).
    shallow = _check(rivals=[_rival(0.001, -1e-9, rate=-1e-3)])
    assert _handler(checks=[_check()]).late([shallow], 4e-3, 0.0) is None


@pytest.mark.parametrize("margin, rate, early_m, jumps", [
    (5e-8, -1e-3, 1e-7, True),    # 50 nm above, crossing in 50 us: within the horizon
    (5e-8, -1e-3, 0.0, False),    # no early jumps asked for
    (5e-8, 1e-3, 1e-7, False),    # receding
    (5e-7, -1e-3, 1e-6, False),   # crossing in 0.5 ms: beyond the horizon
    (5e-7, -1e-2, 1e-7, False),   # within the horizon but higher than asked
    (-2e-9, 0.0, 0.0, True),      # below by more than the tolerance: always
])
def test_a_rival_about_to_sink_below_is_jumped_to_early(margin, rate, early_m, jumps):
    """:meth:`ContactCheck.target` with ``early_m``: a formed rival no higher than that which is
    predicted (from the gap rates) to lie below within ``EARLY_JUMP_S`` is a target now."""
    check = _check(gap_rate=0.0, rivals=[_rival(0.001, margin, rate=rate)])
    assert (check.target(early_m=early_m) is not None) == jumps


def test_a_late_jump_within_the_early_height_is_not_redone():
    """A rival that sank below by less than the driver's early-jump height is jumped to where
    the call ended (the wheelset rises by as much as an early jump lifts it)."""
    end = _check(gap_rate=0.0, rivals=[_rival(0.001, -1e-6, rate=-1e-3)])
    handler = _handler(checks=[_check()])
    handler.early_m = 2e-6
    assert handler.late([end], 4e-3, 0.0) is None
    handler.early_m = 5e-7
    assert handler.late([end], 4e-3, 0.0) == pytest.approx(3e-3)


def test_only_short_calls_fall_back_to_other_solvers():
    """A call that fails falls back to LU and to IDACalcIC only when it is short (a failure to
    start); a long one fails mostly at a fold met on the way, which every fallback would meet
    again after as many steps."""
    stepper = _stepper()
    stepper.opts = {"linear_solver": "qr"}
    assert stepper._attempts(2 * FALLBACK_SPAN_S) == [("qr", True)]
    assert stepper._attempts(FALLBACK_SPAN_S) == [("qr", True), ("csparse", True), ("qr", False)]


def test_a_late_jump_keeps_the_call_up_to_its_last_output_before_the_crossing(monkeypatch):
    """The output kept is the last one no later than the redo's end, if no rival lies below
    there by more than a late jump's depth; else none (the call is redone from its start)."""
    import symcat.wheelrail_events.contact_events as events

    states = {1.0: _check(), 2.0: _check(), 3.0: _check(rivals=[_rival(0.001, -1e-6)])}
    monkeypatch.setattr(events, "check_contacts", lambda form, x, z: [states[float(x[0])]])
    handler = _handler(checks=[_check()])
    handler.form = None
    xs = np.array([[1.0, 2.0, 3.0]])
    offsets = [1e-3, 2e-3, 3e-3]
    assert handler.kept_output(0.0, offsets, xs, xs, 2.5e-3)[0] == 1
    assert handler.kept_output(0.0, offsets, xs, xs, 0.5e-3) is None
    states[2.0] = _check(rivals=[_rival(0.001, -1e-6)])  # already below at the kept output
    assert handler.kept_output(0.0, offsets, xs, xs, 2.5e-3) is None
    states[2.0] = _check(rivals=[_rival(0.001, -1e-9)])  # nanometres below: the next check jumps
    assert handler.kept_output(0.0, offsets, xs, xs, 2.5e-3)[0] == 1


def test_a_late_jump_within_two_units_of_the_finest_grid_does_not_redo_the_same_call():
    """A crossing 1.8 units of the finest grid after a call's start: the redo, rounded to that
    grid, would be the call of 2 units again, and again (the S1002 wheelset at rtol 1e-6 over 4 s
    with 200 outputs repeated one call 11000 times at t = 0.226 s). The call is kept and the
    check at its end jumps; the driver goes on to the end of the span."""
    import symcat.integrate.event_stepping as stepping

    dt = 0.1
    k_max = math.ceil(math.log2(dt / stepping.MIN_SPAN_S))
    unit = dt / 2**k_max
    calls = []

    def call(x, z, t, h, inner, free):
        calls.append((t, h))
        if len(calls) > 50:
            raise AssertionError(f"the driver repeats its call at t = {t}")
        return np.column_stack([x] * (len(inner) + 1)), np.column_stack([z] * (len(inner) + 1))

    def late(checks_end, h, t):  # one crossing, at 1.8 units, seen by any call from 0 passing it
        return 1.8 * unit if t == 0.0 and h > 1.8 * unit else None

    def after(x, z, t, checks=None):  # the check after a call sets the span anew
        return x, z, [], dt, math.inf

    def check(x, z):
        return [_check()]

    handler = SimpleNamespace(overshoot=lambda *a: None, check=check, late=late, after=after, verify=lambda x, z: None,
                              kept_output=lambda *args: kept_output(check, late, *args))
    stepper = _stepper()
    stepper.form, stepper.stats = None, {"contact_calls": 0, "jump_redos": 0, "switch_redos": 0}
    stepper.handler, stepper.counts = handler, ContactEvents.counter_names
    stepper.span, stepper.event = dt, math.inf
    stepper.call = call
    x, z = stepper.advance(np.zeros(1), np.zeros(1), 0.0, [dt])
    assert calls[0] == (0.0, dt)
    # the redo: 0.9 * 1.8 units, on the grid 2 units, kept although it passes the crossing
    assert calls[1] == (0.0, pytest.approx(2 * unit))
    assert calls[2][0] == pytest.approx(2 * unit)
    assert stepper.stats["jump_redos"] == 1
