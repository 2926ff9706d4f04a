"""Force elements between bodies (SymPy kinematics; the force laws are applied in CasADi).

``springdamper_<ki>_<kj>``: the distance ``l`` between a point of body i and a point of body j;
the force law ``F = k (l - l0) + k3 (l - l0)^3 + c l_dot`` (tension positive) acts along the
line of the points, and with ``tension_only = 1`` it vanishes whenever ``l <= l0`` or ``F < 0``
(droppers).
``rotspring_<ki>_<kj>``: the relative rotation angle ``phi`` about the axis ``z_i`` of body i,
measured from ``x_i`` to the projection of ``x_j`` (atan2, so it is smooth through any number of
turns locally); torque ``k (phi - phi0 - rate t) + c (phi_dot - rate)``. With ``k = 0`` and a
``rate`` it is a speed servo (a motor holding the relative angular velocity ``rate``), smooth
through any number of turns.
``bushing_<ki>_<kj>``: three orthogonal spring-dampers and three torsion springs at a point,
in axes ``x_i, y_i, z_i`` fixed in body i. The measures are the displacement
``d = [x_i, y_i, z_i]^T (r_j(P) - r_i(P))`` of body j's point from body i's point (zero in the
initial configuration) and the small relative rotation
``theta = 1/2 [z_i . y_j - y_i . z_j, x_i . z_j - z_i . x_j, y_i . x_j - x_i . y_j]``
(body j's copies of the same axes); the law is applied in CasADi (see
:mod:`symcat.codegen.multibody_kernels`).
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


def bushing(kind_i: str, kind_j: str) -> ForceDefinition:
    a, b = _Side(kind_i, "i"), _Side(kind_j, "j")
    d = b.point() - a.point()
    x_i, y_i, z_i = a.vector("x"), a.vector("y"), a.vector("z")
    x_j, y_j, z_j = b.vector("x"), b.vector("y"), b.vector("z")
    theta = sp.Matrix([z_i.dot(y_j) - y_i.dot(z_j), x_i.dot(z_j) - z_i.dot(x_j), y_i.dot(x_j) - x_i.dot(y_j)]) / 2
    measure = sp.Matrix.vstack(sp.Matrix([x_i.dot(d), y_i.dot(d), z_i.dot(d)]), theta)
    law = [sp.Symbol(f"{n}_{k}", real=True) for n in BUSHING_LAW for k in range(3)]
    params = a.params + b.params + law
    return ForceDefinition(f"bushing_{kind_i}_{kind_j}", a.x, b.x, sp.Matrix(params), [str(x) for x in params],
                           measure, None, sp.Symbol("t", real=True), "bushing: orthogonal translational and torsion springs")


#: Bushing law parameters, 3 components each (in the bushing axes): stiffness (N/m), damping
#: (N s/m), force on body j at zero deflection (N), free play before the stop (m), stop stiffness
#: (N/m), torsion stiffness (N m/rad), torsion damping (N m s/rad).
BUSHING_LAW = ("k", "c", "f0", "gap", "kstop", "kr", "cr")


def rotspring(kind_i: str, kind_j: str) -> ForceDefinition:
    a, b = _Side(kind_i, "i"), _Side(kind_j, "j")
    z, x_i, x_j = a.vector("z"), a.vector("x"), b.vector("x")
    phi = sp.atan2(z.cross(x_i).dot(x_j), x_i.dot(x_j))
    law = sp.symbols("phi0 k c rate", real=True)
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
    **{f"bushing_{a}_{b}": (lambda a=a, b=b: bushing(a, b)) for a, b in [("rigid", "rigid"), ("rigid", "ground")]},
    "pointload_rigid": pointload,
}
