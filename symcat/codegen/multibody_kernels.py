"""CasADi functions of the rigid-body, constraint and force-element libraries.

Rigid body library ``rigid``:
``rigid_mass(q, p) -> M``, ``rigid_qv(q, v, p) -> Qv`` (quadratic velocity vector),
``rigid_energy(q, v, p) -> T``.

Constraint library ``<c>`` with ``y = [x_i, x_j, s]``:
``<c>_c(y, t, p) -> c``; ``<c>_jac(y, t, p) -> c_y, c_t``;
``<c>_gamma(y, y_dot, t, p) -> q_d`` = ``d2c/dt2 - c_y y_ddot`` (the quadratic velocity terms
of seed eq. 14, including the time terms of driving constraints).

Force library ``<f>``: ``<f>(y, y_dot, t, p) -> q`` (generalized force on ``y``).

Every function ships its ``jac_`` companion, so that CasADi differentiates through them with
compiled code (IDAS needs the derivatives of ``c_y^T lambda`` and ``q_d``).
"""
from __future__ import annotations

import casadi as ca

from ..symbolic.force_elements import FORCES
from ..symbolic.joints import CONSTRAINTS
from ..symbolic.rigid import rigid_body
from .sympy_to_casadi import SympyToCasadi, bind

OPTS = {"cse": True}


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
    defn = CONSTRAINTS[name]()
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
        else:
            force = par["k"] * (m - par["phi0"]) + par["c"] * m_dot
        q = -force * ca.gradient(m, y)
    return _with_jacobian(ca.Function(name, [y, y_dot, t, p], [q], ["y", "y_dot", "t", "p"], ["q"], OPTS))


def multibody_library_names() -> list[str]:
    return ["rigid", *sorted(CONSTRAINTS), *sorted(FORCES)]


def multibody_functions(name: str) -> list[ca.Function]:
    if name == "rigid":
        return rigid_functions()
    if name in CONSTRAINTS:
        return constraint_functions(name)
    if name in FORCES:
        return force_functions(name)
    raise KeyError(name)


def interface(name: str) -> dict:
    """Sizes and parameter names recorded in the manifest (read by the runtime without SymPy)."""
    if name == "rigid":
        from ..symbolic.rigid import RIGID_PARAMS

        return {"kind": "rigid", "params": [n for n, _, _ in RIGID_PARAMS]}
    defn = CONSTRAINTS[name]() if name in CONSTRAINTS else FORCES[name]()
    out = {"kind": "constraint" if name in CONSTRAINTS else "force", "params": defn.param_names,
           "n_i": defn.x_i.rows, "n_j": defn.x_j.rows}
    if name in CONSTRAINTS:
        out.update(n_s=defn.s.rows, n_c=defn.c.rows)
    return out
