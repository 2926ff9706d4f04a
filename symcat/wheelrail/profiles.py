"""Wheel and rail profiles as smooth planar curves (cubic splines, continuous to the second derivative).

One frame for every profile in symcat, in metres:

* **wheel**: ``y`` lateral from the tape circle, positive toward the field side (the outer face of
  the wheel; the flange is at negative ``y``, its back at ``y = -0.070`` m for S1002 and
  EN 15302 wheel A); ``z`` the radius deviation ``r(y) - r0`` from the nominal rolling radius
  at the tape circle, positive for a larger radius, i.e. toward the rail (flange tip
  ``z = +0.028`` m).
* **rail**: ``y`` lateral from the rail's reference point, positive toward the field side (the
  gauge face at negative ``y``); ``z`` up, ``z = 0`` at the top of the rail in its installed
  (inclined) position.

In both, the curve parameter ``s`` runs with increasing ``y`` and ``+z`` points out of the
material toward the other body, so the unit normal ``(-z', y') / |r'|`` is the outward normal of
either profile, and the envelope facing the other body is the largest ``z`` at a given ``y``.

A profile is a parametric curve ``(y(s), z(s))``, not a graph ``z(y)``: the rail's gauge face and
the wheel's flange back are near vertical (one UIC60 data step is 20 nm wide). ``s`` is the
cumulative chord length of the data points (arc length within about 1 %), and the curve is a
cubic smoothing spline (FITPACK ``splprep``; simple interior knots, hence C2) whose rms
deviation from the points is ``smoothing_m`` (default 0.2 um: below the accuracy of profile
measurement, which keeps the curvature free of the wiggles of an interpolating spline).
Measured, noisy profiles want a larger value (a few micrometres).
"""
from __future__ import annotations

import math
import warnings
from functools import cached_property

import numpy as np
from scipy.interpolate import BSpline, PPoly, make_interp_spline, splprep

from symcat.errors import ParameterError

from .piecewise_cubic import GraphBrackets, PiecewiseCubic

KINDS = ("wheel", "rail")
DEFAULT_SMOOTHING_M = 2e-7


class Profile:
    """A wheel or rail profile: a C2 cubic spline curve ``r(s) = (y(s), z(s))`` [m].

    Build it with :meth:`from_points` (validated point data) or the functions of
    :mod:`symcat.wheelrail.standard_profiles`. Every evaluation is vectorised over ``s``
    (any shape; the output adds a last axis of length 2 for ``(y, z)``).

    Attributes
    ----------
    spline : scipy.interpolate.BSpline
        The curve, coefficients of shape ``(n, 2)``.
    kind : str
        ``"wheel"`` or ``"rail"`` (see the module docstring for the frames).
    name : str
        Name used in messages.
    points : ndarray or None
        The data points ``(N, 2)`` [m] the curve was fitted to.
    inclination_rad : float
        Rail inclination already built into the data (rotation toward the track centre) [rad].
    source : str
        Provenance (the data file's first line).
    fit_max_m : float
        Largest distance of a data point from the curve [m].
    """

    def __init__(self, spline: BSpline, kind: str, name: str = "", *, points=None,
                 inclination_rad: float = 0.0, source: str = "", fit_max_m: float = 0.0):
        if kind not in KINDS:
            raise ParameterError(f"kind={kind!r}: must be one of {', '.join(KINDS)}")
        self.spline = spline
        self.kind = kind
        self.name = name or kind
        self.points = None if points is None else np.asarray(points, float)
        self.inclination_rad = float(inclination_rad)
        self.source = source
        self.fit_max_m = float(fit_max_m)
        k = spline.k
        self.s_min = float(spline.t[k])
        self.s_max = float(spline.t[-k - 1])
        self._derivs = [spline] + [spline.derivative(n) for n in (1, 2, 3)]
        self._build_table()

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_points(cls, y, z, kind: str, name: str = "", *, smoothing_m: float = DEFAULT_SMOOTHING_M,
                    min_points: int = 10, min_span_m: float = 0.005, inclination_rad: float = 0.0,
                    source: str = "") -> "Profile":
        """Fit a profile to ordered point data.

        Parameters
        ----------
        y, z : array_like
            Point coordinates [m] in the frame of ``kind``, ordered along the profile (either
            direction; the result runs with increasing ``y``).
        kind : str
            ``"wheel"`` or ``"rail"``.
        name : str
            Name used in messages.
        smoothing_m : float
            Root-mean-square distance of the points from the smoothing spline [m]; 0
            interpolates.
        min_points : int
            Fewest points accepted.
        min_span_m : float
            Smallest lateral extent accepted [m].
        inclination_rad : float
            Rail inclination already contained in the data [rad].
        source : str
            Provenance text.

        Raises
        ------
        ParameterError
            For NaN or infinite values, too few points, a span too small, points out of order
            (turning back on themselves) or a self-intersecting polyline.
        """
        label = f"profile {name!r}" if name else "profile"
        if not (isinstance(smoothing_m, (int, float)) and smoothing_m >= 0):
            raise ParameterError(f"smoothing_m={smoothing_m!r}: must be a number >= 0 (m)")
        pts = validate_points(y, z, label, min_points=min_points, min_span_m=min_span_m,
                              tolerance_m=max(4 * smoothing_m, 1e-6))
        if pts[-1, 0] < pts[0, 0]:
            pts = pts[::-1]
        u = np.r_[0.0, np.cumsum(np.hypot(*np.diff(pts, axis=0).T))]  # chord length ~ arc length
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # FITPACK's "s too small" notes; the fit is checked below
            (t, c, k), _ = splprep([pts[:, 0], pts[:, 1]], u=u, k=3, s=len(pts) * smoothing_m**2)
        spline = BSpline(t, np.column_stack(c), k)
        fit_max = float(np.hypot(*(spline(u) - pts).T).max())
        if not fit_max < max(50 * smoothing_m, 1e-6):
            raise ParameterError(f"{label}: the smoothing spline misses the points by {fit_max * 1e3:.3g} mm "
                                 f"(smoothing_m={smoothing_m:g}); check the data for outliers")
        return cls(spline, kind, name, points=pts, inclination_rad=inclination_rad, source=source,
                   fit_max_m=fit_max)

    @classmethod
    def from_parametric(cls, s, y, z, kind: str, name: str = "", **kwargs) -> "Profile":
        """Interpolate exact curve samples ``(y(s), z(s))`` [m] (analytic profiles)."""
        spline = make_interp_spline(np.asarray(s, float), np.column_stack([y, z]), k=3)
        return cls(spline, kind, name, **kwargs)

    # ------------------------------------------------------------------ evaluation
    def position(self, s) -> np.ndarray:
        """Point ``(y, z)`` [m] at parameter ``s`` [m]; shape ``s.shape + (2,)``."""
        return self._derivs[0](np.asarray(s, float))

    def derivative(self, s, order: int = 1) -> np.ndarray:
        """``d^order r / ds^order`` at ``s`` (order 0 to 3); shape ``s.shape + (2,)``."""
        if order not in (0, 1, 2, 3):
            raise ParameterError(f"order={order}: must be 0, 1, 2 or 3")
        return self._derivs[order](np.asarray(s, float))

    def tangent(self, s) -> np.ndarray:
        """Unit tangent, pointing toward increasing ``y``."""
        d = self.derivative(s, 1)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def normal(self, s) -> np.ndarray:
        """Unit normal pointing out of the material (toward the other body)."""
        t = self.tangent(s)
        return np.stack([-t[..., 1], t[..., 0]], axis=-1)

    def curvature(self, s) -> np.ndarray:
        """Signed curvature [1/m]: positive where the surface is concave seen from outside (a
        hollow), negative where convex (the rail crown)."""
        d1, d2 = self.derivative(s, 1), self.derivative(s, 2)
        cross = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
        return cross / np.sqrt(d1[..., 0] ** 2 + d1[..., 1] ** 2) ** 3  # |d1| (as np.linalg.norm, faster)

    def slope(self, s) -> np.ndarray:
        """``dz/dy`` at ``s`` (infinite on a vertical face)."""
        d = self.derivative(s, 1)
        with np.errstate(divide="ignore"):
            return d[..., 1] / d[..., 0]

    @property
    def y_range(self) -> tuple[float, float]:
        """Lateral extent ``(y_min, y_max)`` [m]."""
        return float(self._ytab.min()), float(self._ytab.max())

    @property
    def length_m(self) -> float:
        """Arc length of the curve [m]."""
        xg, wg = np.polynomial.legendre.leggauss(8)
        br = np.unique(self.spline.t)
        a, b = br[:-1], br[1:]
        s = 0.5 * (b - a)[:, None] * xg + 0.5 * (a + b)[:, None]
        speed = np.linalg.norm(self.derivative(s, 1), axis=-1)
        return float((0.5 * (b - a)[:, None] * wg * speed).sum())

    def sample(self, spacing_m: float = 1e-4) -> tuple[np.ndarray, np.ndarray]:
        """Parameters and points spaced about ``spacing_m`` along the curve: ``(s, points)``."""
        n = max(int(math.ceil((self.s_max - self.s_min) / spacing_m)), 2) + 1
        s = np.linspace(self.s_min, self.s_max, n)
        return s, self.position(s)

    # ------------------------------------------------------------------ graph look-ups
    def s_at(self, y) -> np.ndarray:
        """Parameter of the point at lateral ``y`` [m] on the envelope facing the other body
        (largest ``z`` where the curve passes ``y`` more than once); NaN outside the profile."""
        return self.envelope_at(y)[0]

    def envelope_at(self, y, slope: bool = False) -> tuple:
        """Parameter and ``z`` [m] of the point at lateral ``y`` [m] on the envelope facing the
        other body (largest ``z`` where the curve passes ``y`` more than once): ``(s, z)``,
        ``(NaN, -inf)`` outside the profile; with ``slope`` also ``dz/dy`` there (NaN outside):
        ``(s, z, dz/dy)``."""
        y = np.asarray(y, float)
        flat = y.ravel()
        best = [np.full(flat.shape, np.nan), np.full(flat.shape, -np.inf)]
        if slope:
            best.append(np.full(flat.shape, np.nan))
        for graph in self._graph:
            inside = (flat >= graph.ys[0]) & (flat <= graph.ys[-1])
            if not inside.any():
                continue
            found = graph.solve(flat[inside], slope=slope)
            if len(self._graph) == 1:  # one monotone piece (most profiles): nothing to compare
                for b, f in zip(best, found):
                    b[inside] = f
                continue
            better = found[1] > best[1][inside]
            idx = np.flatnonzero(inside)[better]
            for b, f in zip(best, found):
                b[idx] = f[better]
        return tuple(b.reshape(y.shape) for b in best)

    def z_at(self, y) -> np.ndarray:
        """``z`` [m] at lateral ``y`` [m] on the envelope facing the other body; NaN outside."""
        s = self.s_at(y)
        out = np.full(s.shape, np.nan)
        ok = np.isfinite(s)
        out[ok] = self.position(s[ok])[..., 1]
        return out

    def slope_at(self, y) -> np.ndarray:
        """``dz/dy`` at lateral ``y`` [m] (envelope facing the other body); NaN outside."""
        s = self.s_at(y)
        out = np.full(s.shape, np.nan)
        ok = np.isfinite(s)
        out[ok] = self.slope(s[ok])
        return out

    # ------------------------------------------------------------------ other forms
    @cached_property
    def cubic(self) -> PiecewiseCubic:
        """The curve as a :class:`.piecewise_cubic.PiecewiseCubic` (:meth:`piecewise_polynomial`):
        lean evaluation for the many small calls of the contact searches."""
        pp = self.piecewise_polynomial()
        return PiecewiseCubic(pp.x, pp.c)

    def piecewise_polynomial(self) -> PPoly:
        """The curve as a piecewise cubic: ``pp.x`` the breakpoints (strictly increasing),
        ``pp.c`` of shape ``(4, len(pp.x) - 1, 2)``, so that on ``[x_i, x_i+1]``
        ``r(s) = sum_k c[k, i, :] (s - x_i)**(3 - k)`` (scipy's ``PPoly`` convention)."""
        x = np.unique(self.spline.t[self.spline.k:-self.spline.k])
        left = x[:-1]
        c = np.stack([self.derivative(left, 3) / 6, self.derivative(left, 2) / 2,
                      self.derivative(left, 1), self.position(left)])
        return PPoly(c, x)

    def transformed(self, angle_rad: float = 0.0, offset=(0.0, 0.0), mirror: bool = False,
                    name: str | None = None) -> "Profile":
        """A rigidly moved copy: optional mirror ``y -> -y`` (the parameter reversed so that it
        still runs with increasing ``y``), then a rotation by ``angle_rad``
        (counter-clockwise in the ``(y, z)`` plane: for a rail, toward the track centre), then
        a translation by ``offset`` [m]. Exact (the spline's control points are moved)."""
        t = np.array(self.spline.t, float)
        c = np.array(self.spline.c, float)
        if mirror:
            # Reverse the parameter too, so that s still runs with increasing y.
            t = (t[0] + t[-1]) - t[::-1]
            c = c[::-1] * [-1.0, 1.0]
        ca, sa = math.cos(angle_rad), math.sin(angle_rad)
        c = c @ np.array([[ca, sa], [-sa, ca]]) + np.asarray(offset, float)
        pts = None
        if self.points is not None:
            pts = self.points[::-1] * [-1.0, 1.0] if mirror else self.points
            pts = pts @ np.array([[ca, sa], [-sa, ca]]) + np.asarray(offset, float)
        return Profile(BSpline(t, c, self.spline.k), self.kind, name or self.name, points=pts,
                       inclination_rad=self.inclination_rad + (0.0 if mirror else angle_rad),
                       source=self.source, fit_max_m=self.fit_max_m)

    def __repr__(self) -> str:
        y0, y1 = self.y_range
        return (f"Profile({self.name!r}, kind={self.kind!r}, y {y0 * 1e3:.2f}..{y1 * 1e3:.2f} mm, "
                f"{len(np.unique(self.spline.t)) - 1} cubic pieces)")

    # ------------------------------------------------------------------ internals
    def _build_table(self) -> None:
        # Dense table for the graph look-ups: at least 8 samples per spline piece and <= 0.05 mm apart.
        knots = np.unique(self.spline.t)
        per = np.linspace(0.0, 1.0, 9)[:-1]
        fine = (knots[:-1, None] + np.diff(knots)[:, None] * per).ravel()
        n_uniform = int(math.ceil((self.s_max - self.s_min) / 5e-5)) + 1
        s = np.unique(np.r_[fine, np.linspace(self.s_min, self.s_max, n_uniform), self.s_max])
        self._stab = s
        p = self.position(s)
        self._ytab, self._ztab = p[:, 0], p[:, 1]
        dy = np.diff(self._ytab)
        sign = np.sign(dy)
        # Monotone pieces of y(s): split where y turns back (a folded flange back or gauge face).
        pieces, start, current = [], 0, 0.0
        for i, sg in enumerate(sign):
            if sg == 0:
                continue
            if current != 0 and sg != current:
                pieces.append((start, i))
                start = i
            current = sg
        pieces.append((start, len(s) - 1))
        self._pieces = pieces
        self._graph = [GraphBrackets(self.cubic, s[lo:hi + 1], self._ytab[lo:hi + 1]) for lo, hi in pieces]


def validate_points(y, z, label: str = "profile", *, min_points: int = 10, min_span_m: float = 0.005,
                    tolerance_m: float = 1e-6) -> np.ndarray:
    """Check profile point data and return it as an ``(N, 2)`` array without repeated points.

    Raises :class:`~symcat.errors.ParameterError` naming the first problem: mismatched or
    non-finite values, fewer than ``min_points`` points, a lateral span below ``min_span_m``,
    points out of order (the polyline turning back by more than 120 degrees over segments longer
    than ``tolerance_m``) or a self-intersecting polyline.
    """
    y = np.asarray(y, float).ravel()
    z = np.asarray(z, float).ravel()
    if y.shape != z.shape:
        raise ParameterError(f"{label}: {y.size} y values but {z.size} z values")
    bad = np.flatnonzero(~(np.isfinite(y) & np.isfinite(z)))
    if bad.size:
        i = bad[0]
        raise ParameterError(f"{label}: point {i} (y={y[i]}, z={z[i]}) is not finite; "
                             f"{bad.size} such point(s), all values must be finite numbers")
    pts = np.column_stack([y, z])
    if len(pts) > 1:
        keep = np.r_[True, np.any(np.diff(pts, axis=0) != 0, axis=1)]
        pts = pts[keep]
    if len(pts) < min_points:
        raise ParameterError(f"{label}: {len(pts)} distinct points; at least {min_points} are needed")
    span = pts[:, 0].max() - pts[:, 0].min()
    if span < min_span_m:
        raise ParameterError(f"{label}: lateral span {span * 1e3:.3g} mm; at least {min_span_m * 1e3:.3g} mm "
                             "is needed")
    seg = np.diff(pts, axis=0)
    length = np.hypot(*seg.T)
    cosang = (seg[:-1] * seg[1:]).sum(axis=1) / (length[:-1] * length[1:])
    back = np.flatnonzero((cosang < -0.5) & (np.minimum(length[:-1], length[1:]) > tolerance_m))
    if back.size:
        i = back[0]
        turn = math.degrees(math.acos(max(-1.0, min(1.0, cosang[i]))))
        raise ParameterError(f"{label}: points {i}-{i + 2} turn back by {turn:.0f} deg "
                             f"(at y={pts[i + 1, 0] * 1e3:.3f} mm); points must be ordered along the profile")
    hit = _first_crossing(pts)
    if hit is not None:
        i, j, p = hit
        raise ParameterError(f"{label}: segments {i}-{i + 1} and {j}-{j + 1} cross at y={p[0] * 1e3:.3f} mm, "
                             f"z={p[1] * 1e3:.3f} mm; the profile must not intersect itself")
    return pts


def _first_crossing(pts: np.ndarray, chunk: int = 256):
    """First pair of non-adjacent polyline segments that properly cross, or None."""
    a, b = pts[:-1], pts[1:]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    m = len(a)

    def orient(p, q, r):
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])

    for i0 in range(0, m, chunk):
        i = np.arange(i0, min(i0 + chunk, m))[:, None]
        j = np.arange(m)[None, :]
        cand = (j >= i + 2) & np.all(lo[i] <= hi[None, :], axis=-1) & np.all(lo[None, :] <= hi[i], axis=-1)
        ii, jj = np.nonzero(cand)
        if ii.size == 0:
            continue
        ii = ii + i0
        pa, pb, pc, pd = a[ii], b[ii], a[jj], b[jj]
        d1, d2 = orient(pa, pb, pc), orient(pa, pb, pd)
        d3, d4 = orient(pc, pd, pa), orient(pc, pd, pb)
        cross = (d1 * d2 < 0) & (d3 * d4 < 0)
        if cross.any():
            k = np.flatnonzero(cross)[0]
            t = d3[k] / (d3[k] - d4[k])
            return int(ii[k]), int(jj[k]), pa[k] + t * (pb[k] - pa[k])
    return None
