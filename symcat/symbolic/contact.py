"""Unilateral wire contact (SymPy kinematics): seed paper Section 8.

A point ``P`` of a rigid body (the pan-head's contact point, body-frame position ``u_j``)
meets the centre line of ANCF element ``i`` at arc length ``s``. With ``d = r^i(s) - r_P^j``
and the tangent frame ``(i_t, j_t, k_t)`` of the sliding joint (seed eq. 9, see
:func:`symcat.symbolic.joints.sliding`):

``T = i_t . d = 0``  (tangency, the first row of seed eq. 7)
    locates the wire point closest to ``P`` (the wire point directly above the pan-head for
    a wire along x). It is an algebraic equation for ``s`` with no multiplier.
``g = k_t . d``  (normal gap, the third row of eq. 7)
    is positive while the wire is above ``P`` (separated) and negative when ``P`` has pushed
    into the wire; the penetration ``-g`` drives a penalty force along ``k_t``.

``T`` and ``g`` are derived here; the force law (penalty, damping only in contact, never
pulling) is applied in CasADi by :func:`symcat.codegen.multibody_kernels.contact_functions`.
The generalized force is ``Q = f J_d^T n`` with ``J_d = dd/d[e, x_j]`` and the normal
``n = k_t`` held fixed: equal and opposite forces ``+f n`` on the wire and ``-f n`` on the body
at the contact point.
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from .joints import wire_frame


@dataclass
class ContactDefinition:
    """Symbolic wire contact: coordinates ``y = [e, x_j, s]``, parameters, ``T``, ``g``, ``d``, ``n``."""

    name: str
    e: sp.Matrix
    x_j: sp.Matrix
    s: sp.Symbol
    p: sp.Matrix
    param_names: list[str]
    tangency: sp.Expr
    gap: sp.Expr
    d: sp.Matrix
    normal: sp.Matrix
    description: str

    @property
    def y(self) -> sp.Matrix:
        return sp.Matrix.vstack(self.e, self.x_j, sp.Matrix([self.s]))


def wire_contact(element: str, kind_j: str = "rigid") -> ContactDefinition:
    """Tangency condition and normal gap between a body point and an ANCF element's centre line.

    Parameters are ``[L, (d_ref_0:3 for cables), uj_0:3]``, as for the sliding joint, so the
    same frame conventions hold (``k_t`` is up for a wire along x with ``d_ref`` = y).
    """
    f = wire_frame(element, kind_j)
    e, s, side_j, params, d, k_t = f.e, f.s, f.side_j, f.params, f.d, f.k_t
    i_t = f.i_t
    return ContactDefinition(
        name=f"contact_{element}_{kind_j}", e=e, x_j=side_j.x, s=s, p=sp.Matrix(params),
        param_names=[str(x) for x in params], tangency=i_t.dot(d), gap=k_t.dot(d), d=d, normal=k_t,
        description="unilateral contact of a body point with an ANCF centre line (seed Section 8)",
    )


#: Contact libraries symcat generates: name -> builder.
CONTACTS = {
    "contact_cable3d_rigid": lambda: wire_contact("cable3d"),
    "contact_beam3d_rigid": lambda: wire_contact("beam3d"),
}
