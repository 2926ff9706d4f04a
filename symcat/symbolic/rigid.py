"""Rigid bodies with Euler parameters (SymPy).

Reference coordinates ``q = [R, theta]`` (eq. 1 of the seed paper): the position of the body
frame ``R`` (m) and the Euler parameters ``theta = [e0, e1, e2, e3]`` (singularity-free; the
normalization ``theta . theta = 1`` is a constraint of the system). With ``A(theta)`` the rotation
matrix and ``omega_bar = 2 G_bar(theta) theta_dot`` the angular velocity in the body frame, the
kinetic energy is ``T = m/2 R_dot . R_dot + 1/2 omega_bar^T J omega_bar``. Only ``T`` is derived
here; the mass matrix ``d2T/dv2`` and the quadratic velocity vector
``Q_v = dT/dq - d(dT/dv)/dq v`` come from CasADi's differentiation of it.
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

RIGID_PARAMS = (
    ("mass", "kg", "mass"),
    ("Jxx", "kg m^2", "inertia about the body x axis (at the centre of mass)"),
    ("Jyy", "kg m^2", "inertia about the body y axis"),
    ("Jzz", "kg m^2", "inertia about the body z axis"),
    ("Jxy", "kg m^2", "product of inertia (J = [[Jxx, Jxy, Jxz], [Jxy, Jyy, Jyz], [Jxz, Jyz, Jzz]])"),
    ("Jxz", "kg m^2", "product of inertia"),
    ("Jyz", "kg m^2", "product of inertia"),
)


def rotation_matrix(theta: sp.Matrix) -> sp.Matrix:
    """``A(theta) = (2 e0^2 - 1) I + 2 (e e^T + e0 e~)`` for Euler parameters ``theta``."""
    e0 = theta[0]
    e = theta[1:4, 0]
    return (2 * e0**2 - 1) * sp.eye(3) + 2 * (e * e.T + e0 * skew(e))


def g_bar(theta: sp.Matrix) -> sp.Matrix:
    """``G_bar`` with ``omega_bar = 2 G_bar theta_dot`` (body-frame angular velocity)."""
    e0, e1, e2, e3 = theta
    return sp.Matrix([[-e1, e0, e3, -e2], [-e2, -e3, e0, e1], [-e3, e2, -e1, e0]])


def skew(v: sp.Matrix) -> sp.Matrix:
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


@dataclass
class RigidDefinition:
    q: sp.Matrix
    v: sp.Matrix
    p: sp.Matrix
    kinetic_energy: sp.Expr


def rigid_body() -> RigidDefinition:
    """Symbolic rigid body: coordinates, velocities, inertia parameters and kinetic energy."""
    q = sp.Matrix(sp.symbols("R_x R_y R_z e_0 e_1 e_2 e_3", real=True))
    v = sp.Matrix(sp.symbols("Rd_x Rd_y Rd_z ed_0 ed_1 ed_2 ed_3", real=True))
    p = sp.Matrix([sp.Symbol(name, real=True) for name, _, _ in RIGID_PARAMS])
    mass, jxx, jyy, jzz, jxy, jxz, jyz = p
    inertia = sp.Matrix([[jxx, jxy, jxz], [jxy, jyy, jyz], [jxz, jyz, jzz]])
    omega = 2 * g_bar(q[3:7, 0]) * v[3:7, 0]
    r_dot = v[0:3, 0]
    energy = mass * r_dot.dot(r_dot) / 2 + (omega.T * inertia * omega)[0, 0] / 2
    return RigidDefinition(q=q, v=v, p=p, kinetic_energy=energy)
