"""Wheel/rail constraint contact (SymPy): seed paper Section 4, eqs. (15)-(22).

A rigid wheelset (body ``i``, coordinates ``[R, theta]``, axle along the body ``y`` axis, origin
at the axle centre) touches a rail fixed to the ground (body ``j``: no coordinates, ``R^r = 0``,
``A^r = I``) at one point described by four non-generalized surface parameters (eq. 15)
``s = [s1w, s2w, s1r, s2r]``: ``s1w`` along the wheel profile, ``s2w`` the angle about the axle
(0 at the bottom of the wheel, positive turning the point toward body ``+x``), ``s1r`` along the
track, ``s2r`` along the rail profile.

Profiles are the C2 cubic splines of :mod:`symcat.wheelrail.profiles`; the kernel is exact on
**one spline piece**: each profile enters as the local cubic of the piece that contains the
current parameter, ``y(s) = sum_k y_k (s - s0)**(3 - k)`` and likewise ``z`` (scipy's ``PPoly``
convention), with ``s0`` and the eight coefficients as kernel parameters. The runtime
(:mod:`symcat.wheelrail.constraint_contact`) picks the piece; C2 continuity makes ``C``, ``C_s``
and ``Q_d`` continuous across piece ends.

Wheel surface in the wheelset frame (eq. 20, ``r^w = R + A u_bar^w``), with the wheel profile
``(y_w, z_w)`` (``y`` from the tape circle toward the field side, ``z = r - r0``) and
``side`` = +1 for the left wheel (body ``+y``), -1 for the right one::

    u_bar^w = [rho sin s2w, side (b + y_w(s1w)), -rho cos s2w],   rho = r0 + z_w(s1w)

(``b``: half the tape-circle distance). The rail surface (eq. 19 with ``R^r = 0, A^r = I``)::

    r^r = R^rp(s1r) + A^rp(s1r) u_bar^rp,   u_bar^rp = [0, side y_r(s2r), z_r(s2r)]

The profile frame is that of tangent track along global ``x`` (``z`` up, ``y`` toward the left
rail): ``R^rp = [s1r, Y_o, Z_o]`` (the profile origin), ``A^rp = R_x(roll)`` with ``roll``
the rotation of the profile plane about the track axis (cant plus ``side`` times any rail
inclination not built into the profile data). The profile's ``y`` is mirrored on the right
(``side`` = -1), so ``u_bar^rp`` keeps ``A^rp`` a rotation; the outward normal is therefore
``n^r = side t1^r x t2^r`` (eq. 18 up to that sign). Tangents (eq. 17) are derived from
``r^r`` itself, so the track geometry enters only through the frame ``(R^rp, A^rp)``.

Curved track (libraries ``wheelrail_{global,railframe}_rigid_track``): the frame is one cubic
piece in ``s1r`` of a rail frame along the track (built by :mod:`symcat.wheelrail.track_pieces`
from a :class:`symcat.wheelrail.track.TrackLayout`: tangents, circular curves, clothoid
transitions, cant, gradient, rail inclination, irregularities), as the layout writes it
(``A = Rz(psi) Ry(-theta) Rx(phi)``): an origin cubic ``R^t``, heading ``psi`` and cant angle
``phi`` cubics and the constant gradient angle ``theta``, with the origin offset and roll of the
profile applied in that frame::

    t = s1r - st0,   R^t = sum_k tR_k t**k,   psi = sum_k psi_k t**k,   phi = sum_k phi_k t**k
    A^t = Rz(psi) Ry(-theta) Rx(phi)
    R^rp = R^t + A^t [0, Y_o, Z_o],   A^rp = A^t R_x(roll)

``A^t`` is a rotation whatever the coefficients; pieces ``R^t = [s1r, 0, 0]``, ``psi = phi =
theta = 0`` give the tangent-track kernel. ``s1r`` is the layout's chainage (distance along the
centreline in plan), not the rail's arc length: ``t1^r`` is not a unit vector (``1 - kappa y``
in a curve) and, where the cant changes, not normal to ``t2^r``. The rail-frame rows of the track
libraries are therefore written as the components of ``d`` along the unit vectors
``t1^r/|t1^r|, t2^r/|t2^r|, n^r`` in global components: the rows below, since ``A^rp`` is a
rotation.

Constraints (5 each; all unit vectors, so the multiplier of the normal row is the normal
force in N and the others vanish at a frictionless equilibrium)::

    global (eq. 21):     [r^w - r^r (3, global components);  t1w . n^r;  t2w . n^r]
    rail frame (eq. 22): [t1^r . d;  t2^r . d;  n^r . d;  t1w . n^r;  t2w . n^r]

with ``d = r^w - r^r`` written in the rail profile frame (``A^rp^T d``, dotted with the local
unit vectors of the rail), ``t1w, t2w`` the unit wheel tangents and ``t1^r, t2^r, n^r`` the unit
rail tangents and outward normal. As in the paper, the tangency rows use the wheel tangents
against the rail normal (the issue's wording, rail tangents against the wheel normal, is
equivalent at the solution). ``n^r . d`` is the normal gap (m, positive when separated); the
paper prints eq. 22 with four rows, the fifth (``t2w . n^r``) is restored here.

Parameters (in this order; see :data:`PARAM_DOC`): ``side, r0, b, Y_o, Z_o, roll``, then the
wheel piece ``sw0, wy_0:4, wz_0:4`` and the rail piece ``sr0, ry_0:4, rz_0:4`` (24); the track
libraries append the track piece ``st0, tR0_0 .. tR3_2, psi_0:4, phi_0:4, theta`` (22,
:data:`TRACK_PARAM_DOC`; ``Y_o, Z_o`` are then components in the piece frame, ``roll`` about its
first axis).
"""
from __future__ import annotations

import sympy as sp

from .joints import ConstraintDefinition, _Side

#: Kernel parameters: name, unit, meaning (in kernel order).
PARAM_DOC = (
    ("side", "-", "+1 left wheel/rail (body +y), -1 right"),
    ("r0", "m", "nominal rolling radius at the tape circle"),
    ("b", "m", "half the tape-circle distance"),
    ("Y_o", "m", "global y of the rail profile origin"),
    ("Z_o", "m", "global z of the rail profile origin"),
    ("roll", "rad", "rotation of the rail profile plane about the track (x) axis"),
    ("sw0", "m", "start parameter of the wheel profile's spline piece"),
    *((f"wy_{k}", f"m^{-2 + k}", f"wheel y coefficient of (s1w - sw0)^{3 - k}") for k in range(4)),
    *((f"wz_{k}", f"m^{-2 + k}", f"wheel z coefficient of (s1w - sw0)^{3 - k}") for k in range(4)),
    ("sr0", "m", "start parameter of the rail profile's spline piece"),
    *((f"ry_{k}", f"m^{-2 + k}", f"rail y coefficient of (s2r - sr0)^{3 - k}") for k in range(4)),
    *((f"rz_{k}", f"m^{-2 + k}", f"rail z coefficient of (s2r - sr0)^{3 - k}") for k in range(4)),
)
PARAM_NAMES = tuple(name for name, _, _ in PARAM_DOC)
#: Track piece of the curved-track libraries (appended to :data:`PARAM_DOC`): start, the
#: ascending-power coefficients of the frame origin (component ``i``), of the heading and of the
#: cant angle, and the gradient angle.
TRACK_PARAM_DOC = (
    ("st0", "m", "start chainage of the track piece"),
    *((f"tR{k}_{i}", f"m^{1 - k}", f"frame origin component {i}, coefficient of (s1r - st0)^{k}")
      for k in range(4) for i in range(3)),
    *((f"psi_{k}", f"rad/m^{k}", f"heading, coefficient of (s1r - st0)^{k}") for k in range(4)),
    *((f"phi_{k}", f"rad/m^{k}", f"cant angle, coefficient of (s1r - st0)^{k}") for k in range(4)),
    ("theta", "rad", "gradient angle (rise of the track axis)"),
)
TRACK_PARAM_NAMES = tuple(name for name, _, _ in TRACK_PARAM_DOC)
N_TANGENT_PARAMS = len(PARAM_NAMES)
N_TRACK_PARAMS = len(PARAM_NAMES) + len(TRACK_PARAM_NAMES)
#: Surface parameters, in the order of eq. (15).
SURFACE_PARAMETERS = ("s1w", "s2w", "s1r", "s2r")
FORMS = ("global", "railframe")
#: Track kinds: ``"ground"`` (tangent track along global x) and ``"track"`` (cubic track pieces).
TRACKS = ("ground", "track")


def _cubic(s, s0, coeffs):
    ds = s - s0
    return coeffs[0] * ds**3 + coeffs[1] * ds**2 + coeffs[2] * ds + coeffs[3]


def _unit(v: sp.Matrix, norm=None) -> sp.Matrix:
    return v / (sp.sqrt(v.dot(v)) if norm is None else norm)


def _rot_x(a) -> sp.Matrix:
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def tangent_track_frame(s1r, par: dict) -> tuple[sp.Matrix, sp.Matrix]:
    """Rail profile frame ``(R^rp, A^rp)`` of tangent track along global ``x``."""
    return sp.Matrix([s1r, par["Y_o"], par["Z_o"]]), _rot_x(par["roll"])


def _ascending(t, coeffs):
    return ((coeffs[3] * t + coeffs[2]) * t + coeffs[1]) * t + coeffs[0]


def _rot_y(a) -> sp.Matrix:
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rot_z(a) -> sp.Matrix:
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def piece_track_frame(s1r, par: dict) -> tuple[sp.Matrix, sp.Matrix]:
    """Rail profile frame ``(R^rp, A^rp)`` on one cubic track piece (module docstring)."""
    t = s1r - par["st0"]
    r_t = sp.Matrix([_ascending(t, [par[f"tR{k}_{i}"] for k in range(4)]) for i in range(3)])
    psi = _ascending(t, [par[f"psi_{k}"] for k in range(4)])
    phi = _ascending(t, [par[f"phi_{k}"] for k in range(4)])
    a_t = _rot_z(psi) * _rot_y(-par["theta"]) * _rot_x(phi)
    return r_t + a_t * sp.Matrix([0, par["Y_o"], par["Z_o"]]), a_t * _rot_x(par["roll"])


def wheelrail(form: str, track: str = "ground") -> ConstraintDefinition:
    """Five contact constraints of one wheel of a rigid wheelset on a ground-fixed rail.

    ``form`` is ``"global"`` (eq. 21) or ``"railframe"`` (eq. 22); ``track`` is ``"ground"``
    (tangent track along global ``x``, parameters :data:`PARAM_NAMES`) or ``"track"`` (one cubic
    track piece, parameters :data:`PARAM_NAMES` + :data:`TRACK_PARAM_NAMES`); ``y = [R, theta,
    s1w, s2w, s1r, s2r]`` (11).
    """
    if form not in FORMS:
        raise ValueError(f"form={form!r}: must be one of {', '.join(FORMS)}")
    if track not in TRACKS:
        raise ValueError(f"track={track!r}: must be one of {', '.join(TRACKS)}")
    wheelset = _Side("rigid", "i")
    t = sp.Symbol("t", real=True)
    s1w, s2w, s1r, s2r = s = sp.symbols(" ".join(SURFACE_PARAMETERS), real=True)
    names = PARAM_NAMES + (TRACK_PARAM_NAMES if track == "track" else ())
    par = {n: sp.Symbol(n, real=True) for n in names}
    side, r0, b = par["side"], par["r0"], par["b"]

    # Wheel (eq. 20): surface of revolution of the profile piece about the body y axis.
    y_w = _cubic(s1w, par["sw0"], [par[f"wy_{k}"] for k in range(4)])
    z_w = _cubic(s1w, par["sw0"], [par[f"wz_{k}"] for k in range(4)])
    rho = r0 + z_w
    u_w = sp.Matrix([rho * sp.sin(s2w), side * (b + y_w), -rho * sp.cos(s2w)])
    a_w = wheelset.rotation
    r_w = wheelset.origin + a_w * u_w
    u_w1, u_w2 = u_w.diff(s1w), u_w.diff(s2w)
    t1w = a_w * _unit(u_w1, sp.sqrt(y_w.diff(s1w) ** 2 + z_w.diff(s1w) ** 2))
    t2w = a_w * _unit(u_w2, rho)  # |du/ds2w| = rho > 0 on a wheel

    # Rail (eq. 19 with the rail fixed to the ground).
    y_r = _cubic(s2r, par["sr0"], [par[f"ry_{k}"] for k in range(4)])
    z_r = _cubic(s2r, par["sr0"], [par[f"rz_{k}"] for k in range(4)])
    frame = tangent_track_frame if track == "ground" else piece_track_frame
    r_rp, a_rp = frame(s1r, par)
    r_r = r_rp + a_rp * sp.Matrix([0, side * y_r, z_r])
    t1r, t2r = r_r.diff(s1r), r_r.diff(s2r)
    n_r = _unit(side * t1r.cross(t2r))
    d = r_w - r_r

    tangency = sp.Matrix([t1w.dot(n_r), t2w.dot(n_r)])
    if form == "global":
        c = sp.Matrix.vstack(d, tangency)
        description = "wheel/rail contact, global form (seed eq. 21)"
    elif track == "ground":
        # In the profile frame: d_bar = A^rp^T d against the local unit vectors of the rail.
        d_bar = a_rp.T * d
        local = [_unit(a_rp.T * t1r), _unit(a_rp.T * t2r), a_rp.T * n_r]
        c = sp.Matrix.vstack(sp.Matrix([v.dot(d_bar) for v in local]), tangency)
        description = "wheel/rail contact, rail-frame form (seed eq. 22)"
    else:
        # The same components of d, taken in global components (A^t is a cubic, not a rotation).
        c = sp.Matrix.vstack(sp.Matrix([_unit(t1r).dot(d), _unit(t2r).dot(d), n_r.dot(d)]), tangency)
        description = "wheel/rail contact, rail-frame form (seed eq. 22)"
    if track == "track":
        description += ", curved track (cubic track pieces)"
    p = [par[n] for n in names]
    return ConstraintDefinition(
        name=library_name(form, track), x_i=wheelset.x, x_j=sp.zeros(0, 1), s=sp.Matrix(s), t=t,
        p=sp.Matrix(p), param_names=list(names), c=c, description=description,
    )


def library_name(form: str, track: str = "ground") -> str:
    """Name of the kernel library of a constraint form and track kind."""
    return f"wheelrail_{form}_rigid_{track}"


#: Wheel/rail constraint libraries: name -> builder (kept apart from the joints' registry).
WHEELRAIL_CONSTRAINTS = {library_name(form, track): (lambda form=form, track=track: wheelrail(form, track))
                         for track in TRACKS for form in FORMS}
