"""Contact jumps the contact driver found late (:mod:`.contact_events`): when a rival sank
below the followed point inside a call, and how much of that call is kept."""
from __future__ import annotations

from typing import Callable

#: A jump target this deep at a call's end (m) means the jump came late: the call is redone
#: shorter (:func:`late_jump_time`).
LATE_JUMP_GAP_M = 1e-8
#: Least fraction of a call that a late jump's redo keeps (:func:`late_jump_time`).
LATE_JUMP_MIN_FRACTION = 0.25


def late_jump_time(starts, ends, h: float, refused: dict, early_m: float) -> float | None:
    """Time (s after the call's start) at which a rival sank below the followed point, if at
    the call's end one lies deeper than :data:`LATE_JUMP_GAP_M` (and than the driver's
    early-jump height ``early_m``): the jump is then redone at about that time. ``starts``,
    ``ends``: the contact checks at the call's start and end (one per contact, in the same
    order), ``h`` its length (s), ``refused``: contact -> wheel parameter of a refused target.
    The rates' linear prediction (:meth:`.contact_jumps.ContactCheck.span_s`) misses a rival
    that speeds up or is born inside the call; a late jump lifts the wheelset (GGL projects
    onto the deeper point: energy gained) or leaves it penetrating (index 1).

    The time is the secant zero of the rival's margin between the call's ends if a rival
    lay above the followed point at the start (the nearest along the wheel), else the
    margin's zero extrapolated back from its end rate (a rival born inside the call), else
    half the call; at least :data:`LATE_JUMP_MIN_FRACTION` of it, so that the redone calls
    close in geometrically where the estimate fails (at a rail's kink the point past the
    crease appears with the crossing: an estimate near the start would advance the run by
    microseconds per call)."""
    first = None
    for start, end in zip(starts, ends):
        rival = end.target(False, refused.get(end.name))
        if rival is None or rival.point.gap_m >= -max(LATE_JUMP_GAP_M, early_m):
            continue
        m1 = end.margin_m(rival)
        before = [r for r in start.rivals if start.margin_m(r) > 0]
        f = 0.5
        if before:
            m0 = start.margin_m(min(before, key=lambda r: abs(r.point.s[0] - rival.point.s[0])))
            f = m0 / (m0 - m1)
        elif rival.gap_rate_m_s < end.gap_rate_m_s:
            f = max(0.0, 1.0 + m1 / ((end.gap_rate_m_s - rival.gap_rate_m_s) * h))
        f = min(max(f, LATE_JUMP_MIN_FRACTION), 1.0)
        first = f * h if first is None else min(first, f * h)
    return first


def kept_output(check: Callable, late: Callable, t: float, offsets, xs, zs, before: float):
    """``(column, checks)`` of the last output inside a call from ``t`` (at ``offsets``, s,
    states ``xs``, ``zs`` by column) that lies at most ``before`` seconds after its start and
    has no rival deeper than a late jump's there, else ``None``; ``check(x, z)``: the contact
    checks of a state, ``late(checks, h, t)``: :func:`late_jump_time` of a call of ``h`` from
    ``t`` ending with ``checks``.

    A call that passed a contact jump unpredicted is then kept up to that output, where the
    rival, still above, is predicted, instead of redone from its start: the redone calls were a
    third of the integration in the first second of the S1002 vehicle (calls of 25 to 100 ms
    with a contact jump every 40 ms). The output's state is IDAS's interpolation: its
    constraints hold to the tolerance, and the next call starts from the DAE's own ``x_dot``
    there like any other."""
    for col in range(len(offsets) - 1, -1, -1):
        if offsets[col] > before:
            continue
        checks = check(xs[:, col], zs[:, col])
        return (col, checks) if late(checks, offsets[col], t) is None else None
    return None
