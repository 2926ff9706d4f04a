"""All local minima of the wheel/rail gap along the wheel profile (the candidates of a contact
jump, :mod:`symcat.integrate.contact_jumps`)."""
from __future__ import annotations

import math

import numpy as np

from symcat.errors import ParameterError, SolverError

from .constraint_contact import ContactPoint, _rotation


def gap_minima(contact, q, band_m: float = 2e-6, grid_m: float = 2.5e-4, near: float | None = None) -> list:
    """Every local minimum of the gap along the wheel profile, refined by Newton to a contact
    point; lowest first, each point once. Each wheel circle (``s1w`` on a grid of ``grid_m``,
    20 um within 1.5 mm of ``near``) gives its lowest clearance over the rail (along the
    track's ``up``), at the bottom or, by a parabola through three angles, ahead of or behind
    it (a yawed wheelset touches its flange off the axle plane). Circles that are local minima
    within ``band_m`` of the lowest are refined (the band covers the grid's error
    ``kappa h^2 / 8``, 0.8 um at a 10 mm flange-root radius); Newton starts that leave a
    profile are skipped.

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
        grid = np.union1d(grid, np.clip(near + np.arange(-1.5e-3, 1.5e-3 + 1e-9, 2e-5), lo, hi))
    step = 0.05  # rad
    g = [np.nan_to_num(contact._vertical_gap(q, a, bottom + k * step, grid, s_axle)[0], nan=np.inf)
         for k in (-1, 0, 1)]
    with np.errstate(invalid="ignore", divide="ignore"):  # inf off the rail
        curv = g[0] + g[2] - 2 * g[1]
        shift = np.where(curv > 0, 0.5 * step * (g[0] - g[2]) / curv, 0.0)
    s2w = bottom + np.clip(np.nan_to_num(shift), -3 * step, 3 * step)
    gap, s2r, s1r = contact._vertical_gap(q, a, s2w, grid, s_axle)
    gap = np.minimum(np.where(np.isfinite(gap), gap, np.inf), g[1])
    if not np.isfinite(gap).any():
        raise SolverError(f"{contact.side} wheel: no point of the wheel lies above the rail at "
                          f"q={np.array2string(q, precision=5)} (wheelset off the rail)")
    lower = (gap <= np.r_[np.inf, gap[:-1]]) & (gap <= np.r_[gap[1:], np.inf])
    points: list[ContactPoint] = []
    for j in np.flatnonzero(lower & (gap <= gap.min() + band_m)):
        if np.isfinite(s2r[j]):
            r2, r1 = s2r[j], s1r[j]
        else:
            _, r2s, r1s = contact._vertical_gap(q, a, bottom, grid[j : j + 1], s_axle)
            r2, r1 = r2s[0], r1s[0]
        try:
            p = contact._newton(q, np.array([grid[j], s2w[j], r1, r2]), 1e-13, 40)
        except (SolverError, ParameterError):
            continue
        if all(abs(p.s[0] - o.s[0]) > 1e-6 for o in points):
            points.append(p)
    return sorted(points, key=lambda p: p.gap_m)
