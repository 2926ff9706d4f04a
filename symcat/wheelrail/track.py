"""Track geometry: the centreline, the canted track frame and the rail profile frames
``(R^rp, A^rp)`` of the seed's eq. (19) as functions of the distance ``s`` along the track.

A layout is a list of segments - :class:`Tangent`, :class:`Curve`, :class:`Transition` (a
clothoid: curvature and superelevation linear in ``s`` between its neighbours) - laid end to
end from the origin. Frames and sign conventions (global frame ``x`` east, ``y`` north, ``z`` up):

* ``s`` [m] is the distance along the centreline **in plan** (chainage). With a constant
  ``gradient`` the centreline rises ``gradient * s`` and its true length is
  ``s * sqrt(1 + gradient**2)``.
* heading ``psi(s)`` [rad] counter-clockwise from ``x``; curvature ``kappa = dpsi/ds`` [1/m],
  positive for a curve to the **left**.
* superelevation ``h(s)`` [m], signed: positive raises the **left** rail (so a curve to the
  right with positive ``cant_m`` has ``h > 0``). Cant angle ``phi = arcsin(h / cant_base_m)``
  with ``cant_base_m`` the distance between the rails' running circles (1.5 m); ``phi > 0``
  lifts the left rail, as the wheelset roll angle of :mod:`.geometry`. ``h`` (not ``phi``) is
  linear in a transition.
* track frame ``A_t = Rz(psi) Ry(-theta) Rx(phi)`` (``theta = atan(gradient)``): columns tangent,
  lateral (toward the left rail), normal to the running plane (up). The cross-section turns
  about the centreline (``cant_pivot="centre"``) or about the low rail
  (``cant_pivot="low_rail"``: the centreline then rises by ``|h|/2``).
* rail profile frames: origin ``R^rp = C + A_t q`` with ``q = (0, +-rail_offset_m, 0)`` (+ left,
  - right) plus irregularities; orientation ``A^rp = A_t Rx(+-beta)`` with ``beta`` the rail
  inclination added by the frame (toward the track centre: ``+`` left, ``-`` right). Both frames
  are right-handed with their ``y`` column toward the **left**. The profiles of
  :mod:`.profiles` have ``y`` toward the field side, so a profile point ``(y, z)`` enters eq.
  (19) as ``u^rp = (0, y, z)`` on the left rail and ``(0, -y, z)`` on the right rail
  (:meth:`TrackLayout.surface_point` does this).
* irregularities (:class:`Irregularities`, in the canted track frame): alignment ``a`` and
  level ``v`` move both rails (left and up), gauge ``g`` spreads them (each rail outward by
  ``g/2``), cross level ``c`` raises the left rail by ``c/2`` and lowers the right one by
  ``c/2``. They translate the frames; they do not rotate them. :func:`synthetic_irregularities`
  draws alignment and level from the ERRI B176 PSD (or any PSD) with a seed.

Continuity: positions and headings are continuous at every join; without a transition the
curvature jumps (allowed: low-speed and test tracks are built like that; the rail frames stay
C1), but a step of superelevation without a transition would break the rails and is an error.
Derivatives at a join are those of the segment that starts there (right-continuous).

Accuracy: tangents and circular arcs are closed forms (chord formula, round-off only);
clothoids are integrated by 16-point Gauss-Legendre from stored panel starts at most
``0.25 rad`` of heading and 25 m apart (truncation below 1e-16 relative; the checked error
against Fresnel integrals is round-off, about 1e-12 m over kilometres).
"""
from __future__ import annotations

import math

import numpy as np

from symcat.errors import ParameterError

from .irregularities import (Irregularities, _positive, erri_b176_psd, read_irregularities,  # noqa: F401
                             synthetic_irregularities)
from .track_parts import CANT_RAMPS, Curve, cant_ramp_values, FramePiece, RailFrame, Tangent, Transition, rail_offset_for  # noqa: F401

#: Lateral distance from the track centre to the UIC60 1:40 profile origin for a 1.435 m gauge
#: measured 14 mm below the rail top (:func:`rail_offset_for` with the shipped profile) [m].
UIC60_RAIL_OFFSET_M = 0.760532
SIDES = ("left", "right")

_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)
_PANEL_HEADING_RAD = 0.25
_PANEL_LENGTH_M = 25.0
_KX = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
_KZ = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])


class TrackLayout:
    """A track: centreline, track frame and rail profile frames against ``s`` (module docstring).

    Parameters
    ----------
    segments : sequence of Tangent, Curve, Transition
        Laid end to end from ``s = 0``; two transitions may not follow each other.
    rail_offset_m : float
        Lateral distance from the centreline to each rail profile's origin [m]
        (:func:`rail_offset_for`; the default suits UIC60 1:40 at 1.435 m gauge).
    cant_base_m : float
        Distance between the rails' running circles, the base of the cant angle [m].
    rail_inclination_rad : float or None
        Rail inclination toward the track centre [rad]; ``None`` (default) keeps the inclination
        built into the profile data (frame rotation 0), a value makes the frame rotate the
        profile by ``rail_inclination_rad - profile_inclination_rad``.
    profile_inclination_rad : float
        Inclination built into the profile data [rad] (UIC60 1:40: ``atan(1/40)``).
    gradient : float
        Constant longitudinal gradient [m/m] (rise per plan distance), ``|gradient| < 0.1``.
    cant_pivot : str
        ``"centre"`` or ``"low_rail"``: the axis the cross-section turns about.
    irregularities : Irregularities, optional
        Measured irregularities added to the rail frames.
    start_heading_rad : float
        Heading at ``s = 0`` [rad].
    start_position_m : sequence of 3 floats
        Centreline position at ``s = 0`` [m].

    Raises
    ------
    ParameterError
        For a non-positive length or radius, an unknown direction or pivot, adjacent
        transitions, a superelevation step without a transition, or ``|cant| >= cant_base_m``.
    """

    def __init__(self, segments, *, rail_offset_m: float = UIC60_RAIL_OFFSET_M, cant_base_m: float = 1.5,
                 rail_inclination_rad: float | None = None, profile_inclination_rad: float = math.atan(1 / 40),
                 gradient: float = 0.0, cant_pivot: str = "centre", irregularities: Irregularities | None = None,
                 start_heading_rad: float = 0.0, start_position_m=(0.0, 0.0, 0.0)):
        segments = list(segments)
        if not segments:
            raise ParameterError("segments=[]: a track needs at least one segment")
        self.rail_offset_m = _positive("rail_offset_m", rail_offset_m)
        self.cant_base_m = _positive("cant_base_m", cant_base_m)
        if not (math.isfinite(gradient) and abs(gradient) < 0.1):
            raise ParameterError(f"gradient={gradient!r}: must be a number with |gradient| < 0.1 (m/m)")
        if cant_pivot not in ("centre", "low_rail"):
            raise ParameterError(f"cant_pivot={cant_pivot!r}: must be 'centre' or 'low_rail'")
        if irregularities is not None and not isinstance(irregularities, Irregularities):
            raise ParameterError(f"irregularities={irregularities!r}: must be an Irregularities or None")
        p0 = np.asarray(start_position_m, float)
        if p0.shape != (3,) or not np.all(np.isfinite(p0)) or not math.isfinite(start_heading_rad):
            raise ParameterError(f"start_position_m={start_position_m!r}, start_heading_rad={start_heading_rad!r}: "
                                 "must be three finite coordinates [m] and a finite angle [rad]")
        self.segments = tuple(segments)
        self.gradient = float(gradient)
        self.cant_pivot = cant_pivot
        self.irregularities = irregularities
        self.inclination_rad = 0.0 if rail_inclination_rad is None else rail_inclination_rad - profile_inclination_rad
        self._theta = math.atan(self.gradient)
        self._p0 = p0
        self._build(float(start_heading_rad))

    # ----------------------------------------------------------------- construction
    def _build(self, psi0: float) -> None:
        segs = self.segments
        n = len(segs)
        kap = np.zeros(n)  # curvature of curves; transitions filled below
        h = np.zeros(n)
        for i, seg in enumerate(segs):
            label = f"segments[{i}] ({type(seg).__name__})"
            if not isinstance(seg, (Tangent, Curve, Transition)):
                raise ParameterError(f"{label}: must be a Tangent, Curve or Transition")
            _positive(f"{label} length_m", seg.length_m)
            if isinstance(seg, Curve):
                _positive(f"{label} radius_m", seg.radius_m)
                if seg.direction not in ("left", "right"):
                    raise ParameterError(f"{label} direction={seg.direction!r}: must be 'left' or 'right'")
                if not (math.isfinite(seg.cant_m) and abs(seg.cant_m) < self.cant_base_m):
                    raise ParameterError(f"{label} cant_m={seg.cant_m!r}: must satisfy |cant_m| < cant_base_m "
                                         f"= {self.cant_base_m:g} m")
                sign = 1.0 if seg.direction == "left" else -1.0
                kap[i] = sign / seg.radius_m
                h[i] = -sign * seg.cant_m  # the outer rail is the right one in a left curve
            if isinstance(seg, Transition) and i > 0 and isinstance(segs[i - 1], Transition):
                raise ParameterError(f"{label}: follows another transition; put a tangent or curve between them")
            if isinstance(seg, Transition) and seg.cant_ramp not in CANT_RAMPS:
                raise ParameterError(f"{label} cant_ramp={seg.cant_ramp!r}: must be one of {', '.join(CANT_RAMPS)}")
        L = np.array([float(s.length_m) for s in segs])
        k0, k1, h0, h1 = kap.copy(), kap.copy(), h.copy(), h.copy()
        for i, seg in enumerate(segs):
            if isinstance(seg, Transition):
                k0[i], h0[i] = (kap[i - 1], h[i - 1]) if i > 0 else (0.0, 0.0)
                k1[i], h1[i] = (kap[i + 1], h[i + 1]) if i + 1 < n else (0.0, 0.0)
        for i in range(1, n):
            if abs(h0[i] - h1[i - 1]) > 1e-12:
                raise ParameterError(f"segments[{i}] ({type(segs[i]).__name__}): superelevation steps from "
                                     f"{h1[i - 1]:g} m to {h0[i]:g} m; a change of cant needs a Transition")
        self._s0 = np.r_[0.0, np.cumsum(L)[:-1]]
        self._L = L
        self._k0 = k0
        self._dk = (k1 - k0) / L
        self._h0 = h0
        self._dh = (h1 - h0) / L
        self._smooth = np.array([isinstance(g, Transition) and g.cant_ramp == "smooth" for g in segs])
        self.length_m = float(L.sum())
        # Segment starts and clothoid panel starts (plan x, y and heading there).
        ps, px, py = [], [], []
        x, y, psi = self._p0[0], self._p0[1], psi0
        self._psi0 = np.zeros(n)
        for i in range(n):
            self._psi0[i] = psi
            dk = self._dk[i]
            if dk == 0.0:
                cuts = np.array([0.0])
            else:
                # Panels short in length and in heading change, for the fixed Gauss-Legendre rule.
                span = abs(k0[i]) * L[i] + 0.5 * abs(dk) * L[i] ** 2
                m = max(int(math.ceil(span / _PANEL_HEADING_RAD)), int(math.ceil(L[i] / _PANEL_LENGTH_M)), 1)
                cuts = np.linspace(0.0, L[i], m + 1)[:-1]
            u0 = 0.0
            for u in cuts:
                if u > 0.0:
                    dx, dy = self._plan_step(i, u0, u)
                    x, y = x + dx, y + dy
                ps.append(self._s0[i] + u)
                px.append(x)
                py.append(y)
                u0 = u
            dx, dy = self._plan_step(i, u0, L[i])
            x, y = x + dx, y + dy
            psi = psi + k0[i] * L[i] + 0.5 * dk * L[i] ** 2
        self._panel_s = np.array(ps)
        self._panel_xy = np.stack([px, py], axis=1)
        self._panel_seg = np.searchsorted(self._s0, self._panel_s, side="right") - 1
        self.end_position_m = np.array([x, y, self._p0[2] + self.gradient * self.length_m])
        self.end_heading_rad = psi

    def _plan_step(self, i: int, ua: float, ub: float) -> tuple[float, float]:
        """Plan displacement from local abscissa ``ua`` to ``ub`` within segment ``i``."""
        k0, dk, psi0 = self._k0[i], self._dk[i], self._psi0[i]
        d = ub - ua
        if dk == 0.0:
            # Chord of a circle or line: exact, and stable as kappa -> 0.
            chord = d * np.sinc(k0 * d / (2 * np.pi))
            mid = psi0 + k0 * ua + 0.5 * k0 * d
            return chord * math.cos(mid), chord * math.sin(mid)
        u = ua + 0.5 * d * (1.0 + _GL_X)
        psi = psi0 + k0 * u + 0.5 * dk * u**2
        return 0.5 * d * float(np.cos(psi) @ _GL_W), 0.5 * d * float(np.sin(psi) @ _GL_W)

    # ----------------------------------------------------------------- scalar fields
    def _locate(self, s_m, segment=None):
        s = np.atleast_1d(np.asarray(s_m, float))
        if s.ndim != 1 or not np.all(np.isfinite(s)) or s.min() < -1e-12 or s.max() > self.length_m + 1e-9:
            bad = s[~((s >= -1e-12) & (s <= self.length_m + 1e-9))] if np.all(np.isfinite(s)) else s
            raise ParameterError(f"s_m={bad.ravel()[:3]}: must lie on the track, 0 <= s <= {self.length_m:g} m")
        if segment is None:
            seg = np.clip(np.searchsorted(self._s0, s, side="right") - 1, 0, len(self._L) - 1)
        else:
            seg = np.broadcast_to(np.asarray(segment, int), s.shape)
        return s, seg, s - self._s0[seg]

    def segment_index(self, s_m) -> np.ndarray:
        """Index of the segment holding each ``s_m`` [m] (the later one at a join)."""
        return self._locate(s_m)[1]

    @property
    def joins_m(self) -> np.ndarray:
        """Positions of the segment ends, ``0`` and :attr:`length_m` included [m]."""
        return np.r_[self._s0, self.length_m]

    def curvature(self, s_m) -> np.ndarray:
        """Plan curvature ``dpsi/ds`` [1/m], positive to the left."""
        _, seg, u = self._locate(s_m)
        return self._k0[seg] + self._dk[seg] * u

    def heading(self, s_m) -> np.ndarray:
        """Heading ``psi`` [rad], counter-clockwise from the global ``x`` axis."""
        _, seg, u = self._locate(s_m)
        return self._psi0[seg] + self._k0[seg] * u + 0.5 * self._dk[seg] * u**2

    def superelevation(self, s_m) -> np.ndarray:
        """Signed superelevation ``h`` [m]: height of the left rail over the right one."""
        _, seg, u = self._locate(s_m)
        return self._superelevation(seg, u)[0]

    def _superelevation(self, seg, u):
        """``h`` [m] and its first two derivatives at ``u`` [m] into segments ``seg``."""
        return cant_ramp_values(self._h0[seg], self._dh[seg], self._L[seg], self._smooth[seg], u)

    def cant_angle(self, s_m) -> np.ndarray:
        """Cant angle ``phi = arcsin(h / cant_base_m)`` [rad], positive lifting the left rail."""
        return np.arcsin(self.superelevation(s_m) / self.cant_base_m)

    def _fields(self, s_m, segment=None):
        s, seg, u = self._locate(s_m, segment)
        k, dk = self._k0[seg] + self._dk[seg] * u, self._dk[seg]
        psi = self._psi0[seg] + self._k0[seg] * u + 0.5 * dk * u**2
        h, dh, d2h = self._superelevation(seg, u)
        b = self.cant_base_m
        root = np.sqrt(b * b - h * h)
        phi = np.arcsin(h / b)
        dphi = dh / root
        d2phi = d2h / root + dh * dh * h / root**3
        # Plan position from the panel start (the last panel of the segment at a left limit).
        p = np.minimum(np.searchsorted(self._panel_s, s, side="right"),
                       np.searchsorted(self._panel_seg, seg, side="right")) - 1
        p = np.maximum(p, 0)
        ua = self._panel_s[p] - self._s0[seg]
        d = u - ua
        psia = self._psi0[seg] + self._k0[seg] * ua + 0.5 * dk * ua**2
        # Lines and arcs: the exact chord; clothoids: Gauss-Legendre over the panel.
        chord = d * np.sinc(k * d / (2 * np.pi))
        mid = psia + 0.5 * k * d
        step = np.stack([chord * np.cos(mid), chord * np.sin(mid)], axis=1)
        cl = dk != 0.0
        if cl.any():
            half = 0.5 * d[cl]
            g = ua[cl][:, None] + half[:, None] * (1.0 + _GL_X)
            ang = self._psi0[seg[cl]][:, None] + self._k0[seg[cl]][:, None] * g + 0.5 * dk[cl][:, None] * g**2
            step[cl] = half[:, None] * np.stack([np.cos(ang) @ _GL_W, np.sin(ang) @ _GL_W], axis=1)
        xy = self._panel_xy[p] + step
        return s, xy, psi, k, dk, h, dh, phi, dphi, d2phi, d2h

    # ----------------------------------------------------------------- frames
    def _frames(self, s_m, side: str | None, segment=None):
        s, xy, psi, k, dk, h, dh, phi, dphi, d2phi, d2h = self._fields(s_m, segment)
        n = s.size
        g = self.gradient
        cp, sp = np.cos(psi), np.sin(psi)
        P = np.column_stack([xy, self._p0[2] + g * s])
        dP = np.column_stack([cp, sp, np.full(n, g)])
        d2P = np.column_stack([-k * sp, k * cp, np.zeros(n)])
        ct, st = math.cos(self._theta), math.sin(self._theta)
        A0 = np.zeros((n, 3, 3))  # Rz(psi) Ry(-theta)
        A0[:, 0, 0], A0[:, 0, 1], A0[:, 0, 2] = cp * ct, -sp, -cp * st
        A0[:, 1, 0], A0[:, 1, 1], A0[:, 1, 2] = sp * ct, cp, -sp * st
        A0[:, 2, 0], A0[:, 2, 2] = st, ct
        KA0 = _KZ @ A0
        dA0 = k[:, None, None] * KA0
        d2A0 = dk[:, None, None] * KA0 + (k * k)[:, None, None] * (_KZ @ KA0)
        # Offset w of the frame origin from P in the un-canted cross-section (and its derivatives).
        w = np.zeros((n, 3))
        dw = np.zeros((n, 3))
        d2w = np.zeros((n, 3))
        if self.cant_pivot == "low_rail":
            b = self.cant_base_m
            sg = np.where(h != 0.0, np.sign(h), np.sign(dh))
            c = np.cos(phi)
            w[:, 1], w[:, 2] = -sg * 0.5 * b * (1.0 - c), 0.5 * np.abs(h)
            dw[:, 1], dw[:, 2] = -sg * 0.5 * b * np.sin(phi) * dphi, 0.5 * sg * dh
            d2w[:, 1], d2w[:, 2] = -sg * 0.5 * b * (c * dphi**2 + np.sin(phi) * d2phi), 0.5 * sg * d2h
        beta = 0.0
        if side is not None:
            sign = 1.0 if side == "left" else -1.0
            beta = sign * self.inclination_rad
            q = np.zeros((n, 3))
            dq = np.zeros((n, 3))
            d2q = np.zeros((n, 3))
            q[:, 1] = sign * self.rail_offset_m
            if self.irregularities is not None:
                for order, arr in enumerate((q, dq, d2q)):
                    a, v, cl, ga = self.irregularities.evaluate(s, order).T
                    arr[:, 1] += a + sign * 0.5 * ga
                    arr[:, 2] += v + sign * 0.5 * cl
            Rx = _rot_x(phi)
            Rq = np.einsum("nij,nj->ni", Rx, q)
            KRq = Rq @ _KX.T
            KKRq = KRq @ _KX.T
            Rdq = np.einsum("nij,nj->ni", Rx, dq)
            w = w + Rq
            dw = dw + dphi[:, None] * KRq + Rdq
            d2w = (d2w + d2phi[:, None] * KRq + (dphi**2)[:, None] * KKRq + 2 * dphi[:, None] * (Rdq @ _KX.T)
                   + np.einsum("nij,nj->ni", Rx, d2q))
        R = P + _mv(A0, w)
        dR = dP + _mv(dA0, w) + _mv(A0, dw)
        d2R = d2P + _mv(d2A0, w) + 2 * _mv(dA0, dw) + _mv(A0, d2w)
        A = A0 @ _rot_x(phi + beta)
        AK = A @ _KX
        dA = k[:, None, None] * (_KZ @ A) + dphi[:, None, None] * AK
        d2A = (dk[:, None, None] * (_KZ @ A) + k[:, None, None] * (_KZ @ dA) + d2phi[:, None, None] * AK
               + dphi[:, None, None] * (dA @ _KX))
        return RailFrame(R, dR, d2R, A, dA, d2A)

    def track_frame(self, s_m) -> RailFrame:
        """The canted track frame at ``s_m`` [m]: origin on the centreline, columns tangent,
        lateral (left), up; with derivatives (the ``R`` fields hold the centreline)."""
        return self._frames(s_m, None)

    def rail_frame(self, s_m, side: str) -> RailFrame:
        """The rail profile frame ``(R^rp, A^rp)`` of rail ``side`` (``"left"``/``"right"``) at
        ``s_m`` [m] and its first and second derivatives with respect to ``s``."""
        if side not in SIDES:
            raise ParameterError(f"side={side!r}: must be 'left' or 'right'")
        return self._frames(s_m, side)

    def surface_point(self, s_m, side: str, y_m, z_m) -> np.ndarray:
        """Global position [m] of the rail surface point with profile coordinates ``(y_m, z_m)``
        (profile frame of :mod:`.profiles`: ``y`` toward the field side) at ``s_m`` [m]: eq. (19)
        with ``R^r = 0``, ``A^r = I``; shape ``(n, 3)``."""
        f = self.rail_frame(s_m, side)
        y = np.broadcast_to(np.asarray(y_m, float), f.R.shape[:1])
        z = np.broadcast_to(np.asarray(z_m, float), f.R.shape[:1])
        u = np.column_stack([np.zeros_like(y), (1.0 if side == "left" else -1.0) * y, z])
        return f.R + np.einsum("nij,nj->ni", f.A, u)

    # ----------------------------------------------------------------- piecewise cubics
    def piece_breaks(self, piece_length_m: float = 1.0) -> np.ndarray:
        """Ends of the pieces [m]: each segment cut into equal pieces no longer than
        ``piece_length_m``, so the segment joins are piece ends."""
        h = _positive("piece_length_m", piece_length_m)
        parts = [np.linspace(s0, s0 + L, max(int(math.ceil(L / h - 1e-9)), 1) + 1)[:-1]
                 for s0, L in zip(self._s0, self._L)]
        return np.r_[np.concatenate(parts), self.length_m]

    def piece_table(self, side: str, piece_length_m: float = 1.0):
        """Cubic Hermite pieces of the frame of rail ``side`` along the whole track.

        Returns
        -------
        breaks : ndarray (m + 1,)
            Piece ends [m] (:meth:`piece_breaks`).
        position_coeffs : ndarray (m, 4, 3)
        orientation_coeffs : ndarray (m, 4, 3, 3)
            Ascending powers of ``s - breaks[i]`` on piece ``i`` (as :class:`FramePiece`).
        """
        if side not in SIDES:
            raise ParameterError(f"side={side!r}: must be 'left' or 'right'")
        x = self.piece_breaks(piece_length_m)
        seg = np.clip(np.searchsorted(self._s0, x[:-1], side="right") - 1, 0, len(self._L) - 1)
        a = self._frames(x[:-1], side, seg)
        b = self._frames(x[1:], side, seg)  # left limits at the far end
        hh = np.diff(x)
        return x, _hermite(a.R, a.dR_ds, b.R, b.dR_ds, hh), _hermite(a.A, a.dA_ds, b.A, b.dA_ds, hh)

    def piece(self, s_m: float, side: str, piece_length_m: float = 1.0) -> FramePiece:
        """The cubic piece of the rail ``side`` frame holding ``s_m`` [m] (see :meth:`piece_table`)."""
        if side not in SIDES:
            raise ParameterError(f"side={side!r}: must be 'left' or 'right'")
        x = self.piece_breaks(piece_length_m)
        s = float(self._locate(s_m)[0][0])
        i = int(np.clip(np.searchsorted(x, s, side="right") - 1, 0, len(x) - 2))
        seg = int(self._locate(x[i])[1][0])
        f = self._frames(np.array([x[i], x[i + 1]]), side, [seg, seg])
        h = np.array([x[i + 1] - x[i]])
        pc = _hermite(f.R[:1], f.dR_ds[:1], f.R[1:], f.dR_ds[1:], h)[0]
        oc = _hermite(f.A[:1], f.dA_ds[:1], f.A[1:], f.dA_ds[1:], h)[0]
        return FramePiece(float(x[i]), float(x[i + 1]), pc, oc)


def _mv(M, v):
    return np.einsum("nij,nj->ni", M, v)


def _rot_x(angle):
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(np.shape(angle) + (3, 3))
    out[..., 0, 0] = 1.0
    out[..., 1, 1], out[..., 1, 2] = c, -s
    out[..., 2, 1], out[..., 2, 2] = s, c
    return out


def _hermite(p0, m0, p1, m1, h):
    """Coefficients (ascending powers) of the cubic through values ``p`` and slopes ``m`` at
    ``t = 0`` and ``t = h``; the leading axis of the inputs runs over pieces."""
    h = h.reshape((-1,) + (1,) * (p0.ndim - 1))
    c2 = (3.0 * (p1 - p0) - h * (2.0 * m0 + m1)) / h**2
    c3 = (2.0 * (p0 - p1) + h * (m0 + m1)) / h**3
    return np.stack([p0, m0, c2, c3], axis=1)
