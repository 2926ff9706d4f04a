"""The wheel/rail contacts' event handler of the stepping driver
(:class:`symcat.integrate.event_stepping.EventStepper`): contact-point jumps
(:mod:`.contact_jumps`, found late: :mod:`.late_jumps`) and lift-off and touchdown
(:mod:`.contact_switching`) checked after every call, the calls shortened toward them.

Early jumps: a rival predicted to sink below its followed point within
:data:`.contact_jumps.EARLY_JUMP_S`, no higher than :data:`EARLY_JUMP_ATOL` of the smallest
absolute tolerance, is jumped to at once (:meth:`.contact_jumps.ContactCheck.target`), and a
jump found late by no more than that height is not redone. The wheels of one side of a symmetric
vehicle reach their jumps microseconds apart; one by one, each cost a call, a check and a
projection. The point left is refused for twice that horizon, lest the driver jump back to it
while it still lies below. S1002 vehicle, rtol 1e-4: 89 -> 56 calls, 1098 -> 987 steps and
534 -> 416 Jacobian set-ups per simulated second.

A failed call is retried from its start after a relaxed jump check (a point about as low; at
most :data:`RELAXED_JUMPS` times in a row, lest two vanishing points alternate). A call that
fails right after a jump is retried from the point before it, and the jump target is refused for
:data:`REFUSAL_HOLD_S` (two points nanometres apart in depth, IDAS failing from one: jumping back
and forth would advance by microseconds per cycle).
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np

from ..integrate.events import EventHandler
from ..integrate.failure import split_state
from .contact_jumps import EARLY_JUMP_S, JUMP_TOLERANCE_M, check_contacts, jump_contacts, lost_contact
from .contact_switching import Switching, initial_open
from .late_jumps import kept_output, late_jump_time

#: Relaxed jumps tried after consecutive failed calls from one state.
RELAXED_JUMPS = 3
#: How long (s) a jump target stays refused after IDAS failed from it (see :meth:`ContactEvents.recover`).
REFUSAL_HOLD_S = 1e-3
#: Height of an early jump's target (:data:`.contact_jumps.EARLY_JUMP_S`) as a fraction of the
#: smallest absolute tolerance of the state: the rise it gives the wheelset is within IDAS's error.
EARLY_JUMP_ATOL = 0.1
#: A failure while a contact point moves faster than this along its wheel profile (m/s) is
#: reported with it (:func:`sweep_hint`).
SWEEP_HINT_M_S = 5.0


class ContactEvents(EventHandler):
    """The wheel/rail contacts of a model as events of the stepping driver.

    The run's statistics count ``contact_jumps``, ``contact_calls``, ``contact_retries``,
    ``contact_fallbacks``, ``contact_refusals``, ``lift_offs``, ``touchdowns``, ``switch_redos``
    and ``jump_redos`` (calls redone up to a switch or a contact jump they passed unpredicted,
    :meth:`.contact_switching.Switching.overshoot`, :meth:`late`), of which
    ``jump_redos_kept`` were kept up to an output inside them (:meth:`kept_output`).
    """

    stat_keys: ClassVar[tuple] = ("contact_jumps", "contact_calls", "contact_retries", "contact_fallbacks",
                                  "contact_refusals", "lift_offs", "touchdowns", "switch_redos", "jump_redos",
                                  "jump_redos_kept")
    counter_names: ClassVar[dict] = {"calls": "contact_calls", "retries": "contact_retries",
                                     "fallbacks": "contact_fallbacks", "overshoot_redos": "switch_redos",
                                     "late_redos": "jump_redos", "late_redos_kept": "jump_redos_kept"}

    def attach(self, form, stats: dict) -> None:
        self.form = form
        self.stats = stats
        for key in self.stat_keys:
            stats.setdefault(key, 0)
        # Contacts open at the start (a wheelset dropped on its rails).
        self.switching = Switching(form, initial_open(form))
        self.events = self.switching.events
        self.refused: dict[str, tuple[float, float]] = {}  # contact -> (wheel parameter, until t)
        self.early_m = 0.0  # height (m) of an early jump's target, and depth of a late one's that is not redone
        self._jumped_from = None  # (t, x, z, [(contact, new wheel parameter)]) of the last jump
        self.checks = []

    def mode(self) -> np.ndarray:
        """The open flags of the contacts (1: lifted off)."""
        return self.switching.open

    def open_rows(self) -> list:
        return self.switching.open_rows()

    def start(self, x, z, atol) -> tuple[float, float]:
        self.early_m = EARLY_JUMP_ATOL * float(np.min(atol))
        self.checks = check_contacts(self.form, x, z)
        span = min(min(c.span_s() for c in self.checks), self.switching.span_s(0.0, z, self.checks))
        return span, min(c.event_s() for c in self.checks)

    def check(self, x, z):
        """:func:`.contact_jumps.check_contacts` of the state."""
        return check_contacts(self.form, x, z)

    def after(self, x, z, t: float, checks=None) -> tuple:
        return self._after(x, z, t, checks=checks)

    def _after(self, x, z, t, relaxed=False, checks=None):
        checks = check_contacts(self.form, x, z) if checks is None else checks
        refused = {name: s1 for name, (s1, until) in self.refused.items() if t < until}
        x_from, z_from = x, z
        x, z, jumped = jump_contacts(self.form, x, z, t, checks, relaxed, open_rows=self.switching.open_rows(),
                                     refused=refused, early_m=self.early_m)
        self._jumped_from = None
        if jumped:
            self.stats["contact_jumps"] += len(jumped)
            index = {e.joint.name: e.s_index for e in self.form.model.wheelrail}
            s_from = split_state(self.form, x_from, z_from)["s"]
            for c in (c for c in checks if c.name in jumped):
                if c.margin_m(c.target(relaxed, refused.get(c.name), self.early_m)) >= -JUMP_TOLERANCE_M:
                    # An early jump: the point left lies below the new one until the crossing,
                    # and the driver must not jump back to it.
                    self.refused[c.name] = (float(s_from[index[c.name]]), t + 2 * EARLY_JUMP_S)
            if not relaxed:
                s = split_state(self.form, x, z)["s"]
                self._jumped_from = (t, x_from, z_from, [(n, float(s[index[n]])) for n in jumped])
            checks = check_contacts(self.form, x, z)
        x, z, switched = self.switching.update(x, z, t, checks)
        if switched:
            for s in switched:
                self.stats["lift_offs" if s.kind == "lift-off" else "touchdowns"] += 1
            checks = check_contacts(self.form, x, z)
        span = min(min(c.span_s() for c in checks), self.switching.span_s(t, z, checks))
        event = min(c.event_s() for c in checks)
        self.checks = checks
        return x, z, jumped + [s.name for s in switched], span, event

    def recover(self, x, z, t: float, failures: int) -> tuple:
        """Back to the point before a jump made at ``t`` (its target refused for
        :data:`REFUSAL_HOLD_S`), else a relaxed jump check (the first :data:`RELAXED_JUMPS`
        failures in a row)."""
        if self._jumped_from is not None and self._jumped_from[0] == t:
            _, x, z, targets = self._jumped_from
            for name, s1 in targets:
                self.refused[name] = (s1, t + REFUSAL_HOLD_S)
            self.stats["contact_refusals"] += 1
            x, z, _, span, event = self._after(x, z, t)
            return x, z, True, span, event
        x, z, jumped, span, event = self._after(x, z, t, relaxed=failures <= RELAXED_JUMPS)
        return x, z, bool(jumped), span, event

    def overshoot(self, z0, offsets, xs, zs) -> float | None:
        """A lift-off or touchdown passed unpredicted (:meth:`.contact_switching.Switching.overshoot`)."""
        return self.switching.overshoot(z0, self.checks, offsets, xs, zs)

    def late(self, checks_end, h: float, t: float) -> float | None:
        """:func:`.late_jumps.late_jump_time` of a call of ``h`` seconds from ``t``."""
        refused = {name: s1 for name, (s1, until) in self.refused.items() if t + h < until}
        return late_jump_time(self.checks, checks_end, h, refused, self.early_m)

    def kept_output(self, t: float, offsets, xs, zs, before: float):
        """:func:`.late_jumps.kept_output` of a call from ``t`` that passed a contact jump."""
        return kept_output(self.check, self.late, t, offsets, xs, zs, before)

    def verify(self, x, z) -> str | None:
        """A wheel that ran off its rail or lifts off in the global form (:func:`.contact_jumps.lost_contact`)."""
        return lost_contact(self.form, x, z, self.checks)

    def stall_reason(self, exc, failures: int, span_s: float) -> str:
        return stall_reason(self.checks, exc, failures, span_s)

    def failure_hint(self) -> str:
        return sweep_hint(self.checks)


def stall_reason(checks, exc, failures: int, span_s: float) -> str:
    """Why the contact driver stalled (``failures`` calls failed within ``span_s`` seconds, the
    last with ``exc``), from its contact checks: the flattest contact."""
    flat = min(checks, key=lambda c: c.curvature_per_m)
    last = str(exc).strip().splitlines()[-1] if str(exc).strip() else repr(exc)
    return (f"{failures} integrator calls failed within {span_s:g} s of simulated time "
            f"(last: {last.strip('. ')}); the flattest contact is {flat.name}, relative curvature "
            f"{flat.curvature_per_m:.3g} 1/m with {len(flat.rivals)} other minima of the gap: nearly "
            "conformal wheel and rail, where one constraint point per wheel is ill-conditioned (another "
            "n_out or rtol moves the call boundaries; profiles with more curvature difference avoid it)")


def sweep_hint(checks) -> str:
    """Why the contact points may defeat IDAS, if one sweeps: the fastest along its wheel
    profile when that exceeds :data:`SWEEP_HINT_M_S` (its rate grows as the relative
    curvature shrinks: nearly conformal profiles, e.g. the flange root of S1002 on the
    gauge corner of UIC60, crossed without creep damping)."""
    fast = max(checks, key=lambda c: abs(c.s_rate[0]))
    rate = abs(float(fast.s_rate[0]))
    if rate < SWEEP_HINT_M_S:
        return ""
    return (f" (the {fast.name} contact point was sweeping along its wheel at {rate:.3g} m/s, relative curvature "
            f"{fast.curvature_per_m:.3g} 1/m: nearly conformal wheel and rail, which one constraint point per "
            "wheel follows only as fast as IDAS converges; creep forces damp such sweeps)")
