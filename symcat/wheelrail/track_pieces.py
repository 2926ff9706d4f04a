"""Rail profile frames of a constraint contact: tangent track, or cubic pieces of a curved track.

The wheel/rail kernels (:mod:`symcat.symbolic.wheelrail`) take the rail profile frame
``(R^rp, A^rp)`` at the contact's track parameter ``s1r`` either as the frame of tangent track
along global ``x`` (libraries ``wheelrail_*_rigid_ground``: :class:`TangentRailFrames`) or as one
cubic piece of a :class:`symcat.wheelrail.track.TrackLayout` (``wheelrail_*_rigid_track``:
:class:`TrackRailFrames`). Both classes give the contact-point solver the same view of the rail:
the kernel's track parameters at ``s1r``, the frame and its derivative along the track, the
canted track frame (for contact angles), the chainage of a global point (its cross-section), and
(curved track) the compiled lookup ``s1r -> piece`` for the multibody model.

Track pieces (SI units, conventions of :mod:`symcat.wheelrail.track`): the layout is cut at
:meth:`TrackLayout.piece_breaks` (segment joins included, ``piece_length_m`` at most); on each
piece the rail frame origin ``R^t``, the heading ``psi`` and the cant angle ``phi`` are the
cubic Hermite interpolants of the layout's exact values and slopes at the piece ends (``psi`` is
exactly quadratic, so exact), and the orientation is ``A^t = Rz(psi) Ry(-theta) Rx(phi)``, a
rotation. The rail inclination added by the layout is the kernel's ``roll`` (``side`` times
:attr:`TrackLayout.inclination_rad`); the origin offset ``(Y_o, Z_o)`` is zero (the layout's
rail frames already carry the rail offset, the low-rail cant pivot and irregularities).

Smoothness: the pieces are C1 where the layout's rail frames are, so ``C`` and ``C_s`` are
continuous across piece ends and ``Q_d`` jumps only where the layout's curvature rate does (the
ends of a clothoid). A smooth cant ramp (``Transition(..., cant_ramp="smooth")``) keeps the
rails C1. A linear superelevation ramp, however, has ends that are
kinks of the rails (the cant rate steps: the raised rail's slope drops by half the ramp's
gradient, 4 mrad for 80 mm over 10 m) and creases of the rail surfaces; a rigid constraint
contact crosses them as an impact. With the augmented formulation the driver's contact-jump
projection (:mod:`symcat.wheelrail_events.contact_jumps`) carries the run over; the embedded
formulation, whose surface parameters are algebraic, stops there (IDAS failure).
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from symcat.errors import ParameterError

from .geometry import TrackCrossSection, gauge_point
from .track import TrackLayout, _hermite

SIDES = {"left": 1.0, "right": -1.0}
#: Kernel track parameters per piece: st0, origin (4 x 3), heading (4), cant angle (4), gradient.
N_PIECE = 22


def _cant_rate_steps(layout: TrackLayout) -> np.ndarray:
    """Interior segment joins [m] of ``layout`` where the superelevation's slope changes (the ends
    of linear cant ramps; a smooth ramp starts and ends at zero slope)."""
    n = len(layout.segments)
    if n < 2:
        return np.zeros(0)
    seg = np.arange(n)
    _, rate_end, _ = layout._superelevation(seg, layout._L.copy())
    _, rate_start, _ = layout._superelevation(seg, np.zeros(n))
    step = np.abs(rate_start[1:] - rate_end[:-1])
    return layout.joins_m[1:-1][step > 1e-12]


def interval_lookup(breaks, rows, name: str, arg: str = "i0", out: str = "o0") -> ca.Function:
    """SX function ``s -> rows[k]`` for ``breaks[k] <= s < breaks[k + 1]`` (the first and last
    rows extend beyond the ends): the sum of every row times the indicator of its interval, which
    expands to SX and compiles (its derivative is zero)."""
    s = ca.SX.sym(arg)
    rows = np.asarray(rows, float)
    n = len(rows)
    value = ca.SX.zeros(rows.shape[1])
    for k in range(n):
        below = s >= breaks[k] if k > 0 else 1
        above = s < breaks[k + 1] if k < n - 1 else 1
        value += below * above * ca.DM(rows[k])
    return ca.Function(name, [s], [value], [arg], [out])


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


class TangentRailFrames:
    """Rail profile frame of tangent track along global ``x`` (the ``_ground`` kernels).

    Parameters
    ----------
    rail : Profile
        Rail profile (``y`` toward the field side).
    side : {"left", "right"}
    cross_section : TrackCrossSection
        Gauge, gauge depth and rail inclination.
    cant_rad : float
        Cant of the whole cross-section about the track centre line [rad].
    """

    kind = "ground"

    def __init__(self, rail, side: str, cross_section: TrackCrossSection, cant_rad: float = 0.0):
        self.sign = SIDES[side]
        self.cross_section = cross_section
        self.cant_rad = float(cant_rad)
        incl = cross_section.rail_inclination_rad
        extra = 0.0 if incl is None else incl - rail.inclination_rad
        installed = rail.transformed(extra) if extra else rail
        offset = 0.5 * cross_section.gauge_m - gauge_point(installed, cross_section.gauge_depth_m)[0]
        #: Profile origin in the cross-section [m] and roll of the profile plane [rad].
        self.origin_m = rot_x(self.cant_rad) @ np.array([0.0, self.sign * offset, 0.0])
        self.roll_rad = self.cant_rad + self.sign * extra
        self.head = np.array([self.origin_m[1], self.origin_m[2], self.roll_rad])
        #: Chainages of the rails' kinks [m]: none on tangent track.
        self.kinks_m = np.zeros(0)

    def params(self, s1r: float, clip: bool = False) -> np.ndarray:
        """Track parameters of the kernel beyond the head (none on tangent track)."""
        return np.zeros(0)

    def frames(self, s1r):
        """``(R, A, dR, dA)`` of the rail profile frame at chainages ``s1r`` (shape ``(n, ...)``)."""
        s = np.atleast_1d(np.asarray(s1r, float))
        n = s.size
        R = np.column_stack([s, np.full(n, self.origin_m[1]), np.full(n, self.origin_m[2])])
        A = np.broadcast_to(rot_x(self.roll_rad), (n, 3, 3))
        dR = np.broadcast_to(np.array([1.0, 0.0, 0.0]), (n, 3))
        return R, A, dR, np.zeros((n, 3, 3))

    def track_axes(self, s1r) -> np.ndarray:
        """Canted track frame (columns tangent, lateral, up) at ``s1r``, shape ``(3, 3)``."""
        return rot_x(self.cant_rad)

    def up(self, s1r) -> np.ndarray:
        """Direction in which a wheel's lowest point is sought: global ``z``."""
        return np.array([0.0, 0.0, 1.0])

    def project(self, points: np.ndarray, guess=None) -> np.ndarray:
        """Chainage of the cross-sections through global ``points`` (n, 3)."""
        return np.asarray(points, float)[:, 0].copy()

    def check(self, s1r: float) -> None:
        """Tangent track has no ends."""


class TrackRailFrames:
    """Cubic pieces of the rail frame of one rail of a track layout (the ``_track`` kernels).

    Parameters
    ----------
    layout : TrackLayout
    side : {"left", "right"}
    piece_length_m : float
        Longest piece [m] (the frame error of a piece grows as its length to the fourth power:
        about ``1e-12`` m for 1 m pieces on a 300 m curve).

    Raises
    ------
    ParameterError
        For a layout that is not a :class:`TrackLayout` or a bad side or piece length.
    """

    kind = "track"

    def __init__(self, layout: TrackLayout, side: str, piece_length_m: float = 1.0):
        if not isinstance(layout, TrackLayout):
            raise ParameterError(f"track={layout!r}: must be a TrackLayout")
        if side not in SIDES:
            raise ParameterError(f"side={side!r}: must be 'left' or 'right'")
        self.layout = layout
        self.side = side
        self.sign = SIDES[side]
        x = layout.piece_breaks(piece_length_m)
        seg = layout.segment_index(x[:-1])
        h = np.diff(x)
        # Both ends in the segment of the piece start (left limits at the far end).
        fa, fb = layout._fields(x[:-1], seg), layout._fields(x[1:], seg)
        ra, rb = layout.rail_frame(x[:-1], side), layout._frames(x[1:], side, seg)
        origin = _hermite(ra.R, ra.dR_ds, rb.R, rb.dR_ds, h)                       # (m, 4, 3)
        psi = _hermite(fa[2], fa[3], fb[2], fb[3], h)                              # (m, 4)
        phi = _hermite(fa[7], fa[8], fb[7], fb[8], h)
        self.breaks_m = x
        self.length_m = layout.length_m
        self.theta_rad = float(layout._theta)
        self.table = np.column_stack([x[:-1], origin.reshape(len(h), 12), psi, phi, np.full(len(h), self.theta_rad)])
        self.head = np.array([0.0, 0.0, self.sign * layout.inclination_rad])
        self.roll_rad = float(self.head[2])
        #: Chainages of the rails' kinks [m]: the segment joins where the cant rate steps (the
        #: ends of linear cant ramps), crossed as impacts.
        self.kinks_m = _cant_rate_steps(layout)

    # ------------------------------------------------------------------ pieces
    def index(self, s1r, clip: bool = False) -> np.ndarray:
        """Piece index of each chainage ``s1r`` [m].

        Raises
        ------
        ParameterError
            If ``s1r`` leaves the track (unless ``clip``: the end pieces then extend it).
        """
        s = np.atleast_1d(np.asarray(s1r, float))
        if not clip:
            self.check(s)
        return np.clip(np.searchsorted(self.breaks_m, s, side="right") - 1, 0, len(self.table) - 1)

    def check(self, s1r) -> None:
        """Raise :class:`ParameterError` if any chainage ``s1r`` [m] lies off the track."""
        s = np.atleast_1d(np.asarray(s1r, float))
        bad = ~((s >= -1e-9) & (s <= self.length_m + 1e-9))
        if bad.any():
            raise ParameterError(f"s1r={s[bad][0]:.6g} m: the {self.side} rail's contact point leaves the track, "
                                 f"defined for 0 <= s1r <= {self.length_m:.6g} m (lengthen the layout)")

    def params(self, s1r: float, clip: bool = False) -> np.ndarray:
        """The kernel's track piece (22 parameters) holding ``s1r`` [m]."""
        return self.table[int(self.index(s1r, clip)[0])].copy()

    def lookup(self, name: str) -> ca.Function:
        """SX function ``s1r -> track piece (22)``: the sum of every piece's row times the
        indicator of its interval (the end pieces extend the track), as the profiles' pieces are
        picked (:func:`symcat.assembly.wheelrail.piece_lookup`). Its derivative is zero; unlike a
        binary search with a symbolic index (``casadi.low``), it expands to SX, so that a model
        on a track layout compiles whole (:mod:`symcat.codegen.model_dae`)."""
        return interval_lookup(self.breaks_m, self.table, name, "s1r", "piece")

    # ------------------------------------------------------------------ frames
    def _pieces(self, s):
        i = self.index(s, clip=True)
        c = self.table[i]
        t = s - c[:, 0]
        return t, c[:, 1:13].reshape(-1, 4, 3), c[:, 13:17], c[:, 17:21]

    def _axes(self, psi, phi):
        cp, sp_, ct, st = np.cos(psi), np.sin(psi), math.cos(self.theta_rad), math.sin(self.theta_rad)
        a0 = np.zeros((len(psi), 3, 3))  # Rz(psi) Ry(-theta)
        a0[:, 0, 0], a0[:, 0, 1], a0[:, 0, 2] = cp * ct, -sp_, -cp * st
        a0[:, 1, 0], a0[:, 1, 1], a0[:, 1, 2] = sp_ * ct, cp, -sp_ * st
        a0[:, 2, 0], a0[:, 2, 2] = st, ct
        c, s = np.cos(phi), np.sin(phi)
        rx = np.zeros((len(phi), 3, 3))
        rx[:, 0, 0], rx[:, 1, 1], rx[:, 1, 2], rx[:, 2, 1], rx[:, 2, 2] = 1.0, c, -s, s, c
        return a0 @ rx

    def track_frames(self, s1r):
        """``(R^t, A^t, dR^t/ds, dA^t/ds)`` of the pieces at chainages ``s1r`` [m] (vectorised)."""
        s = np.atleast_1d(np.asarray(s1r, float))
        t, pc, psc, phc = self._pieces(s)
        pw = np.stack([np.ones_like(t), t, t**2, t**3], axis=1)
        dw = np.stack([np.zeros_like(t), np.ones_like(t), 2 * t, 3 * t**2], axis=1)
        R, dR = np.einsum("nk,nki->ni", pw, pc), np.einsum("nk,nki->ni", dw, pc)
        psi, dpsi = np.sum(pw * psc, axis=1), np.sum(dw * psc, axis=1)
        phi, dphi = np.sum(pw * phc, axis=1), np.sum(dw * phc, axis=1)
        A = self._axes(psi, phi)
        kz = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
        kx = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
        dA = dpsi[:, None, None] * (kz @ A) + dphi[:, None, None] * (A @ kx)
        return R, A, dR, dA

    def frames(self, s1r):
        """``(R, A, dR, dA)`` of the rail profile frame at ``s1r`` [m] (as the kernel)."""
        R, A, dR, dA = self.track_frames(s1r)
        roll = rot_x(self.roll_rad)
        return R, A @ roll, dR, dA @ roll

    def track_axes(self, s1r) -> np.ndarray:
        """Canted track frame (columns tangent, lateral, up) at ``s1r`` [m], shape ``(3, 3)``."""
        return self.track_frames(s1r)[1][0]

    def up(self, s1r) -> np.ndarray:
        """Normal to the running plane at ``s1r`` [m] (a wheel's lowest point is sought along it)."""
        return self.track_axes(s1r)[:, 2]

    def project(self, points: np.ndarray, guess=None) -> np.ndarray:
        """Chainage of the cross-sections (planes normal to the track tangent through the rail
        frame origin) holding global ``points`` (n, 3) [m]: Newton from ``guess`` or from the
        nearest piece start in plan; the result may lie off the track (see :meth:`check`)."""
        p = np.atleast_2d(np.asarray(points, float))
        if guess is None:
            starts = self.table[:, 1:4]  # R^t at the piece starts
            d2 = ((p[:, None, :2] - starts[None, :, :2]) ** 2).sum(axis=2)
            s = self.breaks_m[np.argmin(d2, axis=1)]
        else:
            s = np.broadcast_to(np.asarray(guess, float), p.shape[:1]).copy()
        for _ in range(20):
            R, A, dR, dA = self.track_frames(s)
            rel, tan, dtan = p - R, A[:, :, 0], dA[:, :, 0]
            f = np.einsum("ni,ni->n", rel, tan)
            df = np.einsum("ni,ni->n", rel, dtan) - np.einsum("ni,ni->n", dR, tan)
            step = -f / df
            s = s + step
            if np.abs(step).max() < 1e-12:
                break
        return s


def cross_section_of(layout: TrackLayout, rail, gauge_depth_m: float = 0.014) -> TrackCrossSection:
    """The :class:`TrackCrossSection` that places ``rail`` where ``layout`` does (its rail offset
    and inclination): for the 2D contact geometry of a wheelset on that track."""
    extra = layout.inclination_rad
    installed = rail.transformed(extra) if extra else rail
    gauge = 2.0 * (layout.rail_offset_m + float(gauge_point(installed, gauge_depth_m)[0]))
    return TrackCrossSection(gauge_m=gauge, gauge_depth_m=gauge_depth_m,
                             rail_inclination_rad=(rail.inclination_rad + extra) if extra else None)


def rail_frames(rail, side: str, track=None, cant_rad: float = 0.0, piece_length_m: float = 1.0):
    """The rail frames of a contact: :class:`TrackRailFrames` for a :class:`TrackLayout`,
    :class:`TangentRailFrames` for a :class:`TrackCrossSection` or ``None``.

    Raises
    ------
    ParameterError
        For another ``track``, or a ``cant_rad`` together with a layout (its cant is the layout's).
    """
    if isinstance(track, TrackLayout):
        if cant_rad:
            raise ParameterError(f"cant_rad={cant_rad!r}: a TrackLayout carries its own cant (Curve.cant_m); "
                                 "leave cant_rad at 0")
        return TrackRailFrames(track, side, piece_length_m)
    if track is not None and not isinstance(track, TrackCrossSection):
        raise ParameterError(f"track={track!r}: must be a TrackCrossSection (tangent track), a TrackLayout "
                             "(curved track) or None")
    return TangentRailFrames(rail, side, track or TrackCrossSection(), cant_rad)
