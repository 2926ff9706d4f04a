"""Contact-point jumps of wheel/rail constraint contacts, located between integrator calls.

A constraint contact follows one stationary point of the wheel/rail gap continuously. On worn or
nearly conformal profiles (S1002 on UIC60, EN 15302 wheel A on rail A) the gap along the wheel
has several local minima a few millimetres apart and within fractions of a micrometre of each
other: the lowest point jumps when another minimum sinks below the followed one. Followed any
further, the old point keeps the wheel up while the new one penetrates, and soon after it meets
a gap maximum and vanishes (a fold: the relative curvature ``kappa`` of wheel and rail across
the profile, the reduced tangency Jacobian, goes through zero, ``C_s`` turns singular and the
contact point would have to move infinitely fast). IDAS cannot pass a fold: it stalls
(IDA_TOO_MUCH_WORK) or its Newton iterates leave the profiles (IDA_CONV_FAIL, inf/NaN in the
Jacobian).

So the driver (:mod:`symcat.integrate.event_stepping`, with :mod:`.contact_events`) integrates in short calls and, after each, looks at
every wheel from scratch (:func:`symcat.wheelrail.gap_minima.gap_minima_batch`, all wheels at
once). The contact jumps to the lowest other minimum that is *formed* (relative curvature at
least :data:`FOLD_CURVATURE_PER_M`; a newborn minimum has none and may vanish again) once that
lies :data:`JUMP_TOLERANCE_M` below the followed point (the hysteresis against chattering
between twin minima), or to any lower one when the followed point nears its fold (``kappa``
below that) or IDAS has failed. The surface parameters move there and the velocities are
projected onto the constraints (the minimum-norm change: a plastic impact at the new point)
before IDAS restarts; the positions stay as they are.

A call lasts at most until (a) the followed point has travelled :data:`TRAVEL_M` along the wheel
profile, (b) about half the time until its relative curvature has halved (predicted from the
profiles' curvatures along its path, so that the calls shorten geometrically toward a fold),
or (c) the lowest formed rival is predicted :data:`JUMP_TOLERANCE_M` below it. On rails with
kinks (cant ramps) the travel is shorter (:func:`travel_limit`). The rates are exact:
``s_dot = -C_Ts^-1 C_Tq q_dot``, and the gap of a stationary point changes at
``C_q[gap] q_dot`` (its derivative in ``s`` vanishes there).

The other minima are searched for with the wheelset moved onto the rail at the followed point
(:func:`_minima`: micrometres of constraint drift would hide those of a flat valley). A wheel
that would lift off or run off its rail ends the run with an error (:func:`lost_contact`), as
does, on curved track, a contact point that has left the layout's defined length (the kernels
would extrapolate the end piece).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..assembly.wheelrail import GAP_ROW, TANGENCY_ROWS
from ..dae.formulation import normal_forces_numeric
from ..dae.initial import consistent_state
from ..errors import ParameterError, SolverError
from ..integrate.event_stepping import MIN_SPAN_S
from ..integrate.failure import physical_coordinates, restart_point, split_state
from ..wheelrail.contact_point import solve_small
from ..wheelrail.gap_minima import gap_minima_batch

#: A minimum this much below the followed point (m) triggers a jump.
JUMP_TOLERANCE_M = 1e-9
#: Horizon (s) of an early jump: a rival predicted to sink below the followed point within it
#: is jumped to at once, if it lies no higher than the caller's ``early_m`` (see
#: :meth:`ContactCheck.target`).
EARLY_JUMP_S = 1e-4
#: Stationary points closer than this along the wheel profile (m) are the same point.
SAME_POINT_M = 1e-6
#: Farthest (m) the followed point's own stationary point is looked for from its parameters.
OWN_RADIUS_M = 1e-5
#: Relative curvature (1/m) below which the followed point is abandoned for any lower minimum
#: (a relative radius above 20 m: a Hertz ellipse as wide as the rail head).
FOLD_CURVATURE_PER_M = 0.05
#: Largest travel of a followed contact point along the wheel profile between two checks (m).
TRAVEL_M = 2e-3
#: A refused jump target (see :class:`.contact_events.ContactEvents`) covers the rivals this
#: close to it along the wheel profile (m): it travels less in a refusal's hold.
REFUSED_RADIUS_M = 1e-4
#: Largest travel (m) on rails with kinks (cant ramps' ends, crossed as impacts: the tangency
#: conditions step with the rail's slope, and the contact point reaches the stationary point
#: past the crease by jumps, :func:`jump_contacts`, which longer calls find too late: with
#: :data:`TRAVEL_M`, the index-1 wheelset of the cant-ramp test drifts 4 mm off its rails).
KINK_TRAVEL_M = 5e-4
#: Gap (m) of a jump target above which a GGL state is projected onto the position constraints.
GGL_PROJECT_GAP_M = 1e-8

_TANGENCY = np.array(TANGENCY_ROWS)
_HELD = np.array([0, 1, 4])  # rows held in relative_curvature (all but the wheel's tangency and the gap)


@dataclass
class Rival:
    """Another local minimum of a wheel's gap: the contact point, its relative curvature (1/m)
    and the rate of its gap (m/s)."""

    point: object
    curvature_per_m: float
    gap_rate_m_s: float

    @property
    def formed(self) -> bool:
        """Whether the minimum is pronounced enough to be followed (not about to vanish: a
        newborn minimum appears with zero curvature)."""
        return self.curvature_per_m >= FOLD_CURVATURE_PER_M


@dataclass
class ContactCheck:
    """One wheel's contact at one state.

    Attributes
    ----------
    name : str
    gap_m, gap_rate_m_s : float
        Normal gap of the followed point and its rate.
    curvature_per_m : float
        Relative curvature of wheel and rail across the profile at the followed point (> 0 at a
        gap minimum, 0 at a fold), see :func:`relative_curvature`.
    fold_in_s : float
        Predicted time (s) until that curvature has halved (``inf``: not within the travel
        :data:`TRAVEL_M`), see :func:`halving_time`.
    s_rate : ndarray (4,)
        Rates of the surface parameters (m/s, rad/s, m/s, m/s).
    rivals : list of Rival
        The other local minima of the gap, lowest first: all but the followed point's own (see
        :func:`_own_point`). In a flat valley of nearly conformal profiles they may be tens of
        micrometres away.
    travel_m : float
        Largest travel (m) along the wheel profile in the next call: :data:`TRAVEL_M`, or
        :data:`KINK_TRAVEL_M` on rails with kinks (:func:`travel_limit`).
    """

    name: str
    gap_m: float
    gap_rate_m_s: float
    curvature_per_m: float
    fold_in_s: float
    s_rate: np.ndarray
    rivals: list = field(default_factory=list)
    travel_m: float = TRAVEL_M

    def margin_m(self, rival: Rival) -> float:
        """Rival's gap minus the followed point's (m)."""
        return rival.point.gap_m - self.gap_m

    def target(self, relaxed: bool = False, refused: float | None = None, early_m: float = 0.0) -> Rival | None:
        """The rival to jump to, if any: the lowest formed one once it lies
        :data:`JUMP_TOLERANCE_M` below the followed point; or, when the followed point nears its
        fold, the lowest one not higher than that tolerance, formed ones first (in a flat valley
        of nearly conformal profiles the minima lie within a fraction of a nanometre, and the
        followed one is about to vanish); or, ``relaxed`` (IDAS has failed on the followed
        point), the lowest one. ``refused``: the wheel parameter (m) of a point IDAS could not
        integrate from just before; rivals within :data:`REFUSED_RADIUS_M` of it are not
        targets unless ``relaxed``.

        ``early_m`` (m): a formed rival at most this high that is predicted to sink below within
        :data:`EARLY_JUMP_S` is a target now. On a symmetric vehicle the wheels of one side
        reach their jumps microseconds apart: one by one, each jump costs an integrator call,
        a contact check and a projection; early, they go together, and the call that would close
        in on the crossing is spared. The wheelset rises by the rival's height at most (a
        fraction of the position tolerance, set by the caller)."""
        rivals = self.rivals
        if refused is not None and not relaxed:
            rivals = [r for r in rivals if abs(r.point.s[0] - refused) > REFUSED_RADIUS_M]
        formed = [r for r in rivals if r.formed]
        if formed:
            margin = self.margin_m(formed[0])
            closing = self.gap_rate_m_s - formed[0].gap_rate_m_s
            if margin < -JUMP_TOLERANCE_M or (margin <= early_m and margin - closing * EARLY_JUMP_S < -JUMP_TOLERANCE_M):
                return formed[0]
        if relaxed:
            return rivals[0] if rivals else None
        if self.curvature_per_m < FOLD_CURVATURE_PER_M:
            level = [r for r in rivals if self.margin_m(r) < JUMP_TOLERANCE_M]
            level.sort(key=lambda r: not r.formed)
            return level[0] if level else None
        return None

    def span_s(self) -> float:
        """Longest next integrator call (s) for this contact: until the followed point has
        travelled :attr:`travel_m` along the wheel; half the predicted time until its relative
        curvature has halved (the contact point speeds up toward a fold, where ``kappa`` goes as
        ``sqrt(t_fold - t)``: the linear prediction would reach the fold itself); until the
        lowest formed rival is predicted :data:`JUMP_TOLERANCE_M` below it (linearly, from the
        rates). At least :data:`MIN_SPAN_S`."""
        spans = [math.inf, 0.5 * self.fold_in_s]
        if abs(self.s_rate[0]) > 0:
            spans.append(self.travel_m / abs(self.s_rate[0]))
        formed = [r for r in self.rivals if r.formed]
        if formed and formed[0].gap_rate_m_s < self.gap_rate_m_s:
            closing = self.gap_rate_m_s - formed[0].gap_rate_m_s
            spans.append((self.margin_m(formed[0]) + 2 * JUMP_TOLERANCE_M) / closing)
        return max(min(spans), MIN_SPAN_S)

    def event_s(self) -> float:
        """Predicted time (s) until the lowest formed rival lies :data:`JUMP_TOLERANCE_M` below
        the followed point (the rival part of :meth:`span_s`; ``inf`` if none closes in). A
        call ends there exactly rather than on a binary fraction of the driver's span (see
        :meth:`symcat.integrate.event_stepping.EventStepper.advance`)."""
        formed = [r for r in self.rivals if r.formed]
        if formed and formed[0].gap_rate_m_s < self.gap_rate_m_s:
            closing = self.gap_rate_m_s - formed[0].gap_rate_m_s
            return max((self.margin_m(formed[0]) + 2 * JUMP_TOLERANCE_M) / closing, MIN_SPAN_S)
        return math.inf


def relative_curvature(contact, q, s, kernels=None) -> float:
    """Relative curvature (1/m) of wheel and rail across the profile at surface parameters ``s``:
    the derivative of the wheel-profile tangency row ``t1w . n^r`` along the wheel profile's arc
    length with the other three conditions held (a Schur complement of ``C_s``). Equal to
    ``-(k_wheel + k_rail)`` of the profiles' curvatures (:meth:`Profile.curvature`) on tangent
    track; positive at a minimum of the gap, zero where the point meets a maximum and vanishes.
    ``kernels``: :meth:`evaluate`'s at ``(q, s)``, if at hand."""
    k = contact.evaluate(q, s, clip=True) if kernels is None else kernels
    t = k.C_s
    reduced = t[3, 0] - t[3, 1:] @ solve_small(t[_HELD][:, 1:], t[_HELD, 0])
    return float(reduced / math.hypot(*contact.wheel.cubic.at(float(s[0]), 1)))


def halving_time(contact, s, s_rate, kappa: float, samples: int = 64) -> float:
    """Time (s) until the relative curvature of a contact point moving at ``s_rate`` has halved
    (or dropped below :data:`FOLD_CURVATURE_PER_M`), predicted over a travel of :data:`TRAVEL_M`
    from the profiles' curvatures along the linearly extrapolated path (``-(k_wheel + k_rail)``,
    as :func:`relative_curvature` on tangent track): measured profiles have their curvature
    changing over fractions of a millimetre, which a rate at the point cannot see. ``inf`` if
    it does not within that travel."""
    return halving_times([contact], [s], [s_rate], [kappa], samples)[0]


def halving_times(contacts, ss, s_rates, kappas, samples: int = 64) -> list[float]:
    """:func:`halving_time` of several contact points (``contacts`` at surface parameters ``ss``
    moving at ``s_rates``, relative curvatures ``kappas``), one curvature evaluation per
    profile for all."""
    out = [math.inf] * len(contacts)
    live = [j for j, (rate, kappa) in enumerate(zip(s_rates, kappas)) if kappa > 0 and rate[0] != 0]
    if not live:
        return out
    s = np.array([ss[j] for j in live], float)
    rate = np.array([s_rates[j] for j in live], float)
    kappa = np.array([kappas[j] for j in live], float)
    wheels, rails = [contacts[j].wheel for j in live], [contacts[j].rail for j in live]
    span = TRAVEL_M / np.abs(rate[:, 0])
    tau = np.arange(samples + 1) * (span / samples)[:, None]  # np.linspace(0, span, samples + 1)
    tau[:, -1] = span
    tau = tau[:, 1:]
    # The point's own curvature first, then the path's.
    k_w = _curvatures(wheels, s[:, :1], s[:, :1] + rate[:, :1] * tau)
    k_r = _curvatures(rails, s[:, 3:], s[:, 3:] + rate[:, 3:] * tau)
    path = -(k_w[:, 1:] + k_r[:, 1:])
    # The path's curvatures are relative to the point's own (3D effects: roll, yaw).
    path += (kappa + (k_w[:, 0] + k_r[:, 0]))[:, None]
    low = path <= np.maximum(0.5 * kappa, FOLD_CURVATURE_PER_M)[:, None]
    first = np.argmax(low, axis=1)
    for row, j in enumerate(live):
        if low[row, first[row]]:
            out[j] = float(tau[row, first[row]])
    return out


def _curvatures(profiles, own, path) -> np.ndarray:
    """Curvatures of ``profiles`` (one per row) at ``[own, path]``, ``path`` clipped to each
    profile: one evaluation per distinct profile."""
    lo, hi = np.array([[p.s_min, p.s_max] for p in profiles]).T
    s = np.concatenate((own, np.minimum(np.maximum(path, lo[:, None]), hi[:, None])), axis=1)  # np.clip, faster
    if all(p is profiles[0] for p in profiles):
        return profiles[0].cubic.curvature(s)
    return np.array([p.cubic.curvature(row) for p, row in zip(profiles, s)])


def travel_limit(frames) -> float:
    """Largest travel (m) of a contact point along the wheel profile in one call:
    :data:`KINK_TRAVEL_M` if its rail has kinks (``frames.kinks_m``), else :data:`TRAVEL_M`."""
    return KINK_TRAVEL_M if len(getattr(frames, "kinks_m", ())) else TRAVEL_M


def check_contacts(form, x, z) -> list[ContactCheck]:
    """:class:`ContactCheck` of every wheel/rail contact at the state ``(x, z)``."""
    model = form.model
    parts = split_state(form, x, z)
    q_full, v_full = physical_coordinates(form, parts)
    out, wheels = [], []
    for e in model.wheelrail:
        q, q_dot = q_full[e.rows], v_full[e.rows]
        s = parts["s"][e.s_index : e.s_index + 4]
        k = e.contact.evaluate(q, s, clip=True)
        # The rates and the followed point's first Newton step (_own_point): one factorization.
        both = solve_small(k.C_s[_TANGENCY], np.column_stack((k.C_q[_TANGENCY] @ q_dot, k.c[_TANGENCY])))
        s_rate = -both[:, 0]
        gap = e.contact.gap(q, s, kernels=k)
        kappa = relative_curvature(e.contact, q, s, k)
        out.append(ContactCheck(e.joint.name, gap, float(k.C_q[GAP_ROW] @ q_dot + k.C_s[GAP_ROW] @ s_rate), kappa,
                                math.inf, s_rate, travel_m=travel_limit(e.contact.frames)))
        wheels.append((e.contact, q, q_dot, s, gap * k.C_q[GAP_ROW, :3], _own_point(e.contact, q, s, abs(both[0, 1]))))
    contacts = [w[0] for w in wheels]
    for check, fold in zip(out, halving_times(contacts, [w[3] for w in wheels], [c.s_rate for c in out],
                                               [c.curvature_per_m for c in out])):
        check.fold_in_s = fold
    # The other minima of all wheels in one search (its phases vectorised over the wheels).
    found = _minima(contacts, *([w[i] for w in wheels] for i in (1, 3, 4, 5))) if wheels else []
    for check, (contact, q, q_dot, s, _, own), points in zip(out, wheels, found):
        for p in points:
            if own is None or abs(p.s[0] - own) > SAME_POINT_M:
                k_p = p.kernels  # Newton's last evaluation, at p.s
                check.rivals.append(Rival(p, relative_curvature(contact, q, p.s, k_p), float(k_p.C_q[GAP_ROW] @ q_dot)))
    return out


def _minima(contacts, qs, ss, offsets, owns) -> list[list]:
    """Local minima of the gap of each wheel (``contacts`` at ``qs``; lowest first), searched
    for with the wheelset moved by ``-offset`` (the followed point's gap along the rail normal)
    onto the rail: the vertical clearances of the search differ from normal gaps by ``gap *
    tan(angle) * d(angle)``, which with micrometres of constraint drift shifts or erases the
    minima of a flat valley (tenths of a millimetre apart, nanometres deep). Each is then
    refined at ``q`` itself. ``owns``: the followed points' own wheel parameters
    (:func:`_own_point`, at ``ss``), already solved for: the search's minimum at one is neither
    refined nor returned. A wheel off its rail has none."""
    touch = []
    for q, offset in zip(qs, offsets):
        q_touch = np.array(q, float)
        q_touch[:3] -= offset
        touch.append(q_touch)
    found = gap_minima_batch(contacts, touch, nears=[s[0] for s in ss], knowns=list(owns))
    out = []
    for contact, q, points in zip(contacts, qs, found):
        if isinstance(points, SolverError):
            out.append([])
            continue
        if isinstance(points, Exception):
            raise points
        refined = []
        for p in points:
            try:
                p = contact.solve(q, p.s, local=True)
            except (SolverError, ParameterError):
                continue
            if all(abs(p.s[0] - o.s[0]) > SAME_POINT_M for o in refined):
                refined.append(p)
        out.append(sorted(refined, key=lambda p: p.gap_m))
    return out


def _own_point(contact, q, s, predicted: float) -> float | None:
    """Wheel parameter (m) of the followed point's own exact stationary point: the followed
    parameters ``s`` are off it by the constraint drift (over the relative curvature). Newton
    from ``s`` finds it, unless it has vanished (past a fold): then Newton goes farther than
    twice its first step predicts (``predicted``, m, along the wheel; perhaps to the next
    minimum), and there is none (None). Near a fold that prediction is large: at most
    :data:`OWN_RADIUS_M` (beyond, the own point shows up as a rival, and a jump there only
    corrects the parameters' drift)."""
    start = np.array(s, float)
    start[1] = math.remainder(start[1], 2 * math.pi)
    try:
        own = contact.solve(q, start, local=True).s[0]
    except (SolverError, ParameterError):
        return None
    return own if abs(own - s[0]) <= min(2 * predicted + SAME_POINT_M, OWN_RADIUS_M) else None


def lost_contact(form, x, z, checks) -> str | None:
    """Why the constraint contacts stop describing the wheelset at the state ``(x, z)``, if they
    do: a contact point off its profiles (the wheel ran off its rail or over its flange; the
    kernels would extrapolate the end pieces) or, for a contact in the global form (eq. 21, no
    gap row to release: rail-frame contacts open instead, :mod:`.contact_switching`), a negative
    normal force. Not the latter near a fold (``checks``: those of the state): there the normal
    force of the vanishing point grows without bound either way, and the point is about to jump."""
    model = form.model
    parts = split_state(form, x, z)
    weights = np.asarray(form.normal_direction_function()(parts["q"], parts["s"])).ravel()
    normal = normal_forces_numeric(weights, np.asarray(parts["lambda"]), form.normal_force_rows())
    releasable = form.releasable()  # these open instead (see contact_switching)
    for k, (e, n, check) in enumerate(zip(model.wheelrail, normal, checks)):
        s = parts["s"][e.s_index : e.s_index + 4]
        try:
            e.contact.frames.check(s[2])
        except ParameterError as err:
            return f"the {e.joint.name} contact point left the track: {err}"
        for label, value, prof in (("wheel", s[0], e.contact.wheel), ("rail", s[3], e.contact.rail)):
            if not prof.s_min <= value <= prof.s_max:
                return (f"the {e.joint.name} contact point left the {label} profile {prof.name!r} (at "
                        f"{value * 1e3:.2f} mm of {prof.s_min * 1e3:.2f} to {prof.s_max * 1e3:.2f} mm): the wheel has run "
                        "off its rail")
        if n < 0 and check.curvature_per_m >= FOLD_CURVATURE_PER_M and k not in releasable:
            return (f"{e.joint.name} lifts off its rail (normal force {n / 1e3:.3g} kN): a contact in the global "
                    "form (eq. 21) cannot separate; use form='railframe'")
    return None


def jump_contacts(form, x, z, t: float, checks=None, relaxed: bool = False, open_rows=(), refused=None,
                  early_m: float = 0.0):
    """``(x, z, names)``: the state after moving every contact with a :meth:`ContactCheck.target`
    there (``names`` lists them; unchanged state and an empty list if none). ``checks`` are those
    of :func:`check_contacts` at this state (computed if not given); ``refused``: contact name ->
    wheel parameter (m) of a target to skip; ``early_m``: height (m) up to which a rival about
    to sink below is a target (:meth:`ContactCheck.target`)."""
    refused = refused or {}
    model = form.model
    if not model.wheelrail:
        return x, z, []
    checks = check_contacts(form, x, z) if checks is None else checks
    parts = split_state(form, x, z)
    s = parts["s"].copy()
    jumped = []
    deepest = 0.0
    for e, c in zip(model.wheelrail, checks):
        rival = c.target(relaxed, refused.get(e.joint.name), early_m)
        if rival is None:
            continue
        deepest = max(deepest, abs(rival.point.gap_m))
        i = e.s_index
        new = rival.point.s.copy()
        # Keep the wheel angle continuous (it counts revolutions).
        new[1] = s[i + 1] + math.remainder(new[1] - s[i + 1], 2 * math.pi)
        s[i : i + 4] = new
        jumped.append(e.joint.name)
    if not jumped:
        return x, z, []
    start = restart_point(form, parts, s)
    # Positions stay: the new point is an exact stationary point of the gap at them, and its
    # gap differs from the old one's by the margin only (both carry the same constraint drift,
    # which the Baumgarte terms remove). Projecting them onto C = 0 would shift and roll the
    # wheelset by that drift (micrometres at speed), enough to reorder minima nanometres apart.
    # GGL has no Baumgarte terms: IDAS's first Newton iteration must close the gap within a
    # step of a microsecond, and fails on a micrometre (a rival that deepened fast, e.g. a
    # loaded wheelset sliding to the centre of S1002): such a state is projected.
    project = form.index == "ggl" and deepest > GGL_PROJECT_GAP_M
    x_new, z_new = consistent_state(form, t, start=start, positions=project, open_rows=open_rows)
    return x_new, z_new, jumped
