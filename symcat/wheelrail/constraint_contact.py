"""Constraint contact of one wheel of a rigid wheelset on its rail (seed eqs. 15-22), at run time.

The compiled kernels ``wheelrail_global_rigid_*`` (eq. 21) and ``wheelrail_railframe_rigid_*``
(eq. 22) are exact on one cubic piece of each profile (and of the track; see
:mod:`symcat.symbolic.wheelrail` for the surfaces, frames and parameter layout). This module
picks the pieces that contain the current surface parameters, passes their coefficients and
evaluates ``C``, ``C_q``, ``C_s``, ``C_t`` and ``Q_d``; and it locates the contact point of a
given wheelset position (the geometric solve of the embedded formulation) by Newton's method.

Frames (as :mod:`.geometry`, extended to 3D): on tangent track global ``x`` along the track,
``y`` toward the left rail, ``z`` up, origin on the track centre line at rail-top level; on a
layout its global frame (:mod:`.track`). Wheelset coordinates
``q = [R, theta]``: ``R`` the axle centre (m), ``theta`` Euler parameters, axle along the body
``y`` axis. Surface parameters ``s = [s1w, s2w, s1r, s2r]``: wheel profile parameter (m), angle
about the axle from the bottom of the wheel (rad, positive toward body ``+x``), distance along
the track (m; a layout's chainage), rail profile parameter (m).

Tangent track (a :class:`.geometry.TrackCrossSection`, libraries ``*_rigid_ground``): the rail
profile frame is ``R^rp = [s1r, Y_o, Z_o]``, ``A^rp = R_x(cant + side * (inclination - built-in
inclination))``. Curved track (a :class:`.track.TrackLayout`, libraries ``*_rigid_track``):
``s1r`` is the layout's chainage and the frame is the cubic track piece holding it
(:mod:`.track_pieces`), passed to the kernel like the profile pieces; ``s1r`` must stay on the
layout (0 to its length).
"""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np

from symcat.errors import ParameterError, SolverError

from .contact_point import ContactPoint, solve_small
from .geometry import TrackCrossSection, WheelsetDimensions
from .profiles import Profile
from .track_pieces import rail_frames

SIDES = {"left": 1.0, "right": -1.0}
FORMS = ("global", "railframe")
N_PARAMS = 24  # tangent track; curved track adds the 22 parameters of a track piece
#: Largest Newton step per surface parameter: s1w, s2w, s1r, s2r [m, rad, m, m].
MAX_STEP = np.array([2e-3, 0.02, 5e-3, 2e-3])
_CONDITION_ROWS = np.array([0, 1, 3, 4])  # rail-frame form: all rows but the gap


def library_name(form: str, track: str = "ground") -> str:
    """Kernel library of a constraint form (``"global"``: eq. 21, ``"railframe"``: eq. 22) on
    tangent (``track="ground"``) or curved track (``"track"``)."""
    if form not in FORMS:
        raise ParameterError(f"form={form!r}: must be one of {', '.join(FORMS)}")
    return f"wheelrail_{form}_rigid_{track}"


@dataclass
class ContactKernels:
    """Constraint values and derivatives at one state (5 rows each).

    Attributes
    ----------
    c : ndarray (5,)
        Constraint values (m for the point rows, - for the tangency rows).
    C_q : ndarray (5, 7)
        Jacobian with respect to the wheelset coordinates ``[R, theta]``.
    C_s : ndarray (5, 4)
        Jacobian with respect to the surface parameters.
    C_t : ndarray (5,)
        Partial time derivative (zero: the rail is fixed).
    Q_d : ndarray (5,)
        ``d2C/dt2 - C_q q_ddot - C_s s_ddot`` (quadratic velocity terms, seed eq. 14).
    """

    c: np.ndarray
    C_q: np.ndarray
    C_s: np.ndarray
    C_t: np.ndarray
    Q_d: np.ndarray | None = None


class WheelRailContact:
    """One wheel/rail contact of a rigid wheelset on tangent or curved track (constraint formulation).

    Parameters
    ----------
    wheel, rail : Profile
        Wheel and rail profiles in the frames of :mod:`.profiles` (the same profiles serve either
        side: they are mirrored on the right, as in :mod:`.geometry`).
    side : str
        ``"left"`` (wheel on the body ``+y`` end of the axle, rail to the left of the track) or
        ``"right"``.
    wheelset : WheelsetDimensions, optional
        Tape-circle distance and nominal rolling radius (default 1.5 m, 0.46 m).
    track : TrackCrossSection or TrackLayout, optional
        Tangent track along global ``x``: gauge, gauge depth and rail inclination (default 1.435 m,
        14 mm, as built into the rail profile; the rails are placed exactly as by
        :func:`.geometry.contact_geometry`). Curved track: a :class:`.track.TrackLayout`, whose
        rail frames (rail offset, inclination, cant, irregularities) place the rail; give it
        ``rail_offset_m=rail_offset_for(rail)`` for this rail profile's gauge.
    cant_rad : float
        Cant of tangent track: rotation of the whole cross-section about the track centre line
        [rad], positive raising the left rail (a layout has its own cant: must be 0 then).
    form : str
        ``"railframe"`` (eq. 22, default) or ``"global"`` (eq. 21).
    track_piece_length_m : float
        Longest cubic track piece on curved track [m].

    Raises
    ------
    ParameterError
        For a bad side, form, profile, dimension, cant or track.
    """

    def __init__(self, wheel: Profile, rail: Profile, side: str, *, wheelset: WheelsetDimensions | None = None,
                 track=None, cant_rad: float = 0.0, form: str = "railframe", track_piece_length_m: float = 1.0):
        if side not in SIDES:
            raise ParameterError(f"side={side!r}: must be 'left' or 'right'")
        for prof, kind in ((wheel, "wheel"), (rail, "rail")):
            if not isinstance(prof, Profile) or prof.kind != kind:
                raise ParameterError(f"{kind}={prof!r}: must be a {kind} Profile")
        if not (isinstance(cant_rad, (int, float)) and abs(cant_rad) < 0.3):
            raise ParameterError(f"cant_rad={cant_rad!r}: must be a number with |cant_rad| < 0.3 rad")
        self.wheelset = wheelset or WheelsetDimensions()
        checks = [("tape_circle_distance_m", self.wheelset.tape_circle_distance_m),
                  ("nominal_radius_m", self.wheelset.nominal_radius_m)]
        if track is None or isinstance(track, TrackCrossSection):
            checks.append(("gauge_m", (track or TrackCrossSection()).gauge_m))
        for label, value in checks:
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ParameterError(f"{label}={value!r}: must be a number > 0")
        self.side = side
        self.sign = SIDES[side]
        self.wheel, self.rail = wheel, rail
        self.cant_rad = float(cant_rad)
        #: The rail frames: :class:`.track_pieces.TangentRailFrames` or ``TrackRailFrames``.
        self.frames = rail_frames(rail, side, track, self.cant_rad, track_piece_length_m)
        self.track = track if track is not None else TrackCrossSection()
        self.curved = self.frames.kind == "track"
        self.form = form
        self.library = library_name(form, self.frames.kind)
        self._wpp = wheel.piecewise_polynomial()
        self._rpp = rail.piecewise_polynomial()
        self._head = np.r_[self.sign, self.wheelset.nominal_radius_m, 0.5 * self.wheelset.tape_circle_distance_m,
                           self.frames.head]
        # Breakpoints as lists (bisect on a float is 10x faster than np.searchsorted) and the
        # kernel parameters of each profile piece: start and the coefficients of y and z.
        self._wx, self._rx = self._wpp.x.tolist(), self._rpp.x.tolist()
        self._wheel_rows, self._rail_rows = _piece_rows(self._wpp), _piece_rows(self._rpp)
        self._kernels = None
        self._buffered = {}
        # Newton's bounds on the surface parameters, and (tangent track) the kernel parameters
        # of each pair of profile pieces met so far.
        self._lo = np.array([wheel.s_min, -math.pi, -np.inf, rail.s_min])
        self._hi = np.array([wheel.s_max, math.pi, np.inf, rail.s_max])
        self._param_rows = {} if not self.curved else None

    # ------------------------------------------------------------------ kernels
    @property
    def kernels(self):
        if self._kernels is None:
            from symcat.codegen.library import kernel_library

            self._kernels = kernel_library(self.library)
        return self._kernels

    def _kernel(self, suffix: str):
        """The kernel ``<library>_<suffix>`` as a :class:`BufferedFunction` (one per contact:
        it owns its buffers)."""
        f = self._buffered.get(suffix)
        if f is None:
            from symcat.codegen.library import BufferedFunction, fused

            names = [f"{self.library}_{part}" for part in suffix.split("_")]  # "c_jac": one call for both
            f = self._buffered[suffix] = BufferedFunction(fused([self.kernels[n] for n in names]))
        return f

    @staticmethod
    def _piece(x: list, s: float, label: str, profile: Profile, clip: bool) -> int:
        """Index of the piece of breakpoints ``x`` holding ``s`` (the end pieces extend them)."""
        if not clip and not (x[0] - 1e-9 <= s <= x[-1] + 1e-9):
            raise ParameterError(f"{label}={s:.6g} m: outside the {profile.kind} profile {profile.name!r} "
                                 f"(allowed {x[0]:.6g} to {x[-1]:.6g} m)")
        return min(max(bisect.bisect_right(x, s) - 1, 0), len(x) - 2)

    def _check_inside(self, s) -> None:
        """Raise :class:`ParameterError` if ``s`` leaves a profile or the track (as
        :meth:`parameters` without ``clip``)."""
        self._piece(self._wx, s[0], "s1w", self.wheel, False)
        self._piece(self._rx, s[3], "s2r", self.rail, False)
        self.frames.check(s[2])

    def parameters(self, s, *, pieces: tuple[int, int] | None = None, clip: bool = False) -> np.ndarray:
        """Kernel parameters (24, curved track 46) for surface parameters ``s``: the spline pieces
        containing ``s1w`` and ``s2r`` (or the given ``pieces = (wheel, rail)`` indices) and the
        track piece containing ``s1r``.

        Raises
        ------
        ParameterError
            If a parameter leaves its profile or the track (unless ``clip``: end pieces extend them).
        """
        return np.array(self._parameters(s, pieces, clip))

    def _parameters(self, s, pieces=None, clip: bool = False) -> np.ndarray:
        """:meth:`parameters`, on tangent track a read-only array shared by the calls that meet
        the same profile pieces (the kernels copy their inputs)."""
        s = np.asarray(s, float)
        if pieces is None:
            iw = self._piece(self._wx, s[0], "s1w", self.wheel, clip)
            ir = self._piece(self._rx, s[3], "s2r", self.rail, clip)
        else:
            iw, ir = pieces
        if self._param_rows is None:
            track = self.frames.params(s[2], clip)
            return np.concatenate((self._head, self._wheel_rows[iw], self._rail_rows[ir], track))
        row = self._param_rows.get((iw, ir))
        if row is None:
            row = self._param_rows[iw, ir] = np.concatenate((self._head, self._wheel_rows[iw], self._rail_rows[ir]))
            row.flags.writeable = False
        return row

    def residual(self, q, s, t: float = 0.0, **kw) -> np.ndarray:
        """The five constraints ``C(q, s)``."""
        y = np.concatenate((np.asarray(q, float), np.asarray(s, float)))
        return self._kernel("c")(y, t, self._parameters(s, **kw))[0].ravel()

    def gap(self, q, s, kernels=None) -> float:
        """Normal gap (m) at surface parameters ``s`` as they are (no solve): the gap row of
        eq. 22, or the rail-normal component of eq. 21's distance rows. ``kernels``:
        :meth:`evaluate`'s at ``(q, s)`` (with ``clip``), if at hand."""
        k = self.evaluate(q, s, clip=True) if kernels is None else kernels
        if self.form == "railframe":
            return float(k.c[2])
        return float(self._normal_from_jacobian(k.C_s) @ k.c[:3])

    def evaluate(self, q, s, q_dot=None, s_dot=None, t: float = 0.0, **kw) -> ContactKernels:
        """``C``, ``C_q``, ``C_s``, ``C_t`` and (with velocities) ``Q_d`` at one state."""
        q, s = np.asarray(q, float), np.asarray(s, float)
        if q.shape != (7,) or s.shape != (4,):
            raise ParameterError(f"q, s: shapes {q.shape}, {s.shape}; must be (7,) and (4,)")
        y = np.concatenate((q, s))
        p = self._parameters(s, **kw)
        c, c_y, c_t = self._kernel("c_jac")(y, t, p)
        c = c.ravel()
        q_d = None
        if q_dot is not None or s_dot is not None:
            y_dot = np.r_[np.zeros(7) if q_dot is None else q_dot, np.zeros(4) if s_dot is None else s_dot]
            q_d = self._kernel("gamma")(y, y_dot, t, p)[0].ravel()
        return ContactKernels(c, c_y[:, :7], c_y[:, 7:], c_t.ravel(), q_d)

    # ------------------------------------------------------------------ contact point
    def initial_guess(self, q, grid_m: float = 5e-4) -> np.ndarray:
        """Surface parameters near the contact for small yaw: the cross-section approach of
        :mod:`.gap_search` in 3D. Each circle of the wheel (a ``s1w`` of a grid) contributes its
        lowest point (``s2w`` where the circle's tangent is normal to the ``up`` direction of the
        track at the axle: global ``z`` on tangent track, the running-plane normal on curved
        track), and the one with the smallest gap above the rail (measured along the rail
        profile's ``z`` in the cross-section through the point) is refined on finer grids to
        about 10 um.

        Raises
        ------
        SolverError
            If no wheel circle lies above the rail (wheelset off the rail).
        ParameterError
            If the axle centre lies off a curved track's defined length.
        """
        q = np.asarray(q, float)
        a = _rotation(q[3:7])
        s_axle = self.frames.project(q[None, :3])
        self.frames.check(s_axle)
        w = a.T @ self.frames.up(s_axle)
        s2w = math.atan2(-w[0], w[2])  # lowest point of every circle (no dependence on s1w)
        lo, hi = self.wheel.s_min, self.wheel.s_max
        n = max(int(math.ceil((hi - lo) / grid_m)), 8) + 1
        grid = np.linspace(lo, hi, n)
        best = None
        for _ in range(4):
            gap, s2r, s1r = self._vertical_gap(q, a, s2w, grid, s_axle)
            if not np.isfinite(gap).any():
                raise SolverError(f"{self.side} wheel: no point of the wheel lies above the rail at "
                                  f"q={np.array2string(q, precision=5)} (wheelset off the rail)")
            j = int(np.nanargmin(gap))
            best = (grid[j], s2r[j], s1r[j])
            h = grid[1] - grid[0]
            grid = np.linspace(max(grid[j] - h, lo), min(grid[j] + h, hi), 9)
        return np.array([best[0], s2w, best[2], best[1]])

    def local_minima(self, q, band_m: float = 2e-6, grid_m: float = 2.5e-4, near: float | None = None,
                     known: float | None = None) -> list[ContactPoint]:
        """Every local minimum of the gap along the wheel profile, lowest first
        (:func:`.gap_minima.gap_minima`)."""
        from .gap_minima import gap_minima

        return gap_minima(self, q, band_m, grid_m, near, known)

    def _vertical_gap(self, q, a, s2w, s1w, s_guess, pw=None):
        """Gap along the rail profile's ``z`` of the wheel points ``(s1w, s2w)``, the rail
        parameter below each, and the chainage of its cross-section. ``pw``: the wheel profile's
        points at ``s1w``, if at hand."""
        pw = self.wheel.position(s1w) if pw is None else pw
        rho = self._head[1] + pw[:, 1]
        u = np.stack([rho * np.sin(s2w), self.sign * (self._head[2] + pw[:, 0]), -rho * np.cos(s2w)])
        points = (q[:3, None] + a @ u).T
        s1r = self.frames.project(points, s_guess)
        R, A, _, _ = self.frames.frames(s1r)
        local = np.einsum("nji,nj->in", A, points - R)  # A^T (p - R) in the profile frame
        s2r, z_r = self.rail.envelope_at(self.sign * local[1])
        return local[2] - np.where(np.isfinite(s2r), z_r, np.nan), s2r, s1r

    def solve(self, q, s_guess=None, *, tol: float = 1e-13, max_iter: int = 40, local: bool = False) -> ContactPoint:
        """Contact point of the wheelset at ``q``: the four surface parameters from the two
        in-plane coincidence and two tangency conditions, and the normal gap (the fifth).

        Rail-frame form: Newton on rows 1, 2, 4, 5 of eq. 22, the gap is row 3. Global form:
        Newton on ``C - [g n; 0; 0] = 0`` for ``(s, g)`` (eq. 21 with the gap ``g`` along the
        rail normal ``n`` taken out), so both forms define the same point. Newton (with
        backtracking on the residual) starts from ``s_guess`` (e.g. the previous step's
        solution), else from :meth:`initial_guess` (the lowest point of the vertical-gap search),
        and, should it fail from ``s_guess`` (unless ``local``), once more from there. It returns
        the stationary point of the gap that Newton reaches: on nearly conformal profiles secondary
        minima lie within 0.2 um of the lowest one (without ``s_guess`` the lowest is found).

        Raises
        ------
        SolverError
            If Newton does not converge or the point leaves a profile.
        """
        q = np.asarray(q, float)
        if s_guess is not None:
            try:
                return self._newton(q, np.array(s_guess, float), tol, max_iter)
            except SolverError:
                if local:
                    raise
        return self._newton(q, self.initial_guess(q), tol, max_iter)

    def _newton(self, q, s, tol, max_iter) -> ContactPoint:
        lo, hi = self._lo, self._hi
        x = np.concatenate((s, [0.0]))  # surface parameters and (global form) the gap
        f, jac, k = self._conditions(q, x)
        res = float(np.abs(f).max())
        it = 0
        # A start within tol and the bounds (a point solved at a nearby state) takes no step.
        if res > tol or not ((x[:4] >= lo) & (x[:4] <= hi)).all():
            for it in range(1, max_iter + 1):
                try:
                    step = -solve_small(jac, f)
                except np.linalg.LinAlgError:
                    raise SolverError(f"{self.side} wheel: singular contact Jacobian C_s at s={x[:4]} (the wheel "
                                      "and rail tangent planes cannot be matched there)") from None
                if step.size == 4:
                    step = np.concatenate((step, [0.0]))
                scale = min(1.0, float(np.min(MAX_STEP / np.maximum(np.abs(step[:4]), 1e-300))))
                # Backtracking on |f|: Newton on the stationarity conditions may overshoot where the
                # profiles are nearly conformal.
                alpha = scale
                for _ in range(12):
                    x_new = np.concatenate((np.minimum(np.maximum(x[:4] + alpha * step[:4], lo), hi),  # np.clip, faster
                                            [x[4] + alpha * step[4]]))
                    f_new, jac_new, k_new = self._conditions(q, x_new)
                    res_new = float(np.abs(f_new).max())
                    if res_new <= (1 - 1e-4 * alpha) * res or res_new <= tol:
                        break
                    alpha *= 0.5
                x, f, jac, k, res = x_new, f_new, jac_new, k_new, res_new
                if res <= tol or (alpha == 1.0 and np.abs(step[:4]).max() < 1e-14):
                    break
            else:
                raise SolverError(f"{self.side} wheel: contact point not found in {max_iter} Newton iterations "
                                  f"(residual {res:.3g}) at q={np.array2string(q, precision=5)}")
        s = x[:4]
        # k are the kernels at s; their pieces are those of an unclipped evaluation unless the
        # point left a profile or the track.
        self._check_inside(s)
        if self.form == "railframe":
            gap, res = float(k.c[2]), float(np.abs(k.c[_CONDITION_ROWS]).max())
        else:
            n = self._normal_from_jacobian(k.C_s)
            gap = float(n @ k.c[:3])
            res = float(np.abs(np.r_[k.c[:3] - gap * n, k.c[3:]]).max())
        if not res < 1e-8:
            raise SolverError(f"{self.side} wheel: Newton stalled at residual {res:.3g} (s={s})")
        return ContactPoint(np.array(s, float), gap, res, it, self, k)

    def _conditions(self, q, x):
        """The four (rail frame) or five (global, with the gap ``x[4]``) conditions, their
        Jacobian in ``x`` and the kernels at ``x[:4]``."""
        k = self.evaluate(q, x[:4], clip=True)
        if self.form == "railframe":
            return k.c[_CONDITION_ROWS], k.C_s[_CONDITION_ROWS], k
        n = self._normal_from_jacobian(k.C_s)
        jac = np.zeros((5, 5))
        jac[:, :4] = k.C_s  # the normal's dependence on s2r is left out (exact at zero gap)
        jac[:3, 4] = -n
        return k.c - np.r_[x[4] * n, 0.0, 0.0], jac, k

    def _normal_from_jacobian(self, c_s: np.ndarray) -> np.ndarray:
        # Rows 1-3 of eq. 21 are r^w - r^r: their s1r and s2r columns are -t1^r and -t2^r.
        n = self.sign * np.cross(-c_s[:3, 2], -c_s[:3, 3])
        return n / np.linalg.norm(n)

    def _describe(self, s) -> dict:
        """The geometric attributes of a :class:`ContactPoint` at surface parameters ``s``."""
        pw = self.wheel.position(s[0])
        pr, dr = self.rail.position(s[3]), self.rail.derivative(s[3])
        R, A, dR, dA = (v[0] for v in self.frames.frames(s[2]))
        u, du = np.array([0.0, self.sign * pr[0], pr[1]]), np.array([0.0, self.sign * dr[0], dr[1]])
        normal = self.sign * np.cross(dR + dA @ u, A @ du)
        normal /= np.linalg.norm(normal)
        in_track = self.frames.track_axes(s[2]).T @ normal
        return dict(rolling_radius_m=float(self._head[1] + pw[1]),
                    contact_angle_rad=float(math.atan2(-self.sign * in_track[1], in_track[2])),
                    wheel_y_m=float(pw[0]), rail_y_m=float(pr[0]), point_m=R + A @ u, normal=normal)


def _piece_rows(pp) -> np.ndarray:
    """Kernel parameters of each piece of a profile's piecewise cubic ``pp``: its start and the
    coefficients of ``y`` and of ``z``, shape ``(pieces, 9)``."""
    return np.column_stack([pp.x[:-1], pp.c[:, :, 0].T, pp.c[:, :, 1].T])


def _rotation(theta) -> np.ndarray:
    """Rotation matrix of Euler parameters (as :func:`symcat.symbolic.rigid.rotation_matrix`)."""
    e0, e = theta[0], np.asarray(theta[1:4], float)
    skew = np.array([[0, -e[2], e[1]], [e[2], 0, -e[0]], [-e[1], e[0], 0]])
    return (2 * e0**2 - 1) * np.eye(3) + 2 * (np.outer(e, e) + e0 * skew)


def euler_parameters_roll(phi_rad: float) -> np.ndarray:
    """Euler parameters of a rotation by ``phi_rad`` about the global ``x`` axis (wheelset roll,
    positive lifting the left wheel)."""
    return np.array([math.cos(phi_rad / 2), math.sin(phi_rad / 2), 0.0, 0.0])
