"""Gradient-deficient ANCF cable elements: planar (2 x 4) and spatial (2 x 6).

Nodal coordinates are ``[r, r_x]``; the position is interpolated by cubic Hermite functions.
The local kinematic quantities are ``g = [a, a_x]`` with ``a = r_x`` and ``a_x = r_xx``. The
strain energy per unit stress-free length is ``EA/2 eps^2 + EI/2 |kappa|^2`` with

* ``eps = |a| (1 + prestrain) - 1`` the engineering strain against the stress-free length
  (exact for an elastic string: the tension is ``EA eps``), and
* ``kappa = a x a_x / |a|^2`` (a signed scalar in 2D, a vector in 3D), the rotation rate of
  the tangent per unit *reference* length, ``d theta / dx``. This is the bending strain of an
  extensible Kirchhoff rod: a pure end moment gives exactly ``d theta / dx = M / EI`` whatever
  the stretch. (The geometric curvature ``|a x a_x| / |a|^3``, per unit deformed length,
  would couple bending to stretching and spoil the roll-up to a full circle.) Rigid motions,
  however large, store no energy.

Mass and weight are those of the stress-free material: a mesh length ``L`` holds
``rho A L / (1 + prestrain)`` kilograms.

Damping is Kelvin-Voigt on the rates of the small-strain measures ``(1 + prestrain) a.a / 2``
and ``a x a_x`` (equal to ``eps`` and ``kappa`` to first order in the strain). In 3D the
curvature vector is expressed in the global frame, so its rate is made objective by removing
the rotation of the tangent, ``k_dot - (t x t_dot) x k``; a spin about the tangent itself is invisible to a
cable without a material frame, so a curved 3D cable spinning rigidly about its own tangent is
(weakly) damped. A straight cable is never damped by rigid motion.
"""
from __future__ import annotations

import sympy as sp

from ..catalog import ELEMENT_TYPES
from .element import ElementDefinition, linear_map, node_vectors, param_specs, param_symbols, symbols_vector
from .shape_functions import hermite_cubic, interpolate


def _cross2(a: sp.Matrix, b: sp.Matrix) -> sp.Expr:
    return a[0] * b[1] - a[1] * b[0]


def cable(dim: int) -> ElementDefinition:
    """Build the planar (``dim=2``) or spatial (``dim=3``) ANCF cable element."""
    if dim not in (2, 3):
        raise ValueError(f"dim={dim}: must be 2 or 3")
    e = symbols_vector("e", 4 * dim)
    spec = ELEMENT_TYPES[f"cable{dim}d"]
    p = param_symbols(spec.params)
    length, E, A, I, rho, prestrain, tau_axial, tau_bending = p
    xi = sp.Symbol("xi", real=True)

    shape = hermite_cubic(xi, length)
    r = interpolate(shape, node_vectors(e, dim))
    r_x = r.diff(xi) / length
    r_xx = r_x.diff(xi) / length

    a = sp.Matrix(sp.symbols(f"a_0:{dim}", real=True))
    a_x = sp.Matrix(sp.symbols(f"ax_0:{dim}", real=True))
    local = sp.Matrix.vstack(a, a_x)
    local_map = linear_map(sp.Matrix.vstack(r_x, r_xx), e)

    stretch2 = a.dot(a)
    eps = sp.sqrt(stretch2) * (1 + prestrain) - 1
    if dim == 2:
        kappa = sp.Matrix([_cross2(a, a_x) / stretch2])
    else:
        kappa = a.cross(a_x) / stretch2
    scale = 1 / (1 + prestrain)  # mesh length -> stress-free length
    energy_density = scale * (E * A * eps**2 / 2 + E * I * kappa.dot(kappa) / 2)
    # Damping acts on the rates of the small-strain measures a.a/2 and a x a_x, which differ
    # from eps and kappa by O(eps) (a relative change of the damping of order 1e-3 for wires)
    # but cost a fraction to differentiate.
    bend = [_cross2(a, a_x)] if dim == 2 else list(a.cross(a_x))
    damped = [(a.dot(a) / 2 * (1 + prestrain), E * A, tau_axial)] + [(k, E * I, tau_bending) for k in bend]

    # Exact mass matrix: integrate the Hermite products over the element.
    x = sp.Symbol("x")
    shape_x = [sp.expand(s.subs(xi, x / length)) for s in shape]
    rho_a = rho * A * scale
    blocks = sp.zeros(4, 4)
    for i in range(4):
        for j in range(i, 4):
            blocks[i, j] = blocks[j, i] = sp.factor(sp.integrate(shape_x[i] * shape_x[j], (x, 0, length)))
    mass = sp.kronecker_product(blocks, sp.eye(dim)) * rho_a
    gravity = sp.kronecker_product(
        sp.Matrix([sp.integrate(s, (x, 0, length)) for s in shape_x]), sp.eye(dim)
    ) * rho_a

    return ElementDefinition(
        name=f"cable{dim}d",
        dim=dim,
        node_coordinates=list(spec.node_coordinates),
        e=e,
        params=param_specs(spec.params),
        p=p,
        xi=xi,
        local=local,
        local_map=local_map,
        position=r,
        slope=r_x,
        energy_density=energy_density,
        damped_strains=damped,
        rate_tangent=a / sp.sqrt(stretch2) if dim == 3 else None,
        axial_strain=eps,
        bending_strain=kappa,
        mass_matrix=mass,
        gravity_shape=gravity,
        gauss_points=4,
        description=(
            f"{'planar' if dim == 2 else 'spatial'} gradient-deficient ANCF cable, "
            f"2 nodes x {2 * dim} coordinates [r, r_x]"
        ),
    )


def cable2d() -> ElementDefinition:
    """Planar ANCF cable (2 nodes x 4 coordinates)."""
    return cable(2)


def cable3d() -> ElementDefinition:
    """Spatial gradient-deficient ANCF cable (2 nodes x 6 coordinates)."""
    return cable(3)
