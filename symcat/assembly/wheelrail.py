"""Assembly of wheel/rail constraint contacts (:class:`symcat.scene.WheelRailJoint`).

Each contact owns four consecutive entries of the surface-parameter vector ``s`` (after the
sliding joints' arc lengths) and five constraint rows (after the sliding joints' rows). The
compiled kernel (:mod:`symcat.symbolic.wheelrail`) is exact on one cubic piece of each profile;
the piece is selected *inside the CasADi graph* by a compiled SX lookup ``s -> (s0, coefficients)``
made of comparisons, whose derivative is zero, so ``C``, ``C_q``, ``C_s`` and ``Q_d`` follow the
surface parameters across piece ends (C2 splines: the values are continuous there).

Creep forces (:class:`symcat.scene.CreepModel`) are applied forces at the wheel's material point
at the contact; they depend on the normal force, a linear function of the multipliers
(:func:`normal_directions`), so :mod:`symcat.dae.formulation` adds them to the dynamics with
the multipliers. The constraint force on the wheelset is ``-C_q^T lambda``. In the rail-frame
form (eq. 22) the gap row's gradient is the rail's outward normal ``n``, so ``N = -lambda_gap``.
In the global form (eq. 21) the three coincidence rows ``r^w - r^r`` have the identity as
gradient in the wheelset position, so their force on the wheel is ``-lambda[0:3]``, normal to
the rail surface where ``C_s^T lambda = 0`` holds; ``N = -n . lambda[0:3]``. The contact ellipse and
Kalker's coefficients are computed in the same graph at the current contact point
(:func:`contact_ellipse`, :mod:`.creep_ellipse`): from the curvatures of the selected cubic
pieces, so they follow the point across the profiles. The contact frame is ``t1`` the unit rail
tangent along the track
at the contact (rolling direction: global ``x`` on tangent track), ``n`` the rail's outward
normal there, ``t2 = n x t1``; the creepages are the material point's velocity along ``t1, t2``
and the wheelset's angular velocity along ``n``, divided by ``V = sqrt((R_dot . t1)^2 +
v_ref^2)`` (the forward speed along the track tangent).

Curved track (a :class:`symcat.wheelrail.track.TrackLayout` as the joint's ``track``): the
kernels ``wheelrail_*_rigid_track`` take the cubic track piece holding ``s1r`` as 22 more
parameters, selected by :meth:`symcat.wheelrail.track_pieces.TrackRailFrames.lookup` (a binary
search and a table read by symbolic index: zero derivative, cost independent of the track's
length); tangent track keeps the cheaper ``wheelrail_*_rigid_ground`` kernels.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..codegen.library import kernel_library
from .contact import _placement
from .creep_ellipse import (hertz_semi_axes_sx, kalker_coefficients_sx, plane_curvature_sx,
                            relative_curvatures_sx)
from ..errors import ParameterError, SolverError
from ..scene.rigid import RigidBody
from ..scene.wheelrail import CreepModel, WheelRailJoint
from ..wheelrail.creep import SHEAR_MODULUS_STEEL_PA, kalker_coefficients, kalker_linear_forces
from ..wheelrail.hertz import hertz_contact, relative_curvatures
from ..wheelrail.identity_memo import IdentityMemo
from ..wheelrail.track_pieces import interval_lookup

#: Rows of a contact that define its surface parameters in the embedded form (eq. 22: the two
#: in-plane coincidence rows and the two tangency rows); row 2 is the normal gap.
TANGENCY_ROWS = (0, 1, 3, 4)
GAP_ROW = 2
#: A wheelset farther than this from touching its rail at the start is "off the rails" (m).
PLACEMENT_TOLERANCE_M = 2e-3


@dataclass
class CreepSetup:
    """Contact ellipse and Kalker coefficients (times the model's ``coefficient_factor``) at the
    nominal load and the *initial* contact point (see :class:`CreepModel`): the values the creep
    function starts from (it recomputes them at the current contact point) and those of a linear
    analysis about the initial state."""

    a_m: float
    b_m: float
    c11: float
    c22: float
    c23: float
    c33: float
    nominal_normal_force_N: float


@dataclass
class WheelRailEntry:
    joint: WheelRailJoint
    contact: object                 # symcat.wheelrail.WheelRailContact
    library: str
    body: RigidBody
    rows: list                      # the wheelset's 7 global coordinate indices
    s0: np.ndarray                  # initial surface parameters
    head: np.ndarray                # the 6 constant kernel parameters
    wheel_piece: ca.Function
    rail_piece: ca.Function
    track_piece: ca.Function | None = None  # curved track: s1r -> track piece (22)
    normal_fn: ca.Function | None = None    # (s, p) -> the rail's unit outward normal (global)
    creep: CreepSetup | None = None
    creep_fn: ca.Function | None = None
    s_index: int = 0                # first of the contact's 4 entries in s
    row_start: int = 0              # first of its 5 constraint rows


def piece_lookup(profile, name: str, shared: IdentityMemo | None = None) -> ca.Function:
    """Compiled SX lookup ``s -> [s0, y_0:4, z_0:4]`` of the cubic piece containing ``s``
    (the end pieces extend beyond the profile's ends); with ``shared``, one per profile object,
    named ``name`` by the first contact that asks."""
    def build():
        pp = profile.piecewise_polynomial()
        rows = np.column_stack([pp.x[:-1], pp.c[:, :, 0].T, pp.c[:, :, 1].T])
        return interval_lookup(pp.x, rows, name)

    return build() if shared is None else shared.get((profile,), ("piece",), build)


def add_wheelrail(model, joint: WheelRailJoint) -> WheelRailEntry:
    """Record of one contact for ``model`` (a :class:`MultibodyModel` under construction)."""
    body = model.scene.find(joint.body)
    if not isinstance(body, RigidBody):
        raise ParameterError(f"wheel/rail contact {joint.name!r}: body={joint.body!r} must be a rigid body (the wheelset)")
    contact = joint.contact()
    rows = model._rigid_indices(body.name)
    q_body = model.q0[rows]
    try:
        point = contact.solve(q_body)
    except SolverError as err:
        raise ParameterError(f"wheel/rail contact {joint.name!r}: the {joint.side} wheel of {body.name!r} does not "
                             f"meet its rail at the initial position ({err})") from None
    if abs(point.gap_m) > PLACEMENT_TOLERANCE_M:
        raise ParameterError(
            f"wheel/rail contact {joint.name!r}: the {joint.side} wheel of {body.name!r} is {point.gap_m * 1e3:.2f} mm "
            f"{'above' if point.gap_m > 0 else 'into'} its rail at the initial position (allowed "
            f"{PLACEMENT_TOLERANCE_M * 1e3:g} mm); place the wheelset with symcat.vehicle.wheelset_on_track")
    s0 = point.s
    head = contact.parameters(s0)[:6]
    entry = WheelRailEntry(joint, contact, contact.library, body, rows, s0, head,
                           piece_lookup(joint.wheel, f"{joint.name}_wheel_piece", model.wheelrail_shared),
                           piece_lookup(joint.rail, f"{joint.name}_rail_piece", model.wheelrail_shared))
    if contact.curved:
        entry.track_piece = contact.frames.lookup(f"{joint.name}_track_piece")
    entry.normal_fn = rail_normal_function(f"{joint.name}_normal", curved=contact.curved)
    if joint.creep is not None:
        entry.creep = creep_setup(joint, contact, point)
        entry.creep_fn = creep_function(joint, entry.creep, curved=contact.curved, shared=model.wheelrail_shared)
    return entry


def creep_setup(joint: WheelRailJoint, contact, point) -> CreepSetup:
    """Hertz ellipse and Kalker coefficients at the nominal load and the initial contact point
    (NumPy: :func:`symcat.wheelrail.hertz.hertz_contact`, :func:`kalker_coefficients`).

    Raises
    ------
    ParameterError
        If the profiles have no Hertz ellipse there (conformal or concave relative surface).
    """
    cm = joint.creep
    try:
        A, B = relative_curvatures(*contact_curvatures(contact.wheel, contact.rail, point.s, point.rolling_radius_m))
        ellipse = hertz_contact(cm.nominal_normal_force_N, A, B)
    except ParameterError as err:
        raise ParameterError(f"wheel/rail contact {joint.name!r}: no Hertz ellipse at the initial contact point "
                             f"({err})") from None
    a, b = float(ellipse.semi_axis_a_m), float(ellipse.semi_axis_b_m)
    c = kalker_coefficients(a / b, clamp=True)
    f = cm.coefficient_factor
    return CreepSetup(a, b, f * float(c.c11), f * float(c.c22), f * float(c.c23), f * float(c.c33),
                      cm.nominal_normal_force_N)


def contact_curvatures(wheel, rail, s, rolling_radius_m):
    """Arguments of :func:`symcat.wheelrail.hertz.relative_curvatures` at surface parameters
    ``s``, as the creep function computes them in its graph (NumPy).

    The profile curvatures are negated (``Profile.curvature`` is positive for hollows, Hertz
    wants convex positive). The angle is that of the wheel's profile normal to its radius,
    ``atan(dz/dy)`` of the wheel profile: the angle of Meusnier's theorem for the wheel's
    curvature along the rolling direction (the track-plane ``ContactPoint.contact_angle_rad``
    differs from it by the wheelset's roll).

    Returns
    -------
    (rolling_radius_m, wheel_curvature_per_m, rail_curvature_per_m, contact_angle_rad)
    """
    d = wheel.derivative(s[0])
    return (float(rolling_radius_m), -float(wheel.curvature(s[0])), -float(rail.curvature(s[3])),
            float(np.arctan2(-d[1], d[0])))


def _rotation(th):
    e0, e1, e2, e3 = th[0], th[1], th[2], th[3]
    e = ca.vertcat(e1, e2, e3)
    skew = ca.vertcat(ca.horzcat(0, -e3, e2), ca.horzcat(e3, 0, -e1), ca.horzcat(-e2, e1, 0))
    return (2 * e0**2 - 1) * ca.SX.eye(3) + 2 * (ca.mtimes(e, e.T) + e0 * skew)


def _cubic(s, s0, c):
    d = s - s0
    return c[0] * d**3 + c[1] * d**2 + c[2] * d + c[3], 3 * c[0] * d**2 + 2 * c[1] * d + c[2]


def _cubic_slopes(s, s0, c):
    """First and second derivative of the cubic piece of :func:`_cubic`."""
    d = s - s0
    return 3 * c[0] * d**2 + 2 * c[1] * d + c[2], 6 * c[0] * d + 2 * c[1]


def _piece_curvature(s, s0, cy, cz):
    """Curvature (1/m) of a profile's cubic piece at ``s``, convex positive (Hertz's sign,
    the negative of ``Profile.curvature``), and the ``y`` and ``z`` slopes ``dy/ds, dz/ds``."""
    dy, ddy = _cubic_slopes(s, s0, cy)
    dz, ddz = _cubic_slopes(s, s0, cz)
    return -plane_curvature_sx(dy, dz, ddy, ddz), dy, dz


def contact_ellipse(p, s, normal_N, creep: CreepModel):
    """Semi-axes ``a, b`` (m) and Kalker's coefficients (times ``coefficient_factor``) at the
    contact point of surface parameters ``s`` (SX), kernel parameters ``p``, normal force
    ``normal_N``: the graph form of :func:`creep_setup` (see :func:`contact_curvatures`)."""
    z_w, _ = _cubic(s[0], p[6], p[11:15])
    k_wheel, dy_w, dz_w = _piece_curvature(s[0], p[6], p[7:11], p[11:15])
    k_rail, _, _ = _piece_curvature(s[3], p[15], p[16:20], p[20:24])
    cos_angle = dy_w / ca.sqrt(dy_w**2 + dz_w**2)
    A, B = relative_curvatures_sx(p[1] + z_w, cos_angle, k_wheel, k_rail)
    a, b = hertz_semi_axes_sx(normal_N, A, B)
    return a, b, kalker_coefficients_sx(a / b, factor=creep.coefficient_factor)


def _rail_tangents(p, s, curved: bool):
    """Rail tangents ``t1^r = dr^r/ds1r`` and ``t2^r = dr^r/ds2r`` (global, SX) at surface
    parameters ``s`` for kernel parameters ``p``, as the kernels write them."""
    side, y_o, z_o, roll = p[0], p[3], p[4], p[5]
    y_r, dy_r = _cubic(s[3], p[15], p[16:20])
    z_r, dz_r = _cubic(s[3], p[15], p[20:24])
    c, sn = ca.cos(roll), ca.sin(roll)
    rx = ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, c, -sn), ca.horzcat(0, sn, c))
    u, du = ca.vertcat(0, side * y_r, z_r), ca.vertcat(0, side * dy_r, dz_r)
    if not curved:
        return ca.DM([1.0, 0.0, 0.0]), ca.mtimes(rx, du)
    tp = p[24:46]
    t = s[2] - tp[0]
    d_origin = ca.vertcat(*[tp[4 + i] + 2 * tp[7 + i] * t + 3 * tp[10 + i] * t**2 for i in range(3)])
    psi = tp[13] + t * (tp[14] + t * (tp[15] + t * tp[16]))
    d_psi = tp[14] + t * (2 * tp[15] + 3 * t * tp[16])
    phi = tp[17] + t * (tp[18] + t * (tp[19] + t * tp[20]))
    d_phi = tp[18] + t * (2 * tp[19] + 3 * t * tp[20])
    cp, sp, ct, st, cf, sf = ca.cos(psi), ca.sin(psi), ca.cos(tp[21]), ca.sin(tp[21]), ca.cos(phi), ca.sin(phi)
    a0 = ca.vertcat(ca.horzcat(cp * ct, -sp, -cp * st), ca.horzcat(sp * ct, cp, -sp * st), ca.horzcat(st, 0, ct))
    a_t = ca.mtimes(a0, ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, cf, -sf), ca.horzcat(0, sf, cf)))
    kz = ca.DM([[0, -1, 0], [1, 0, 0], [0, 0, 0]])
    kx = ca.DM([[0, 0, 0], [0, 0, -1], [0, 1, 0]])
    d_a = d_psi * ca.mtimes(kz, a_t) + d_phi * ca.mtimes(a_t, kx)
    t1r = d_origin + ca.mtimes(d_a, ca.vertcat(0, y_o, z_o) + ca.mtimes(rx, u))
    return t1r, ca.mtimes(a_t, ca.mtimes(rx, du))


def _contact_frame(p, s, curved: bool):
    """Unit contact frame ``(t1, t2, n)`` (global, SX): ``t1`` the rail tangent along the track,
    ``n`` the rail's outward normal, ``t2 = n x t1`` (the kernels' ``n^r``)."""
    side = p[0]
    t1r, t2r = _rail_tangents(p, s, curved)
    t1 = t1r if not curved else t1r / ca.norm_2(t1r)
    n = side * ca.cross(t1, t2r)
    n = n / ca.norm_2(n)
    return t1, ca.cross(n, t1), n


def rail_normal_function(name: str, curved: bool = False) -> ca.Function:
    """SX function ``(s, p) -> n``: the rail's unit outward normal at surface parameters ``s``
    (4) for kernel parameters ``p`` (24; 46 on curved track)."""
    s, p = ca.SX.sym("s", 4), ca.SX.sym("p", 46 if curved else 24)
    return ca.Function(name, [s, p], [_contact_frame(p, s, curved)[2]], ["s", "p"], ["n"])


def creep_function(joint: WheelRailJoint, setup: CreepSetup, curved: bool = False,
                   shared: IdentityMemo | None = None) -> ca.Function:
    """SX function ``(x, x_dot, s, p, N) -> (Q, [xi_x, xi_y, phi, Fx, Fy, Mz])``: generalized creep
    forces on the wheelset coordinates ``x = [R, theta]`` (7) for surface parameters ``s``,
    kernel parameters ``p`` (24; 46 on curved track) and normal force ``N`` (N). It depends on
    the creep model alone (the profiles enter through ``p``): with ``shared``, contacts with
    equal creep models share one, named by the first."""
    if shared is None:
        return _creep_function(joint, setup, curved)
    values = (dataclasses.astuple(joint.creep), float(setup.nominal_normal_force_N), bool(curved), "creep")
    return shared.get((), values, lambda: _creep_function(joint, setup, curved))


def _creep_function(joint: WheelRailJoint, setup: CreepSetup, curved: bool) -> ca.Function:
    x, xd = ca.SX.sym("x", 7), ca.SX.sym("xd", 7)
    s, p, normal = ca.SX.sym("s", 4), ca.SX.sym("p", 46 if curved else 24), ca.SX.sym("N")
    side, r0, b = p[0], p[1], p[2]
    y_w, _ = _cubic(s[0], p[6], p[7:11])
    z_w, _ = _cubic(s[0], p[6], p[11:15])
    rho = r0 + z_w
    u_w = ca.vertcat(rho * ca.sin(s[1]), side * (b + y_w), -rho * ca.cos(s[1]))
    th, r_dot, th_dot = x[3:7], xd[:3], xd[3:7]
    arm = ca.mtimes(_rotation(th), u_w)
    e0, e1, e2, e3 = th[0], th[1], th[2], th[3]
    g = ca.vertcat(ca.horzcat(-e1, e0, -e3, e2), ca.horzcat(-e2, e3, e0, -e1), ca.horzcat(-e3, -e2, e1, e0))
    omega = 2 * ca.mtimes(g, th_dot)
    v_point = r_dot + ca.cross(omega, arm)
    t1, t2, n = _contact_frame(p, s, curved)
    cm = joint.creep
    speed = ca.sqrt(ca.dot(r_dot, t1) ** 2 + cm.reference_speed_m_s**2)
    xi_x, xi_y, phi = ca.dot(v_point, t1) / speed, ca.dot(v_point, t2) / speed, ca.dot(omega, n) / speed
    # the ellipse at the nominal load and the current contact point
    a_m, b_m, coeff = contact_ellipse(p, s, setup.nominal_normal_force_N, cm)
    if cm.law == "linear":
        fx, fy, mz = kalker_linear_forces(xi_x, xi_y, phi, a_m, b_m, coeff)
    else:
        # The multiplier may dip below zero where the constraint holds the wheel down.
        n_pos = smooth_positive(normal, 1e-3 * setup.nominal_normal_force_N)
        scale = (n_pos / setup.nominal_normal_force_N) ** (1.0 / 3.0)
        fx, fy, mz = polach_forces_casadi(xi_x, xi_y, phi, n_pos, a_m * scale, b_m * scale, coeff,
                                          friction_coefficient=cm.friction_coefficient)
    force = fx * t1 + fy * t2
    moment = mz * n
    # Virtual work: F . delta r_P + M . delta pi, with delta r_P and delta pi linear in the rates.
    rates = ca.vertcat(r_dot, th_dot)
    q_gen = ca.mtimes(ca.jacobian(v_point, rates).T, force) + ca.mtimes(ca.jacobian(omega, rates).T, moment)
    return ca.Function(f"{joint.name}_creep", [x, xd, s, p, normal], [q_gen, ca.vertcat(xi_x, xi_y, phi, fx, fy, mz)],
                       ["x", "x_dot", "s", "p", "N"], ["Q", "creep"])


def smooth_positive(x, eps):
    """Smooth ``max(x, 0)``, ``(x + sqrt(x^2 + eps^2)) / 2`` (CasADi), written as
    ``eps^2 / (2 (sqrt(x^2 + eps^2) - x))`` for ``x < 0``: the same value without the
    cancellation that makes the first form exactly zero (and a creep law dividing by it NaN)
    once ``|x| > 1e8 eps``. Value and derivative stay positive and finite for every ``x``."""
    r = ca.sqrt(x**2 + eps**2)
    return ca.if_else(x >= 0, 0.5 * (x + r), 0.5 * eps**2 / (r - x))


def polach_forces_casadi(xi_x, xi_y, phi, normal_N, a_m, b_m, coefficients,
                         shear_modulus_Pa=SHEAR_MODULUS_STEEL_PA, friction_coefficient=0.3):
    """Polach's creep forces (1999 method, as :func:`symcat.wheelrail.polach_forces`) in CasADi
    symbols; ``mz`` is zero (Polach has no spin moment).

    Written to be differentiable everywhere: the resultant creepages are regularized at zero
    (``sqrt(s^2 + 1e-24)``), and the spin term ``K_M phi / s_c`` with ``K_M = eps_M h(eps_M^2)``
    uses ``eps_M / s_c ~ |xi_y_c| / s_c = sqrt((xi_y_c^2 + 1e-24) / s_c^2)``, which is 1 for pure
    spin (Kalker's linear ``-G (ab)^1.5 C23 phi`` at small spin) instead of the 0 that
    ``|xi_y_c| / sqrt(xi_y_c^2 + 1e-24)`` gives there. Polach's combined coefficient
    ``C = sqrt((C11 xi_x)^2 + (C22 xi_y)^2) / s`` depends on the direction of the creepage, so
    the law itself has no derivative at zero creepage on scales above the regularization; the
    Jacobian there is finite (``C = C11`` in every direction)."""
    c11, c22, c23, _ = coefficients
    g, mu = shear_modulus_Pa, friction_coefficient
    bound = mu * normal_N
    xi_y_edge = xi_y + phi * a_m
    xi_y_c2 = ca.fmax(xi_y_edge**2, xi_y**2)  # the larger lateral creepage, squared
    tiny = 1e-24
    s = ca.sqrt(xi_x**2 + xi_y**2 + tiny)
    s_c2 = xi_x**2 + xi_y_c2 + tiny
    s_c = ca.sqrt(s_c2)
    c_jj = ca.sqrt((c11 * xi_x) ** 2 + (c22 * xi_y) ** 2 + tiny * c11**2) / s
    eps = g * math.pi * a_m * b_m * c_jj * s_c / (4.0 * bound)
    force = 2.0 * bound / math.pi * (eps / (1.0 + eps**2) + ca.atan(eps))
    k_spin = 1.0 + 6.3 * (1.0 - ca.exp(-a_m / b_m))
    k_eps = 8.0 / 3.0 * g * b_m * ca.sqrt(a_m * b_m) * c23 / (bound * k_spin)  # eps_M / |xi_y_c|
    e2 = k_eps**2 * xi_y_c2
    delta = (e2 - 1.0) / (e2 + 1.0)
    # K_M / eps_M; sqrt((1 - delta^2)^3) / eps_M = 8 eps_M^2 / (eps_M^2 + 1)^3.
    h = delta**3 / 3.0 - delta**2 / 2.0 + 1.0 / 6.0 - 8.0 * e2 / (3.0 * (e2 + 1.0) ** 3)
    f_spin = 9.0 / 16.0 * a_m * bound * k_eps * h * ca.sqrt((xi_y_c2 + tiny) / s_c2) * k_spin * phi
    return -force * xi_x / s_c, -force * xi_y / s_c + f_spin, 0 * xi_x


# --- MX pieces for the multibody model ------------------------------------------------------
def kernel_inputs(entry: WheelRailEntry, q: ca.MX, v: ca.MX, s: ca.MX, s_dot: ca.MX):
    """Kernel arguments ``y``, ``y_dot`` and parameters ``p`` of one contact (MX)."""
    i = entry.s_index
    s_e, sd_e = s[i : i + 4], s_dot[i : i + 4]
    y = ca.vertcat(q[entry.rows], s_e)
    y_dot = ca.vertcat(v[entry.rows], sd_e)
    pieces = [ca.DM(entry.head), entry.wheel_piece(s_e[0]), entry.rail_piece(s_e[3])]
    if entry.track_piece is not None:
        pieces.append(entry.track_piece(s_e[2]))
    return y, y_dot, ca.vertcat(*pieces)


def constraint_parts(model, q, v, s, s_dot, t, place):
    """``(c, c_q, c_s, c_t, q_d)`` blocks of every contact (5 rows each); ``place`` puts a
    block's columns at global coordinate columns."""
    parts = []
    for e in model.wheelrail:
        kl = kernel_library(e.library)
        y, y_dot, p = kernel_inputs(e, q, v, s, s_dot)
        c = kl[f"{e.library}_c"](y, t, p)
        c_y, c_t = kl[f"{e.library}_jac"](y, t, p)
        cs = ca.MX(5, model.n_s)
        cs[:, e.s_index : e.s_index + 4] = c_y[:, 7:11]
        parts.append((c, place(c_y[:, :7], e.rows, model.n_q), cs, c_t, kl[f"{e.library}_gamma"](y, y_dot, t, p)))
    return parts


def creep_terms(model, q, v, s, s_dot, normal_N) -> tuple[ca.MX, ca.MX]:
    """Generalized creep forces (n_q) and the creep record (6 per contact: ``xi_x, xi_y, phi``
    (-, -, 1/m) and ``Fx, Fy, Mz`` (N, N, N m)) for the normal forces ``normal_N`` (one per
    contact, N); contacts without a creep model contribute zeros."""
    total = ca.MX(model.n_q, 1)
    records = []
    for k, e in enumerate(model.wheelrail):
        if e.creep_fn is None:
            records.append(ca.MX(6, 1))
            continue
        y, y_dot, p = kernel_inputs(e, q, v, s, s_dot)
        q_gen, rec = e.creep_fn(y[:7], y_dot[:7], y[7:], p, normal_N[k])
        total += ca.mtimes(_placement(e.rows, model.n_q).T, q_gen)
        records.append(rec)
    return total, (ca.vertcat(*records) if records else ca.MX(0, 1))


def normal_directions(model, q: ca.MX, s: ca.MX) -> ca.MX:
    """Per contact the weights ``w`` (3) of its normal force ``N = -w . lambda[r : r + 3]``, ``r``
    its first constraint row (MX, 3 per contact): ``(0, 0, 1)`` in the rail-frame form (the gap
    row), the rail's unit outward normal in the global form (the coincidence rows' force,
    projected: linear in the multipliers, hence smooth for the solver, and equal to its
    magnitude wherever ``C_s^T lambda = 0`` makes it normal to the rail)."""
    out = []
    for e in model.wheelrail:
        if e.joint.form == "railframe":
            out.append(ca.DM([0.0, 0.0, 1.0]))
            continue
        zeros = ca.MX.zeros(q.shape[0])
        _, _, p = kernel_inputs(e, q, zeros, s, ca.MX.zeros(s.shape[0]))
        out.append(e.normal_fn(s[e.s_index : e.s_index + 4], p))
    return ca.vertcat(*out) if out else ca.MX(0, 1)


def has_creep(model) -> bool:
    return any(e.creep_fn is not None for e in model.wheelrail)
