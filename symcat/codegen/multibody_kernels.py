"""CasADi functions of the rigid-body, constraint and force-element libraries.

Rigid body library ``rigid``:
``rigid_mass(q, p) -> M``, ``rigid_qv(q, v, p) -> Qv`` (quadratic velocity vector),
``rigid_energy(q, v, p) -> T``.

Constraint library ``<c>`` with ``y = [x_i, x_j, s]``:
``<c>_c(y, t, p) -> c``; ``<c>_jac(y, t, p) -> c_y, c_t``;
``<c>_gamma(y, y_dot, t, p) -> q_d`` = ``d2c/dt2 - c_y y_ddot`` (the quadratic velocity terms
of seed eq. 14, including the time terms of driving constraints).

The wheel/rail contact libraries ``wheelrail_global_rigid_ground`` and
``wheelrail_railframe_rigid_ground`` (:mod:`symcat.symbolic.wheelrail`) are constraint libraries
of this form, with ``y = [R, theta, s1w, s2w, s1r, s2r]``.

Force library ``<f>``: ``<f>(y, y_dot, t, p) -> q`` (generalized force on ``y``).

Contact library ``contact_<el>_rigid`` with ``y = [e, x_j, s]`` (see
:mod:`symcat.symbolic.contact`): ``<c>_tangency(y, p) -> T``; ``<c>_force(y, y_dot, p) -> q, gap, f``
with ``y_dot`` the rates of ``[e, x_j]`` (``s_dot`` follows from the tangency condition),
``q`` the generalized force on ``[e, x_j]``, ``gap`` (m, > 0 when separated) and the normal
force ``f`` (N, >= 0). The penalty law is C1 (IDAS sees no kink at contact loss or re-contact)
and exactly zero once separated, with the smoothing depth ``delta`` (m)::

    ramp_d(x) = 0 (x <= 0),  x^2 / (2 d) (0 < x < d),  x - d / 2 (x >= d)
    pen = -gap,  w = smoothstep(pen / delta)               (damping only in contact)
    f = ramp_f0(k ramp_delta(pen) + c w pen_dot),  f0 = k delta   (never pulling)

so ``f = k (pen - delta) + c pen_dot`` in contact, once ``pen > 2 delta``.

Every function ships its ``jac_`` companion, so that CasADi differentiates through them with
compiled code (IDAS needs the derivatives of ``c_y^T lambda`` and ``q_d``).
"""
from __future__ import annotations

import casadi as ca

from ..symbolic.contact import CONTACTS
from ..symbolic.force_elements import FORCES
from ..symbolic.joints import CONSTRAINTS
from ..symbolic.rigid import rigid_body
from ..symbolic.wheelrail import WHEELRAIL_CONSTRAINTS
from .sympy_to_casadi import SympyToCasadi, bind

OPTS = {"cse": True}
#: Every constraint library: the joints plus the wheel/rail contacts (same kernels, ``y = [x_i, x_j, s]``).
ALL_CONSTRAINTS = {**CONSTRAINTS, **WHEELRAIL_CONSTRAINTS}


def _with_jacobian(f: ca.Function) -> list[ca.Function]:
    jac = f.jacobian()
    args = jac.sx_in()
    return [f, ca.Function(jac.name(), args, jac.call(args), jac.name_in(), jac.name_out(), OPTS)]


def rigid_functions() -> list[ca.Function]:
    defn = rigid_body()
    q, v, p = ca.SX.sym("q", 7), ca.SX.sym("v", 7), ca.SX.sym("p", defn.p.rows)
    conv = SympyToCasadi({**bind(defn.q, q), **bind(defn.v, v), **bind(defn.p, p)})
    energy = conv(defn.kinetic_energy)
    mass, momentum = ca.hessian(energy, v)
    qv = ca.gradient(energy, q) - ca.jtimes(momentum, q, v)
    return [
        *_with_jacobian(ca.Function("rigid_mass", [q, p], [mass], ["q", "p"], ["M"], OPTS)),
        *_with_jacobian(ca.Function("rigid_qv", [q, v, p], [qv], ["q", "v", "p"], ["Qv"], OPTS)),
        ca.Function("rigid_energy", [q, v, p], [energy], ["q", "v", "p"], ["T"], OPTS),
    ]


def constraint_functions(name: str) -> list[ca.Function]:
    defn = ALL_CONSTRAINTS[name]()
    ny = defn.y.rows
    y, y_dot, t, p = ca.SX.sym("y", ny), ca.SX.sym("y_dot", ny), ca.SX.sym("t"), ca.SX.sym("p", defn.p.rows)
    conv = SympyToCasadi({**bind(defn.y, y), **bind(defn.p, p), defn.t: t})
    c = conv(defn.c)
    c_y, c_t = ca.jacobian(c, y), ca.jacobian(c, t)
    c_dot = ca.mtimes(c_y, y_dot) + c_t
    gamma = ca.jtimes(c_dot, y, y_dot) + ca.jacobian(c_dot, t)
    return [
        *_with_jacobian(ca.Function(f"{name}_c", [y, t, p], [c], ["y", "t", "p"], ["c"], OPTS)),
        *_with_jacobian(ca.Function(f"{name}_jac", [y, t, p], [c_y, c_t], ["y", "t", "p"], ["c_y", "c_t"], OPTS)),
        *_with_jacobian(ca.Function(f"{name}_gamma", [y, y_dot, t, p], [gamma], ["y", "y_dot", "t", "p"], ["q_d"], OPTS)),
    ]


def force_functions(name: str) -> list[ca.Function]:
    defn = FORCES[name]()
    ny = defn.y.rows
    y, y_dot, t, p = ca.SX.sym("y", ny), ca.SX.sym("y_dot", ny), ca.SX.sym("t"), ca.SX.sym("p", defn.p.rows)
    conv = SympyToCasadi({**bind(defn.y, y), **bind(defn.p, p), defn.t: t})
    names = defn.param_names
    par = {n: p[k] for k, n in enumerate(names)}
    if defn.work_terms is not None:
        q = conv(defn.work_terms)
    else:
        m = conv(defn.measure)
        m_dot = ca.jtimes(m, y, y_dot)
        if name.startswith("springdamper"):
            stretch = m - par["l0"]
            force = par["k"] * stretch + par["k3"] * stretch**3 + par["c"] * m_dot
            slack = ca.logic_and(par["tension_only"] > 0.5, ca.logic_or(stretch <= 0, force < 0))
            force = ca.if_else(slack, 0, force)
            q = -force * ca.gradient(m, y)
        elif name.startswith("bushing"):
            q = _bushing_force(m, m_dot, y, par)
        else:
            force = par["k"] * (m - par["phi0"] - par["rate"] * t) + par["c"] * (m_dot - par["rate"])
            q = -force * ca.gradient(m, y)
    return _with_jacobian(ca.Function(name, [y, y_dot, t, p], [q], ["y", "y_dot", "t", "p"], ["q"], OPTS))


def _bushing_force(m, m_dot, y, par):
    """Generalized force of a bushing: ``-J^T f`` with ``J = dm/dy`` and, per axis,
    ``f = k d + c d_dot - f0 + kstop (max(d - gap, 0) + min(d + gap, 0))`` (translations; the stop
    force is continuous at the free play's edge) and ``f = kr theta + cr theta_dot`` (rotations)."""
    vec = lambda n: ca.vertcat(*(par[f"{n}_{k}"] for k in range(3)))  # noqa: E731
    d, d_dot, theta, theta_dot = m[0:3], m_dot[0:3], m[3:6], m_dot[3:6]
    gap = vec("gap")
    stop = ca.fmax(d - gap, 0) + ca.fmin(d + gap, 0)
    f = ca.vertcat(vec("k") * d + vec("c") * d_dot - vec("f0") + vec("kstop") * stop,
                   vec("kr") * theta + vec("cr") * theta_dot)
    return -ca.mtimes(ca.jacobian(m, y).T, f)


CONTACT_LAW = ("k", "c", "delta")


def _ramp(x, d):
    """C1 ramp: 0 below 0, quadratic up to ``d``, then ``x - d / 2``."""
    return ca.if_else(x <= 0, 0, ca.if_else(x < d, x**2 / (2 * d), x - d / 2))


def _smoothstep(x):
    """C1 step from 0 (x <= 0) to 1 (x >= 1)."""
    t = ca.fmin(ca.fmax(x, 0), 1)
    return t**2 * (3 - 2 * t)


def contact_functions(name: str) -> list[ca.Function]:
    defn = CONTACTS[name]()
    ny = defn.y.rows
    y, y_dot = ca.SX.sym("y", ny), ca.SX.sym("y_dot", ny - 1)
    p = ca.SX.sym("p", defn.p.rows + len(CONTACT_LAW))
    conv = SympyToCasadi({**bind(defn.y, y), **bind(defn.p, p[: defn.p.rows])})
    k, c, delta = (p[defn.p.rows + i] for i in range(len(CONTACT_LAW)))
    tangency, gap, d, normal = conv(defn.tangency), conv(defn.gap), conv(defn.d), conv(defn.normal)
    t_y, g_y = ca.gradient(tangency, y), ca.gradient(gap, y)
    s_dot = -ca.dot(t_y[: ny - 1], y_dot) / t_y[ny - 1]
    pen_dot = -(ca.dot(g_y[: ny - 1], y_dot) + g_y[ny - 1] * s_dot)
    pen = -gap
    f_raw = k * _ramp(pen, delta) + c * _smoothstep(pen / delta) * pen_dot
    force = _ramp(f_raw, k * delta)
    q = force * ca.mtimes(ca.jacobian(d, y[: ny - 1]).T, normal)
    return [
        *_with_jacobian(ca.Function(f"{name}_tangency", [y, p], [tangency], ["y", "p"], ["T"], OPTS)),
        *_with_jacobian(ca.Function(f"{name}_force", [y, y_dot, p], [q, gap, force], ["y", "y_dot", "p"],
                                    ["q", "gap", "f"], OPTS)),
    ]


def multibody_library_names() -> list[str]:
    return ["rigid", *sorted(CONSTRAINTS), *sorted(FORCES), *sorted(CONTACTS), *sorted(WHEELRAIL_CONSTRAINTS)]


def multibody_functions(name: str) -> list[ca.Function]:
    if name == "rigid":
        return rigid_functions()
    if name in ALL_CONSTRAINTS:
        return constraint_functions(name)
    if name in FORCES:
        return force_functions(name)
    if name in CONTACTS:
        return contact_functions(name)
    raise KeyError(name)


def interface(name: str) -> dict:
    """Sizes and parameter names recorded in the manifest (read by the runtime without SymPy)."""
    if name == "rigid":
        from ..symbolic.rigid import RIGID_PARAMS

        return {"kind": "rigid", "params": [n for n, _, _ in RIGID_PARAMS]}
    if name in CONTACTS:
        defn = CONTACTS[name]()
        return {"kind": "contact", "params": defn.param_names + list(CONTACT_LAW), "n_i": defn.e.rows,
                "n_j": defn.x_j.rows, "n_s": 1}
    defn = ALL_CONSTRAINTS[name]() if name in ALL_CONSTRAINTS else FORCES[name]()
    out = {"kind": "constraint" if name in ALL_CONSTRAINTS else "force", "params": defn.param_names,
           "n_i": defn.x_i.rows, "n_j": defn.x_j.rows}
    if name in ALL_CONSTRAINTS:
        out.update(n_s=defn.s.rows, n_c=defn.c.rows)
    return out
