"""Force elements between bodies (SymPy kinematics; the force laws are applied in CasADi).

``springdamper_<ki>_<kj>``: the distance ``l`` between a point of body i and a point of body j;
the force law ``F = k (l - l0) + k3 (l - l0)^3 + c l_dot`` (tension positive) acts along the
line of the points, and with ``tension_only = 1`` it vanishes whenever ``l <= l0`` or ``F < 0``
(droppers).
``rotspring_<ki>_<kj>``: the relative rotation angle ``phi`` about the axis ``z_i`` of body i,
measured from ``x_i`` to the projection of ``x_j`` (atan2, so it is smooth through any number of
turns locally); torque ``k (phi - phi0) + c phi_dot``.
``pointload_rigid``: a force ``F(t) = F0 + F1 sin(omega t + phase)`` (N, global) at a body point
and a torque ``T(t) = T0 + T1 sin(omega t + phase)`` (N m, global).
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from .joints import _Side
from .rigid import g_bar


@dataclass
class ForceDefinition:
    name: str
    x_i: sp.Matrix
    x_j: sp.Matrix
    p: sp.Matrix
    param_names: list[str]
    measure: sp.Expr | None       # l or phi, for springs
    work_terms: sp.Matrix | None  # for loads: generalized force expressions directly
    t: sp.Symbol
    description: str

    @property
    def y(self) -> sp.Matrix:
        return sp.Matrix.vstack(self.x_i, self.x_j)


def springdamper(kind_i: str, kind_j: str) -> ForceDefinition:
    a, b = _Side(kind_i, "i"), _Side(kind_j, "j")
    d = b.point() - a.point()
    law = sp.symbols("l0 k k3 c tension_only", real=True)
    params = a.params + b.params + list(law)
    return ForceDefinition(f"springdamper_{kind_i}_{kind_j}", a.x, b.x, sp.Matrix(params), [str(x) for x in params],
                           sp.sqrt(d.dot(d)), None, sp.Symbol("t", real=True), "point-to-point spring-damper")


def rotspring(kind_i: str, kind_j: str) -> ForceDefinition:
    a, b = _Side(kind_i, "i"), _Side(kind_j, "j")
    z, x_i, x_j = a.vector("z"), a.vector("x"), b.vector("x")
    phi = sp.atan2(z.cross(x_i).dot(x_j), x_i.dot(x_j))
    law = sp.symbols("phi0 k c", real=True)
    params = a.params + b.params + list(law)
    return ForceDefinition(f"rotspring_{kind_i}_{kind_j}", a.x, b.x, sp.Matrix(params), [str(x) for x in params],
                           phi, None, sp.Symbol("t", real=True), "rotational spring-damper about z_i")


def pointload() -> ForceDefinition:
    a = _Side("rigid", "i")
    t = sp.Symbol("t", real=True)
    r = a.point()
    f0, f1, t0, t1 = (sp.Matrix(sp.symbols(f"{n}_0:3", real=True)) for n in ("F0", "F1", "T0", "T1"))
    omega, phase = sp.symbols("omega phase", real=True)
    wave = sp.sin(omega * t + phase)
    force = f0 + f1 * wave
    torque = t0 + t1 * wave
    theta = a.x[3:7, 0]
    q_r = r.jacobian(a.x).T * force
    # Virtual rotation (global) = A * 2 G_bar * d theta, so Q_theta = 2 G_bar^T A^T T.
    q_theta = 2 * g_bar(theta).T * a.rotation.T * torque
    q = q_r + sp.Matrix.vstack(sp.zeros(3, 1), q_theta)
    params = a.params + list(f0) + list(f1) + list(t0) + list(t1) + [omega, phase]
    return ForceDefinition("pointload_rigid", a.x, sp.zeros(0, 1), sp.Matrix(params), [str(x) for x in params],
                           None, q, t, "force at a body point and torque, constant plus sinusoid")


FORCES = {
    **{f"springdamper_{a}_{b}": (lambda a=a, b=b: springdamper(a, b)) for a, b in
       [("rigid", "rigid"), ("rigid", "ground"), ("node", "rigid"), ("node", "ground"), ("node", "node")]},
    **{f"rotspring_{a}_{b}": (lambda a=a, b=b: rotspring(a, b)) for a, b in [("rigid", "rigid"), ("rigid", "ground")]},
    "pointload_rigid": pointload,
}
