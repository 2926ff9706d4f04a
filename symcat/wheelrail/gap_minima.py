"""All local minima of the wheel/rail gap along the wheel profile (the candidates of a contact
jump, :mod:`symcat.integrate.contact_jumps`)."""
from __future__ import annotations

import math

import numpy as np

from symcat.errors import ParameterError, SolverError

from .constraint_contact import ContactPoint, _rotation


#: Safety factor on the predicted lowering of a wheel circle's clearance off its bottom point.
OFF_BOTTOM_SAFETY = 4.0
#: Fine grid step (m) of the search near the followed point.
FINE_GRID_M = 2e-5


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
    """
    q = np.asarray(q, float)
    a = _rotation(q[3:7])
    s_axle = contact.frames.project(q[None, :3])
    contact.frames.check(s_axle)
    w = a.T @ contact.frames.up(s_axle)
    bottom = math.atan2(-w[0], w[2])
    lo, hi = contact.wheel.s_min, contact.wheel.s_max
    grid = np.linspace(lo, hi, max(int(math.ceil((hi - lo) / grid_m)), 8) + 1)
    if near is not None:
        grid = np.union1d(grid, np.clip(near + np.arange(-1.5e-3, 1.5e-3 + 1e-9, FINE_GRID_M), lo, hi))
    pw = contact.wheel.position(grid)
    gap, s2r, s1r = contact._vertical_gap(q, a, bottom, grid, s_axle, pw)
    gap = np.where(np.isfinite(gap), gap, np.inf)
    if not np.isfinite(gap).any():
        raise SolverError(f"{contact.side} wheel: no point of the wheel lies above the rail at "
                          f"q={np.array2string(q, precision=5)} (wheelset off the rail)")
    # Off-bottom lowering bound per circle (inf where the rail slope is unknown: off the rail).
    tangent = np.asarray(contact.frames.track_axes(float(s_axle[0])))[:, 0]
    sin_yaw = float(a[:, 1] @ tangent)
    slope = np.full(len(grid), np.inf)
    on = np.isfinite(s2r)
    d = contact.rail.derivative(s2r[on])
    with np.errstate(divide="ignore", invalid="ignore"):
        slope[on] = np.abs(d[:, 1] / d[:, 0])
    radius = contact._head[1] + pw[:, 1]
    finite = np.isfinite(slope)
    lowering = np.full(len(grid), np.inf if sin_yaw != 0.0 else 0.0)
    lowering[finite] = 0.5 * radius[finite] * (slope[finite] * sin_yaw) ** 2
    with np.errstate(invalid="ignore"):  # inf - inf off the rail: not a candidate
        candidate = gap - OFF_BOTTOM_SAFETY * lowering <= gap.min() + band_m
    candidate &= np.isfinite(gap)
    s2w = np.full(len(grid), bottom)
    if sin_yaw != 0.0 and candidate.any():
        step = 0.05  # rad
        sub, pw_sub = grid[candidate], pw[candidate]
        # Both angles in one evaluation (its fixed cost exceeds that of the few circles).
        angles = bottom + step * np.repeat([-1.0, 1.0], sub.size)
        g = contact._vertical_gap(q, a, angles, np.tile(sub, 2), s_axle, np.tile(pw_sub, (2, 1)))[0]
        g = np.nan_to_num(g, nan=np.inf).reshape(2, -1)
        with np.errstate(invalid="ignore", divide="ignore"):  # inf off the rail
            curv = g[0] + g[1] - 2 * gap[candidate]
            shift = np.where(curv > 0, 0.5 * step * (g[0] - g[1]) / curv, 0.0)
        s2w_sub = bottom + np.clip(np.nan_to_num(shift), -3 * step, 3 * step)
        moved = s2w_sub != bottom
        if moved.any():
            gm, r2m, r1m = contact._vertical_gap(q, a, s2w_sub[moved], sub[moved], s_axle, pw_sub[moved])
            idx = np.flatnonzero(candidate)[moved]
            better = np.isfinite(gm) & (gm < gap[idx])
            i = idx[better]
            gap[i], s2r[i], s1r[i], s2w[i] = gm[better], r2m[better], r1m[better], s2w_sub[moved][better]
    lower = (gap <= np.concatenate(([np.inf], gap[:-1]))) & (gap <= np.concatenate((gap[1:], [np.inf])))
    points: list[ContactPoint] = []
    for j in np.flatnonzero(lower & (gap <= gap.min() + band_m)):
        if known is not None and abs(grid[j] - known) <= 1.5 * FINE_GRID_M:
            continue
        try:
            p = contact._newton(q, np.array([grid[j], s2w[j], s1r[j], s2r[j]]), 1e-13, 40)
        except (SolverError, ParameterError):
            continue
        if all(abs(p.s[0] - o.s[0]) > 1e-6 for o in points):
            points.append(p)
    return sorted(points, key=lambda p: p.gap_m)
