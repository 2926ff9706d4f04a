"""All local minima of the wheel/rail gap along the wheel profile (the candidates of a contact
jump, :mod:`symcat.wheelrail_events.contact_jumps`), of one wheel or of many at once.

The search evaluates some 750 wheel circles per wheel; one check of a vehicle looks at every
wheel. :func:`gap_minima_batch` does each of its phases (the circles' bottoms, the two angles of
a yawed circle, the parabola's angle) for all wheels in one vectorised pass
(:class:`.wheel_circles.WheelCircles`: one graph look-up of the rail per rail profile), and
Newton per minimum; :func:`gap_minima` is one wheel of it.
"""
from __future__ import annotations

import numpy as np

from symcat.errors import ParameterError, SolverError

from .contact_point import ContactPoint
from .wheel_circles import FINE_GRID_M, WheelCircles

#: Safety factor on the predicted lowering of a wheel circle's clearance off its bottom point.
OFF_BOTTOM_SAFETY = 4.0
#: Angle step (rad) of the parabola through three points of a yawed circle.
ANGLE_STEP_RAD = 0.05


def gap_minima(contact, q, band_m: float = 2e-6, grid_m: float = 2.5e-4, near: float | None = None,
               known: float | None = None) -> list:
    """Every local minimum of the gap along the wheel profile, refined by Newton to a contact
    point; lowest first, each point once. Each wheel circle (``s1w`` on a grid of ``grid_m``,
    20 um within 1.5 mm of ``near``) gives its lowest clearance over the rail (along the
    track's ``up``), at the bottom or, by a parabola through three angles, ahead of or behind
    it (a yawed wheelset touches its flange off the axle plane). Circles that are local minima
    within ``band_m`` of the lowest are refined (the band covers the grid's error
    ``kappa h^2 / 8``, 0.8 um at a 10 mm flange-root radius); Newton starts that leave a
    profile are skipped. ``known``: the wheel parameter (m) of a point already solved for (the
    followed one): a circle minimum within 1.5 fine grid steps of it is that point, and is not
    refined again (nor returned).

    The three angles are evaluated only where they can matter: off the bottom, a circle of
    radius ``R`` yawed by ``psi`` to the rail reaches lower over a rail of slope ``h'`` by
    about ``R (h' sin psi)^2 / 2`` (the minimum over the angle ``theta`` of ``-R cos theta -
    h(y + R sin theta sin psi)``), so circles whose bottom clearance, less
    :data:`OFF_BOTTOM_SAFETY` times that, lies above the band are settled by the bottom alone
    (most of them: on tangent track yaw is milliradians).

    Raises
    ------
    SolverError
        If no wheel circle lies above the rail.
    ParameterError
        If the axle centre lies off a curved track's defined length.
    """
    found = gap_minima_batch([contact], [q], band_m, grid_m, [near], [known])[0]
    if isinstance(found, Exception):
        raise found
    return found


def gap_minima_batch(contacts, qs, band_m: float = 2e-6, grid_m: float = 2.5e-4, nears=None, knowns=None) -> list:
    """:func:`gap_minima` of several wheels (``contacts`` at wheelset positions ``qs``, with
    ``nears`` and ``knowns`` per wheel, None by default), each phase of the search done for all
    of them at once: the same points as wheel by wheel (to rounding of the grid's clearances).

    Returns
    -------
    list
        Per wheel, its points (lowest first), or the :class:`SolverError` or
        :class:`ParameterError` that :func:`gap_minima` would raise for it.
    """
    n = len(contacts)
    nears = [None] * n if nears is None else list(nears)
    knowns = [None] * n if knowns is None else list(knowns)
    out: list = [None] * n
    qs = [np.asarray(q, float) for q in qs]
    for j, contact in enumerate(contacts):
        if contact.frames.kind != "ground":  # tangent track has no ends
            try:
                contact.frames.check(contact.frames.project(qs[j][None, :3]))
            except ParameterError as err:
                out[j] = err
    live = [j for j in range(n) if out[j] is None]
    if not live:
        return out
    c = WheelCircles([contacts[j] for j in live], [qs[j] for j in live], grid_m, [nears[j] for j in live])
    gap, s2r, s1r, slope = c.vertical_gap(c.wid, c.pw, slope=True)
    gap = np.where(np.isfinite(gap), gap, np.inf)
    low = np.minimum.reduceat(gap, c.starts)
    for j, g in zip(live, low):
        if not np.isfinite(g):
            out[j] = SolverError(f"{contacts[j].side} wheel: no point of the wheel lies above the rail at "
                                 f"q={np.array2string(qs[j], precision=5)} (wheelset off the rail)")
    s2w = c.bottom[c.wid]
    candidate = _off_bottom_candidates(c, gap, slope, low, band_m)
    if candidate.size:
        _yawed_circles(c, candidate, gap, s2r, s1r, s2w)
    # Local minima of each wheel's clearances within the band of its (updated) lowest.
    prev, nxt = np.concatenate(([np.inf], gap[:-1])), np.concatenate((gap[1:], [np.inf]))
    prev[c.starts], nxt[c.ends - 1] = np.inf, np.inf
    low = np.minimum.reduceat(gap, c.starts)
    picked = np.flatnonzero((gap <= prev) & (gap <= nxt) & (gap <= low[c.wid] + band_m) & np.isfinite(low)[c.wid])
    starts = np.searchsorted(picked, c.starts)
    for k, j in enumerate(live):
        if out[j] is not None:
            continue
        points: list[ContactPoint] = []
        for i in picked[starts[k]:starts[k + 1] if k + 1 < len(live) else None]:
            if knowns[j] is not None and abs(c.grid[i] - knowns[j]) <= 1.5 * FINE_GRID_M:
                continue
            try:
                p = contacts[j]._newton(qs[j], np.array([c.grid[i], s2w[i], s1r[i], s2r[i]]), 1e-13, 40)
            except (SolverError, ParameterError):
                continue
            if all(abs(p.s[0] - o.s[0]) > 1e-6 for o in points):
                points.append(p)
        out[j] = sorted(points, key=lambda p: p.gap_m)
    return out


def _off_bottom_candidates(c, gap, slope, low, band_m) -> np.ndarray:
    """Circles of yawed wheels whose lowest clearance off the bottom may lie in the band: the
    bottom's less :data:`OFF_BOTTOM_SAFETY` times the predicted lowering (see
    :func:`gap_minima`; infinite where the rail slope is unknown: off the rail)."""
    sin_yaw = c.sin_yaw[c.wid]
    radius = c.r0[c.wid] + c.pw[1]
    with np.errstate(invalid="ignore"):  # inf * 0 and inf - inf off the rail: not a candidate
        unknown = np.where(sin_yaw != 0.0, np.inf, 0.0)
        lowering = np.where(np.isfinite(slope), 0.5 * radius * (slope * sin_yaw) ** 2, unknown)
        candidate = gap - OFF_BOTTOM_SAFETY * lowering <= low[c.wid] + band_m
    return np.flatnonzero(candidate & np.isfinite(gap) & (sin_yaw != 0.0))


def _yawed_circles(c, idx, gap, s2r, s1r, s2w) -> None:
    """Lowest clearance of the circles ``idx`` (ascending) off their bottoms: a parabola through
    the bottom and :data:`ANGLE_STEP_RAD` either side gives the angle, kept where lower (in
    place)."""
    step = ANGLE_STEP_RAD
    wid, pw = c.wid[idx], c.pw[:, idx]
    bottom = c.bottom[wid]
    # Both angles of every circle in one evaluation (its fixed cost exceeds that of the circles),
    # interleaved so that the circles stay in order of their wheels.
    angles = (bottom[:, None] + [-step, step]).ravel()
    g = c.vertical_gap(np.repeat(wid, 2), np.repeat(pw, 2, axis=1), angles)[0]
    g = np.nan_to_num(g, nan=np.inf).reshape(-1, 2).T
    with np.errstate(invalid="ignore", divide="ignore"):  # inf off the rail
        curv = g[0] + g[1] - 2 * gap[idx]
        shift = np.where(curv > 0, 0.5 * step * (g[0] - g[1]) / curv, 0.0)
    s2w_sub = bottom + np.clip(np.nan_to_num(shift), -3 * step, 3 * step)
    moved = np.flatnonzero(s2w_sub != bottom)
    if moved.size:
        gm, r2m, r1m = c.vertical_gap(wid[moved], pw[:, moved], s2w_sub[moved])
        better = np.isfinite(gm) & (gm < gap[idx[moved]])
        i = idx[moved][better]
        gap[i], s2r[i], s1r[i], s2w[i] = gm[better], r2m[better], r1m[better], s2w_sub[moved][better]
