"""The minimum-gap contact search of one wheel on its rail (used by :mod:`.geometry`).

The vertical gap ``Z_wheel - Z_rail`` is evaluated along the wheel profile on a grid of the
wheel parameter against a tabulated rail (coarse), the best two local minima at least 1 mm apart
are refined on the exact splines (eight rounds, each narrowing a nine-point bracket four-fold),
and a Newton step or two on the tangency condition ``d(gap)/ds = 0`` finishes: the gap's minimum
is flat, so the grid alone locates it only to about ``sqrt(round-off / relative curvature)``
(nanometres), the slopes to round-off.
"""
from __future__ import annotations

import math

import numpy as np

from .profiles import Profile


class WheelOnRail:
    """One wheel over its rail, placed in the track frame (``sign`` +1 left, -1 right; the rail
    profile's origin at ``Y = sign * rail_origin``), and the search for the smallest vertical gap.
    All methods are vectorised over shifts (and roll angles)."""

    def __init__(self, name: str, sign: float, wheel: Profile, rail: Profile, rail_origin: float,
                 half_tape_m: float, nominal_radius_m: float, grid_m: float):
        self.name = name
        self.sign = sign
        self.wheel = wheel
        self.rail = rail
        self.origin = rail_origin
        self.half_tape = half_tape_m
        self.r0 = nominal_radius_m
        n = max(int(math.ceil((wheel.s_max - wheel.s_min) / grid_m)), 4) + 1
        self.s_grid = np.linspace(wheel.s_min, wheel.s_max, n)
        self.h = self.s_grid[1] - self.s_grid[0]
        # Flange tip: the largest radius (for a flangeless tread, its inner end).
        self.tip_y = float(wheel.position(self.s_grid)[np.argmax(wheel.position(self.s_grid)[:, 1]), 0])
        # Rail as a fine table (0.02 mm) for the coarse search only; refinement uses the spline.
        ry0, ry1 = rail.y_range
        self.rail_range = (ry0, ry1)
        self.y_tab = np.linspace(ry0, ry1, max(int((ry1 - ry0) / 2e-5), 10) + 1)
        self.z_tab = rail.z_at(self.y_tab)

    def wheel_points(self, s, shift, phi):
        """Track coordinates (Y, Z) of wheel parameter ``s`` for axle height 0, plus the
        wheelset-frame coordinates (rotated) needed for the roll derivative."""
        p = self.wheel.position(s)
        yw = self.sign * (self.half_tape + p[..., 0])
        zw = -(self.r0 + p[..., 1])
        c, sn = np.cos(phi), np.sin(phi)
        yrel = c * yw - sn * zw
        zrel = sn * yw + c * zw
        return shift + yrel, zrel, yrel

    def gap(self, s, shift, phi, exact: bool):
        Y, Z, _ = self.wheel_points(s, shift, phi)
        yr = self.sign * Y - self.origin
        if exact:
            zr = self.rail.z_at(yr)
        else:
            zr = np.interp(yr, self.y_tab, self.z_tab, left=np.nan, right=np.nan)
        g = Z - zr
        return np.where(np.isfinite(g), g, np.inf)

    def search(self, shift, phi):
        """Contact and second-best candidate for each shift: parameters and gaps (axle at 0)."""
        sh, ph = shift[:, None], phi[:, None]
        g = self.gap(self.s_grid[None, :], sh, ph, exact=False)
        n = len(shift)
        rows = np.arange(n)
        i1 = np.argmin(g, axis=1)
        if not np.all(np.isfinite(g[rows, i1])):
            k = int(np.flatnonzero(~np.isfinite(g[rows, i1]))[0])
            raise NoContact(k, f"the {self.name} wheel is nowhere above its rail")
        # Best other local minimum at least 1 mm away along the wheel.
        interior = np.zeros_like(g, dtype=bool)
        interior[:, 1:-1] = (g[:, 1:-1] <= g[:, :-2]) & (g[:, 1:-1] <= g[:, 2:])
        interior[:, 0] = g[:, 0] <= g[:, 1]
        interior[:, -1] = g[:, -1] <= g[:, -2]
        far = np.abs(self.s_grid[None, :] - self.s_grid[i1][:, None]) > 1e-3
        g2 = np.where(interior & far & np.isfinite(g), g, np.inf)
        i2 = np.argmin(g2, axis=1)
        has2 = np.isfinite(g2[rows, i2])
        s1, v1 = self._refine(i1, shift, phi)
        s2, v2 = self._refine(np.where(has2, i2, i1), shift, phi)
        v2 = np.where(has2, v2, np.inf)
        swap = v2 < v1  # the coarse table may rank near-equal candidates wrongly
        s1, s2 = np.where(swap, s2, s1), np.where(swap, s1, s2)
        v1, v2 = np.where(swap, v2, v1), np.where(swap, v1, v2)
        return s1, v1, s2, v2

    def _refine(self, i, shift, phi, rounds: int = 8, m: int = 9):
        lo = self.s_grid[np.maximum(i - 1, 0)]
        hi = self.s_grid[np.minimum(i + 1, len(self.s_grid) - 1)]
        window = (lo, hi)
        for _ in range(rounds):
            s = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, m)[None, :]
            g = self.gap(s, shift[:, None], phi[:, None], exact=True)
            j = np.argmin(g, axis=1)
            rows = np.arange(len(lo))
            step = (hi - lo) / (m - 1)
            centre = s[rows, j]
            lo = np.maximum(centre - step, self.wheel.s_min)
            hi = np.minimum(centre + step, self.wheel.s_max)
        s = 0.5 * (lo + hi)
        s = np.where(np.isfinite(self.gap(s, shift, phi, exact=True)), s, centre)
        return self._polish(s, *window, shift, phi)

    def _polish(self, s, lo, hi, shift, phi):
        # Newton on the tangency condition d(gap)/ds = 0: the gap's minimum is flat, so the grid
        # locates it only to ~sqrt(round-off / curvature) (nm); the slopes locate it to round-off.
        g = self.gap(s, shift, phi, exact=True)
        for _ in range(2):
            p1, p2 = self.wheel.derivative(s, 1), self.wheel.derivative(s, 2)
            c, sn = np.cos(phi), np.sin(phi)
            y1, y2 = c * self.sign * p1[..., 0] + sn * p1[..., 1], c * self.sign * p2[..., 0] + sn * p2[..., 1]
            z1, z2 = sn * self.sign * p1[..., 0] - c * p1[..., 1], sn * self.sign * p2[..., 0] - c * p2[..., 1]
            Y = self.wheel_points(s, shift, phi)[0]
            sr = self.rail.s_at(self.sign * Y - self.origin)
            ok = np.isfinite(sr)
            sr = np.where(ok, sr, self.rail.s_min)
            r1, r2 = self.rail.derivative(sr, 1), self.rail.derivative(sr, 2)
            m = r1[..., 1] / r1[..., 0]
            q = (r2[..., 1] * r1[..., 0] - r1[..., 1] * r2[..., 0]) / r1[..., 0] ** 3
            d1 = z1 - self.sign * m * y1
            d2 = z2 - q * y1**2 - self.sign * m * y2
            with np.errstate(divide="ignore", invalid="ignore"):
                trial = s - d1 / d2
            take = ok & (d2 > 0) & np.isfinite(trial) & (trial >= lo) & (trial <= hi)
            gt = self.gap(np.where(take, trial, s), shift, phi, exact=True)
            take &= gt <= g + 1e-14  # no worse than round-off
            s, g = np.where(take, trial, s), np.where(take, gt, g)
        return s, g

    def describe(self, s, shift, phi, height):
        """Contact quantities at wheel parameter ``s``."""
        Y, Zrel, yrel = self.wheel_points(s, shift, phi)
        yr = self.sign * Y - self.origin
        slope = self.rail.slope_at(yr)
        p = self.wheel.position(s)
        return {
            "Y": Y, "Z": Zrel + height, "wheel_y": p[..., 0], "rail_y": yr,
            "radius": self.r0 + p[..., 1], "angle": np.arctan(slope),
            "droll": -(yrel + self.sign * slope * Zrel),  # d(axle height to touch)/d(phi)
        }


class NoContact(Exception):
    """A wheel finds no contact on its rail at shift number ``index`` (``what`` says why)."""

    def __init__(self, index, what):
        super().__init__(what)
        self.index, self.what = index, what
