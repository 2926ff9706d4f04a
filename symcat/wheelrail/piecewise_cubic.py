"""Lean evaluation of a profile's piecewise cubic (Horner on its ``PPoly`` coefficients).

The contact searches (:mod:`.gap_minima`, :mod:`symcat.wheelrail_events.contact_jumps`) evaluate the
profiles thousands of times per check, mostly on small arrays, where scipy's
``BSpline.__call__`` spends about 10 us per call on argument handling. :class:`PiecewiseCubic`
evaluates the same curve (to rounding: Horner from the piece start instead of de Boor) with a
few numpy operations, and :class:`GraphBrackets` does the graph look-up's Newton on it
(:meth:`symcat.wheelrail.profiles.Profile.envelope_at`).
"""
from __future__ import annotations

import bisect

import numpy as np

#: A graph look-up's Newton step below this (m) is rounding: the point has converged.
SETTLED_M = 1e-17


class PiecewiseCubic:
    """A planar piecewise cubic ``r(s) = sum_k c[k, i] (s - x_i)**(3 - k)`` on ``[x_i, x_i+1]``
    (scipy's ``PPoly`` convention; the end pieces extend it beyond ``x_0`` and ``x_m``).

    Parameters
    ----------
    x : array_like (m + 1,)
        Strictly increasing breakpoints.
    c : array_like (4, m, 2)
        Coefficients of ``(y, z)`` per piece, highest power first.
    """

    def __init__(self, x, c):
        self.x = np.asarray(x, float)
        c = np.asarray(c, float)
        self.start = self.x[:-1]
        self._last = len(self.start) - 1
        self._x = self.x.tolist()  # bisect on a list is 10x faster than searchsorted for one value
        # Coefficients of r and its first three derivatives per piece, highest power first:
        # (terms, 2, m), so that a gather along the pieces gives contiguous rows (Horner on
        # them, not on strided columns).
        d1 = np.stack([3 * c[0], 2 * c[1], c[2]])
        d2 = np.stack([6 * c[0], 2 * c[1]])
        self._coef = [np.ascontiguousarray(np.moveaxis(a, 1, 2)) for a in (c, d1, d2, 6 * c[:1])]
        self._rows = [np.moveaxis(a, 2, 0).tolist() for a in self._coef]  # (m, terms, 2): at()
        #: Coefficients of ``y`` and of ``z`` alone, (m, 4): the graph look-up's Newton.
        self.cy, self.cz = c[:, :, 0].T.copy(), c[:, :, 1].T.copy()

    def index(self, s) -> np.ndarray:
        """Piece of each parameter ``s`` (the end pieces extend the curve)."""
        return np.minimum(np.maximum(np.searchsorted(self.x, s, side="right") - 1, 0), self._last)  # np.clip, faster

    def __call__(self, s, order: int = 0, index=None) -> np.ndarray:
        """``d^order r / ds^order`` (order 0 to 3) at ``s``, shape ``s.shape + (2,)``; ``index``:
        the pieces of ``s`` (:meth:`index`), if known."""
        return np.moveaxis(self.components(s, order, index), 0, -1)

    def components(self, s, order: int = 0, index=None) -> np.ndarray:
        """:meth:`__call__` as its two components ``(y, z)``: shape ``(2,) + s.shape``."""
        s = np.asarray(s, float)
        i = self.index(s) if index is None else index
        coef = self._coef[order].take(i, axis=-1)  # (terms, 2) + s.shape
        t = s - self.start[i]
        out = coef[0]
        for k in range(1, len(coef)):
            out = out * t + coef[k]
        return out

    def at(self, s: float, order: int = 0) -> tuple[float, float]:
        """:meth:`__call__` at one parameter, as Python floats (no numpy overhead)."""
        i = min(max(bisect.bisect_right(self._x, s) - 1, 0), self._last)
        t = s - self._x[i]
        y, z = self._rows[order][i][0]
        for cy, cz in self._rows[order][i][1:]:
            y, z = y * t + cy, z * t + cz
        return y, z

    def curvature(self, s) -> np.ndarray:
        """Signed curvature [1/m] (:meth:`symcat.wheelrail.profiles.Profile.curvature`)."""
        s = np.asarray(s, float)
        i = self.index(s)
        (dy, dz), (ddy, ddz) = self.components(s, 1, i), self.components(s, 2, i)
        return (dy * ddz - dz * ddy) / np.sqrt(dy**2 + dz**2) ** 3


class GraphBrackets:
    """Brackets of a monotone piece of ``y(s)`` for the graph look-up ``y -> (s, z)``: the table
    points ``(s_j, y_j)`` (ascending in ``y``; each bracket within one cubic piece) and, per
    bracket, the coefficients of ``y`` and ``z`` in ``t = s - x_i`` of its piece, the bracket in
    ``t`` and the start of Newton (one gather per query instead of a dozen).

    The start is the cubic Hermite interpolant of the inverse ``t(y)`` over the bracket (where it
    is monotone, Fritsch-Carlson; else linear): within 1e-10 m on the profiles shipped, so that
    Newton converges in one step and stops after the second.

    Parameters
    ----------
    cubic : PiecewiseCubic
    ss, ys : ndarray
        Table parameters and their ``y``, ``y`` monotone (either direction).
    """

    def __init__(self, cubic: PiecewiseCubic, ss, ys):
        ss, ys = np.asarray(ss, float), np.asarray(ys, float)
        if ys[-1] < ys[0]:
            ss, ys = ss[::-1], ys[::-1]
        self.ys = np.ascontiguousarray(ys)
        self._index = np.arange(len(ys), dtype=float)
        piece = cubic.index(np.minimum(ss[:-1], ss[1:]))
        x0 = cubic.start[piece]
        cy, cz = cubic.cy[piece], cubic.cz[piece]
        t0, t1 = ss[:-1] - x0, ss[1:] - x0  # at the bracket's lower and upper y
        h, delta = ys[1:] - ys[:-1], t1 - t0
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            m0, m1 = (1.0 / ((3 * cy[:, 0] * t + 2 * cy[:, 1]) * t + cy[:, 2]) for t in (t0, t1))  # dt/dy
            alpha, beta = m0 * h / delta, m1 * h / delta
            hermite = np.isfinite(alpha) & np.isfinite(beta) & (alpha >= 0) & (beta >= 0) & (alpha**2 + beta**2 <= 9)
            linear = np.where(h > 0, delta / h, 0.0)
            a = np.where(hermite, m0, linear)
            b = np.where(hermite, (3 * delta / h - 2 * m0 - m1) / h, 0.0)
            c = np.where(hermite, (m0 + m1 - 2 * delta / h) / h**2, 0.0)
        base = np.where(h > 0, t0, 0.5 * (t0 + t1))  # a flat bracket: its middle
        #: Per bracket: y coefficients (4), 3a and 2b of y', t range (2), start in v = y - y_lo
        #: (t = base + v (a + v (b + v c))), y_lo, x0, z coefficients (4).
        self.table = np.ascontiguousarray(np.column_stack(
            [cy, 3 * cy[:, 0], 2 * cy[:, 1], np.minimum(t0, t1), np.maximum(t0, t1), base, a, b, c, ys[:-1], x0,
             cz]).T)

    def solve(self, q, steps: int = 4, slope: bool = False):
        """``(s, z)`` of the curve where ``y(s) = q`` (1-D, inside ``[ys[0], ys[-1]]``), and with
        ``slope`` ``dz/dy`` there: Newton in the bracket, each step kept in it, at most
        ``steps``. After the second step only the points it moved by more than
        :data:`SETTLED_M` go on (the others have converged: they would oscillate by ulps)."""
        # The bracket of each q: np.interp's binary search is 3x faster than np.searchsorted's (a
        # q within rounding of a table point may get the next bracket, where Newton stops at it).
        i = np.minimum(np.interp(q, self.ys, self._index).astype(np.intp), len(self.ys) - 2)
        row = self.table.take(i, axis=1)
        coef = row[:8]  # a, b, c, d - q, 3a, 2b, lo, hi
        coef[3] -= q
        v = q - row[12]
        t = row[8] + v * (row[9] + v * (row[10] + v * row[11]))
        active = None
        with np.errstate(divide="ignore", invalid="ignore"):
            for k in range(steps):
                a, b, c, d, a3, b2, lo, hi = coef
                t_a = t if active is None else t[active]
                dy = (a3 * t_a + b2) * t_a + c
                step = ((a * t_a + b) * t_a + c) * t_a + d
                step /= dy
                if not dy.all():  # a vertical tangent: no step
                    step[dy == 0] = 0.0
                new = np.minimum(np.maximum(t_a - step, lo), hi)  # np.clip, faster
                if k == 0:
                    t = new
                    continue
                moved = np.flatnonzero(np.abs(new - t_a) > SETTLED_M)
                if active is None:
                    t, active = new, moved
                else:
                    t[active], active = new, active[moved]
                if not moved.size:
                    break
                coef = coef[:, moved]
        z = ((row[14] * t + row[15]) * t + row[16]) * t + row[17]
        if not slope:
            return row[13] + t, z
        dz = (3 * row[14] * t + 2 * row[15]) * t + row[16]
        with np.errstate(divide="ignore", invalid="ignore"):
            return row[13] + t, z, dz / ((row[4] * t + row[5]) * t + row[2])
