"""The wheel circles of the search for gap minima (:mod:`.gap_minima`) of many wheels at once,
and their vertical clearances over the rails.

Each wheel contributes its circles ``s1w`` (a coarse grid over its profile and a fine one near
the followed point); all wheels' circles are concatenated in order of wheel, stored by
component (``pw[0]``, ``pw[1]``: rows, not strided columns), so that every phase of the search
is a few numpy operations for all wheels together and one graph look-up per rail profile.
"""
from __future__ import annotations

import math
import weakref

import numpy as np

#: Fine grid step (m) of the search near the followed point.
FINE_GRID_M = 2e-5
#: Half width (m) of the fine grid around the followed point.
FINE_HALF_WIDTH_M = 1.5e-3

# Coarse grids of each wheel profile and their points (they depend on the profile and the step).
_COARSE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_FINE = np.arange(-FINE_HALF_WIDTH_M, FINE_HALF_WIDTH_M + 1e-9, FINE_GRID_M)


class WheelCircles:
    """The circles of several wheels (``contacts`` at wheelset positions ``qs``, the fine grid
    around ``nears``, None: none), concatenated in order of wheel.

    Attributes
    ----------
    grid : ndarray (N,)
        Wheel profile parameter ``s1w`` of each circle: per wheel ``grid_m`` apart over the
        profile and :data:`FINE_GRID_M` apart within :data:`FINE_HALF_WIDTH_M` of its ``near``
        (the union of both, as ``np.union1d``).
    pw : ndarray (2, N)
        The wheel profile's ``(y, z)`` at ``grid``.
    wid, starts, ends : ndarray
        Each circle's wheel; each wheel's range of circles.
    bottom, sin_yaw : ndarray (wheels,)
        The angle ``s2w`` of each wheel's lowest points (along the track's ``up``) and the sine
        of its yaw to the track.
    """

    def __init__(self, contacts, qs, grid_m: float, nears):
        self.contacts = list(contacts)
        n = len(self.contacts)
        qs = np.array(qs, float).reshape(n, 7)
        self.q3 = qs[:, :3]
        self.rotation = rotations(qs[:, 3:7])
        heads = np.array([ct._head[:3] for ct in self.contacts]).reshape(n, 3)
        self.sign, self.r0, self.half = heads.T
        self.tangent = np.array([ct.frames.kind == "ground" for ct in self.contacts], bool)
        # Tangent track: up is global z and the track tangent global x.
        self.s_axle = self.q3[:, 0].copy()
        self.bottom = np.arctan2(-self.rotation[:, 2, 0], self.rotation[:, 2, 2])
        self.sin_yaw = self.rotation[:, 0, 1].copy()
        for k in np.flatnonzero(~self.tangent):  # curved track: the layout's frame at the axle
            frames, a = self.contacts[k].frames, self.rotation[k]
            self.s_axle[k] = frames.project(self.q3[k][None, :])[0]
            w = a.T @ frames.up(self.s_axle[k:k + 1])
            self.bottom[k] = math.atan2(-w[0], w[2])
            self.sin_yaw[k] = float(a[:, 1] @ np.asarray(frames.track_axes(self.s_axle[k]))[:, 0])
        self._rails = by_profile([ct.rail for ct in self.contacts])
        self._grid(grid_m, nears)
        self._maps()

    def _grid(self, grid_m: float, nears) -> None:
        n, wheel = len(self.contacts), [ct.wheel for ct in self.contacts]
        coarse = [_coarse(w, grid_m) for w in wheel]
        lo, hi = np.array([[w.s_min, w.s_max] for w in wheel]).reshape(n, 2).T
        near = np.array([np.nan if v is None else v for v in nears], float)
        fine = np.minimum(np.maximum(near[:, None] + _FINE, lo[:, None]), hi[:, None])  # np.clip, faster
        fine[np.isnan(fine)] = np.inf  # no fine grid: padding, dropped below
        nf = len(_FINE)
        width = max(len(g) for g, _ in coarse) + nf
        values = np.full((n, width), np.inf)
        points = np.full((2, n, width), np.nan)
        values[:, width - nf:] = fine
        for profile, rows in by_profile(wheel):
            g, pw = coarse[rows[0]]
            values[rows, :len(g)] = g
            points[:, rows, :len(g)] = pw[:, None, :]
            f = fine[rows]
            points[:, rows, width - nf:] = profile.cubic.components(np.where(np.isfinite(f), f, g[0]))
        # One sort for all wheels (stable: the coarse value first of two equal ones).
        order = np.argsort(values, axis=1, kind="stable") + width * np.arange(n)[:, None]
        values = values.ravel()[order]
        keep = np.isfinite(values)
        keep[:, 1:] &= values[:, 1:] != values[:, :-1]
        picked = order[keep]
        self.grid = values[keep]
        self.pw = np.stack((points[0].ravel()[picked], points[1].ravel()[picked]))
        sizes = keep.sum(axis=1)
        self.ends = np.cumsum(sizes)
        self.starts = self.ends - sizes
        self.wid = np.repeat(np.arange(n), sizes)

    def _maps(self) -> None:
        """Tangent track: the affine maps from a wheel point to (chainage, y, z) in the rail
        profile frame (fixed: origin and roll, as ``TangentRailFrames.frames``), the wheel's
        rotation, side and tape-circle offset folded in: of ``[rho sin a, y_w, -rho cos a]``
        (``map``, ``offset``), and at the bottom angle of ``(y_w, z_w)`` (``bottom_map``,
        ``bottom_offset``)."""
        n = len(self.contacts)
        origin, roll = np.zeros((n, 2)), np.zeros(n)
        for k in np.flatnonzero(self.tangent):
            frames = self.contacts[k].frames
            origin[k], roll[k] = frames.origin_m[1:], frames.roll_rad
        cr, sr = np.cos(roll), np.sin(roll)
        local = np.zeros((n, 3, 3))  # A^T, A = R_x(roll); its first row gives the chainage x
        local[:, 0, 0], local[:, 1, 1], local[:, 1, 2], local[:, 2, 1], local[:, 2, 2] = 1.0, cr, sr, -sr, cr
        m = local @ self.rotation
        m[:, :, 1] *= self.sign[:, None]
        self.map = m
        rel = self.q3 - np.column_stack((np.zeros(n), origin))
        self.offset = np.einsum("kij,kj->ki", local, rel) + self.half[:, None] * m[:, :, 1]
        across = np.sin(self.bottom)[:, None] * m[:, :, 0] - np.cos(self.bottom)[:, None] * m[:, :, 2]  # per unit rho
        self.bottom_map = np.stack((m[:, :, 1], across), axis=2)
        self.bottom_offset = self.offset + self.r0[:, None] * across

    def vertical_gap(self, wid, pw, s2w=None, slope: bool = False):
        """Gap along the rail profile's ``z`` of the wheel points ``(pw, s2w)`` (the profile's
        ``(y, z)`` at the circles' ``s1w``, shape (2, n), and the angles, default: each wheel's
        bottom) of wheels ``wid`` (ascending), the rail parameter below each and the chainage
        of its cross-section (as :meth:`.WheelRailContact._vertical_gap`); ``slope``: also the
        rail's ``|dz/dy|`` there (NaN off the rail)."""
        local = np.empty((3, len(wid)))  # chainage, y, z in the rail profile frame
        bounds = np.searchsorted(wid, np.arange(len(self.contacts) + 1))
        if s2w is not None:
            rho = self.r0[wid] + pw[1]
            u = np.stack((rho * np.sin(s2w), pw[0], -rho * np.cos(s2w)))
        for k in np.flatnonzero(bounds[1:] > bounds[:-1]):
            part = slice(bounds[k], bounds[k + 1])
            if self.tangent[k] and s2w is None:
                local[:, part] = self.bottom_map[k] @ pw[:, part] + self.bottom_offset[k][:, None]
            elif self.tangent[k]:
                local[:, part] = self.map[k] @ u[:, part] + self.offset[k][:, None]
            else:
                local[:, part] = self._curved(k, pw[:, part], None if s2w is None else s2w[part])
        s2r, z_r = np.empty(len(wid)), np.empty(len(wid))
        dzdy = np.empty(len(wid)) if slope else None
        for rail, rows in self._rails:
            sel = slice(None) if len(self._rails) == 1 else np.flatnonzero(np.isin(wid, rows))
            found = rail.envelope_at(self.sign[wid[sel]] * local[1, sel], slope=slope)
            s2r[sel], z_r[sel] = found[:2]
            if slope:
                dzdy[sel] = np.abs(found[2])
        gap = local[2] - np.where(np.isfinite(s2r), z_r, np.nan)
        return (gap, s2r, local[0], dzdy) if slope else (gap, s2r, local[0])

    def _curved(self, k, pw, s2w) -> np.ndarray:
        """(chainage, y, z) in the rail profile frame of wheel ``k``'s points on curved track:
        each point's own cross-section."""
        angle = self.bottom[k] if s2w is None else s2w
        rho = self.r0[k] + pw[1]
        u = np.stack([rho * np.sin(angle), self.sign[k] * (self.half[k] + pw[0]), -rho * np.cos(angle)])
        points = (self.q3[k][:, None] + self.rotation[k] @ u).T
        frames = self.contacts[k].frames
        s1r = frames.project(points, self.s_axle[k:k + 1])
        R, A, _, _ = frames.frames(s1r)
        local = np.einsum("nji,nj->in", A, points - R)
        return np.stack((s1r, local[1], local[2]))


def rotations(theta) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of Euler parameters ``theta`` (n, 4) (as
    :func:`.constraint_contact._rotation`, vectorised)."""
    e0, e1, e2, e3 = np.asarray(theta, float).T
    d = 2 * e0**2 - 1
    r = np.empty((len(e0), 3, 3))
    r[:, 0, 0], r[:, 1, 1], r[:, 2, 2] = d + 2 * (e1 * e1), d + 2 * (e2 * e2), d + 2 * (e3 * e3)
    r[:, 0, 1], r[:, 1, 0] = 2 * (e1 * e2 - e0 * e3), 2 * (e2 * e1 + e0 * e3)
    r[:, 0, 2], r[:, 2, 0] = 2 * (e1 * e3 + e0 * e2), 2 * (e3 * e1 - e0 * e2)
    r[:, 1, 2], r[:, 2, 1] = 2 * (e2 * e3 - e0 * e1), 2 * (e3 * e2 + e0 * e1)
    return r


def by_profile(profiles) -> list:
    """``(profile, indices)`` of each distinct profile (by identity) in ``profiles``."""
    groups: dict = {}
    for i, p in enumerate(profiles):
        groups.setdefault(id(p), (p, []))[1].append(i)
    return [(p, np.array(rows)) for p, rows in groups.values()]


def _coarse(wheel, grid_m: float):
    """The coarse grid of a wheel profile and its points ``(2, n)`` (cached)."""
    grids = _COARSE.setdefault(wheel, {})
    if grid_m not in grids:
        lo, hi = wheel.s_min, wheel.s_max
        grid = np.linspace(lo, hi, max(int(math.ceil((hi - lo) / grid_m)), 8) + 1)
        grids[grid_m] = grid, wheel.cubic.components(grid)
    return grids[grid_m]
