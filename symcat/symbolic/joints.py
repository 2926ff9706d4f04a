"""Kinematic constraints (SymPy): joints between bodies of given kinds, and the sliding joint.

A constraint ``C(y, t; p) = 0`` is written in the local coordinates ``y = [x_i, x_j, s]`` of the
bodies it connects (``s``: the non-generalized arc-length parameters of a sliding joint) and the
time ``t``. Only ``C`` is derived here; its Jacobians ``C_y``, ``C_t`` and the acceleration term
``Q_d`` (all of ``d2C/dt2`` except ``C_y y_ddot``) are formed by CasADi in
:mod:`symcat.codegen.constraints`.

Body kinds:

``ground``   no coordinates; a point is a parameter, the frame is the identity.
``rigid``    ``[R, theta]`` (7); a point is ``R + A u_bar`` with ``u_bar`` a parameter.
``node``     an ANCF node's position (3 coordinates).
``cable3d``, ``beam3d``  the coordinates of one ANCF element plus ``s`` (sliding joints).
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..catalog import ELEMENT_TYPES
from .rigid import rotation_matrix
from .shape_functions import hermite_cubic, interpolate, shabana_yakoub
from .element import node_vectors


@dataclass
class ConstraintDefinition:
    """Symbolic constraint: equations ``c`` in ``y = [x_i, x_j, s]``, time ``t`` and params ``p``."""

    name: str
    x_i: sp.Matrix
    x_j: sp.Matrix
    s: sp.Matrix
    t: sp.Symbol
    p: sp.Matrix
    param_names: list[str]
    c: sp.Matrix
    description: str

    @property
    def y(self) -> sp.Matrix:
        return sp.Matrix.vstack(self.x_i, self.x_j, self.s)


class _Side:
    """Coordinates, parameters and point/frame expressions of one body of a joint."""

    def __init__(self, kind: str, tag: str):
        self.kind = kind
        self.tag = tag
        self.params: list[sp.Symbol] = []
        if kind == "ground":
            self.x = sp.zeros(0, 1)
            self.rotation = sp.eye(3)
            self.origin = sp.zeros(3, 1)
        elif kind == "rigid":
            self.x = sp.Matrix(sp.symbols(f"R{tag}_0:3 th{tag}_0:4", real=True))
            self.rotation = rotation_matrix(self.x[3:7, 0])
            self.origin = self.x[0:3, 0]
        elif kind == "node":
            self.x = sp.Matrix(sp.symbols(f"r{tag}_0:3", real=True))
            self.rotation = sp.eye(3)
            self.origin = self.x
        else:
            raise ValueError(f"body kind {kind!r}")

    def vector(self, name: str) -> sp.Matrix:
        """A body-fixed vector parameter, in global components."""
        bar = sp.Matrix(sp.symbols(f"{name}{self.tag}_0:3", real=True))
        self.params += list(bar)
        return self.rotation * bar

    def point(self, name: str = "u") -> sp.Matrix:
        """A body-fixed point parameter (ground: a global point), in global coordinates."""
        return self.origin + self.vector(name)


def _joint(name, kind_i, kind_j, build, description, extra_params=()):
    side_i, side_j = _Side(kind_i, "i"), _Side(kind_j, "j")
    t = sp.Symbol("t", real=True)
    extra = [sp.Symbol(n, real=True) for n in extra_params]
    c = build(side_i, side_j, t, *extra)
    params = side_i.params + side_j.params + extra
    return ConstraintDefinition(
        name=f"{name}_{kind_i}_{kind_j}", x_i=side_i.x, x_j=side_j.x, s=sp.zeros(0, 1), t=t,
        p=sp.Matrix(params), param_names=[str(s) for s in params], c=c, description=description,
    )


def spherical(kind_i: str, kind_j: str) -> ConstraintDefinition:
    """Coincident points: ``r_i(u_i) - r_j(u_j) = 0`` (3 equations)."""
    return _joint("spherical", kind_i, kind_j, lambda a, b, t: a.point() - b.point(), "coincident points")


def revolute(kind_i: str, kind_j: str) -> ConstraintDefinition:
    """Spherical joint plus the axis ``z_i`` normal to ``x_j`` and ``y_j`` (5 equations)."""

    def build(a, b, t):
        axis = a.vector("z")
        return sp.Matrix.vstack(a.point() - b.point(), sp.Matrix([axis.dot(b.vector("x")), axis.dot(b.vector("y"))]))

    return _joint("revolute", kind_i, kind_j, build, "rotation about the common axis z_i")


def prismatic(kind_i: str, kind_j: str) -> ConstraintDefinition:
    """Translation along ``a_i`` only: ``n1_i, n2_i`` normal to ``d``, orientations locked (5)."""

    def build(a, b, t):
        n1, n2 = a.vector("n1"), a.vector("n2")
        d = b.point() - a.point()
        m1, axis_j = b.vector("m1"), b.vector("a")
        return sp.Matrix([n1.dot(d), n2.dot(d), n1.dot(axis_j), n2.dot(axis_j), n2.dot(m1)])

    return _joint("prismatic", kind_i, kind_j, build, "translation along a common axis")


def fixed(kind_i: str, kind_j: str) -> ConstraintDefinition:
    """Coincident points and locked orientation (6 equations)."""

    def build(a, b, t):
        xi, yi, zi = a.vector("x"), a.vector("y"), a.vector("z")
        xj, yj, zj = b.vector("x"), b.vector("y"), b.vector("z")
        return sp.Matrix.vstack(a.point() - b.point(), sp.Matrix([xi.dot(yj), yi.dot(zj), zi.dot(xj)]))

    return _joint("fixed", kind_i, kind_j, build, "rigid connection")


def driving(kind_i: str) -> ConstraintDefinition:
    """Prescribed motion of a point along a direction ``n`` (1 equation):
    ``n . r_i(u) = x0 + v t + amp sin(omega t + phase)``."""

    def build(a, b, t, x0, vel, amp, omega, phase):
        n = sp.Matrix(sp.symbols("n_0:3", real=True))
        a.params += list(n)
        return sp.Matrix([n.dot(a.point()) - (x0 + vel * t + amp * sp.sin(omega * t + phase))])

    return _joint("driving", kind_i, "ground", build, "prescribed point motion along a direction",
                  extra_params=("x0", "velocity", "amplitude", "omega", "phase"))


def euler_normalization() -> ConstraintDefinition:
    """``theta . theta - 1 = 0`` for a rigid body's Euler parameters."""
    side = _Side("rigid", "i")
    t = sp.Symbol("t", real=True)
    th = side.x[3:7, 0]
    return ConstraintDefinition(
        name="normalization_rigid", x_i=side.x, x_j=sp.zeros(0, 1), s=sp.zeros(0, 1), t=t, p=sp.zeros(0, 1),
        param_names=[], c=sp.Matrix([(th.dot(th) - 1) / 2]), description="Euler parameter normalization",
    )


def wire_point(element: str, xi_of_s: sp.Expr, e: sp.Matrix, length: sp.Symbol):
    """Centre-line position, slope ``r_s`` and (beam only) ``r_y`` of an ANCF element at ``xi``."""
    etype = ELEMENT_TYPES[element]
    if element == "beam3d":
        eta, zeta = sp.symbols("eta zeta", real=True)
        xi = sp.Symbol("xi_", real=True)
        r = interpolate(shabana_yakoub(xi, eta / length, zeta / length, length), node_vectors(e, 3))
        centre = r.subs({eta: 0, zeta: 0})
        r_s = centre.diff(xi) / length
        r_y = r.diff(eta).subs({eta: 0, zeta: 0})
        sub = {xi: xi_of_s}
        return centre.subs(sub), r_s.subs(sub), r_y.subs(sub)
    xi = sp.Symbol("xi_", real=True)
    r = interpolate(hermite_cubic(xi, length), node_vectors(e, etype.dim))
    return r.subs(xi, xi_of_s), (r.diff(xi) / length).subs(xi, xi_of_s), None


@dataclass
class WireFrame:
    """A body point against an ANCF element's centre line at arc length ``s``: the tangent
    frame ``i_t, j_t, k_t`` (seed eq. 9) and ``d = r^i(s) - r_P^j``; shared by the sliding
    joint and the unilateral contact so both use one frame convention."""

    e: sp.Matrix
    s: sp.Symbol
    side_j: "_Side"
    params: list
    i_t: sp.Matrix
    j_t: sp.Matrix
    k_t: sp.Matrix
    d: sp.Matrix


def wire_frame(element: str, kind_j: str = "rigid") -> WireFrame:
    """Tangent frame and relative position of a body point and an ANCF element (see
    :func:`sliding`); parameters ``[L, (d_ref_0:3 for cables), body j's parameters]``."""
    etype = ELEMENT_TYPES[element]
    e = sp.Matrix(sp.symbols(f"e_0:{etype.n_coordinates}", real=True))
    s = sp.Symbol("s", real=True)
    length = sp.Symbol("L", real=True)
    r_i, r_s, r_y = wire_point(element, s / length, e, length)
    side_j = _Side(kind_j, "j")
    params = [length]
    if r_y is None:
        d_ref = sp.Matrix(sp.symbols("d_ref_0:3", real=True))
        params += list(d_ref)
        r_y = d_ref
    i_t = r_s / sp.sqrt(r_s.dot(r_s))
    k_raw = i_t.cross(r_y)
    k_t = k_raw / sp.sqrt(k_raw.dot(k_raw))
    d = r_i - side_j.point()  # point() declares body j's parameters
    return WireFrame(e, s, side_j, params + list(side_j.params), i_t, k_t.cross(i_t), k_t, d)


def sliding(element: str, kind_j: str = "rigid") -> ConstraintDefinition:
    """Sliding joint of seed eqs. (5)-(9): a point of body j on the centre line of ANCF element i.

    ``C = A_t^T (r_P^i(s) - r_P^j)`` with the tangent frame ``i_t = r_s/|r_s|``,
    ``k_t = i_t x r_y / |i_t x r_y|``, ``j_t = k_t x i_t`` (eq. 9). The beam uses its gradient
    ``r_y``; the gradient-deficient cable has none and uses a fixed reference direction ``d_ref``
    (a parameter, global; the frame is then ``k_t = i_t x d_ref / |.|``): choose ``d_ref`` across
    the wire, e.g. the global y axis for a wire along x. ``s`` is the arc-length coordinate of the
    element, ``xi = s / L`` (the element is straight in its reference configuration, so s equals
    the undeformed arc length, as in the paper).
    """
    f = wire_frame(element, kind_j)
    c = sp.Matrix([f.i_t.dot(f.d), f.j_t.dot(f.d), f.k_t.dot(f.d)])
    e, s, side_j, params = f.e, f.s, f.side_j, f.params
    return ConstraintDefinition(
        name=f"sliding_{element}_{kind_j}", x_i=e, x_j=side_j.x, s=sp.Matrix([s]), t=sp.Symbol("t", real=True),
        p=sp.Matrix(params), param_names=[str(x) for x in params], c=c,
        description="point of body j on the centre line of an ANCF element, tangent-frame form (seed eq. 7)",
    )


#: Constraint libraries symcat generates: name -> builder.
CONSTRAINTS = {
    **{f"spherical_{a}_{b}": (lambda a=a, b=b: spherical(a, b)) for a, b in
       [("rigid", "rigid"), ("rigid", "ground"), ("node", "rigid"), ("node", "ground")]},
    **{f"revolute_{a}_{b}": (lambda a=a, b=b: revolute(a, b)) for a, b in [("rigid", "rigid"), ("rigid", "ground")]},
    **{f"prismatic_{a}_{b}": (lambda a=a, b=b: prismatic(a, b)) for a, b in [("rigid", "rigid"), ("rigid", "ground")]},
    **{f"fixed_{a}_{b}": (lambda a=a, b=b: fixed(a, b)) for a, b in [("rigid", "rigid"), ("rigid", "ground")]},
    "driving_rigid_ground": lambda: driving("rigid"),
    "normalization_rigid": euler_normalization,
    "sliding_cable3d_rigid": lambda: sliding("cable3d"),
    "sliding_beam3d_rigid": lambda: sliding("beam3d"),
}
