"""Fully parameterized 3D ANCF beam (2 nodes x 12 coordinates) with locking-free elastic forces.

Nodal coordinates are ``[r, r_x, r_y, r_z]``; the position field is the Shabana-Yakoub
interpolation. The elastic forces use *elastic-line* (structural) strain measures rather than
the continuum Green-Lagrange strain, because the plain St. Venant-Kirchhoff continuum energy of
this element locks in the thin-beam limit (Poisson locking through the linear cross-section
field, shear locking through the mismatch of the cubic ``r_x`` and the linear ``r_y``).
With ``a = r_x``, ``b = r_y``, ``c = r_z`` on the centre line:

* axial strain ``eps = |a| (1 + prestrain) - 1``;
* bending curvatures ``kappa_y, kappa_z``: the centre-line rotation rate per unit reference
  length ``a x a_x / |a|^2`` (see :mod:`symcat.symbolic.cable`) resolved on the cross-section directors
  ``d3 = a x b / |a x b|`` and ``d2 = d3 x a / |a|``;
* torsion ``kappa_x = (c . b_x - b . c_x) / (2 |b| |c|)``;
* shear ``gamma_y, gamma_z`` (cosines between ``a`` and ``b``, ``c``), the cross-section strains
  ``|b| - 1, |c| - 1`` and ``gamma_yz``, which keep the gradients an orthonormal frame attached
  to the centre line.

Axial, bending and torsion energies use Gauss quadrature; the shear and cross-section energies
are collocated at the two nodes, where the nodal gradients can satisfy them exactly for any
centre-line shape, so they cannot stiffen bending (no shear locking), and Poisson's ratio enters
only through ``G`` (no Poisson locking). The centre line behaves as an Euler-Bernoulli beam with
torsion, which is what slender wires need; transverse shear deformation of the centre line is
neglected.
"""
from __future__ import annotations

import sympy as sp

from ..catalog import ELEMENT_TYPES
from .element import ElementDefinition, linear_map, node_vectors, param_specs, param_symbols, symbols_vector
from .shape_functions import interpolate, shabana_yakoub

def _section_integral(expr: sp.Expr, y: sp.Symbol, z: sp.Symbol, A, Iy, Iz) -> sp.Expr:
    """Integrate a polynomial in (y, z) over a doubly symmetric cross-section."""
    poly = sp.Poly(sp.expand(expr), y, z)
    moments = {(0, 0): A, (2, 0): Iz, (0, 2): Iy}
    total = sp.Integer(0)
    for (i, j), coeff in poly.terms():
        if i + j > 2:
            raise ValueError("mass integrand of degree > 2 in the section coordinates")
        total += coeff * moments.get((i, j), 0)  # odd moments vanish by symmetry
    return total


def beam3d() -> ElementDefinition:
    """Build the fully parameterized 3D ANCF beam element."""
    e = symbols_vector("e", 24)
    spec = ELEMENT_TYPES["beam3d"]
    p = param_symbols(spec.params)
    length, E, G, A, Iy, Iz, J, kshear, rho, prestrain, tau_axial, tau_bending = p
    xi = sp.Symbol("xi", real=True)
    y, z = sp.symbols("y z", real=True)

    shape = shabana_yakoub(xi, y / length, z / length, length)
    r = interpolate(shape, node_vectors(e, 3))
    centre = r.subs({y: 0, z: 0})
    r_x = centre.diff(xi) / length
    r_y = r.diff(y).subs({y: 0, z: 0})
    r_z = r.diff(z).subs({y: 0, z: 0})
    kinematics = sp.Matrix.vstack(r_x, r_x.diff(xi) / length, r_y, r_z, r_y.diff(xi) / length, r_z.diff(xi) / length)

    names = ["a", "ax", "b", "c", "bx", "cx"]
    vecs = [sp.Matrix(sp.symbols(f"{n}_0:3", real=True)) for n in names]
    a, a_x, b, c, b_x, c_x = vecs
    local = sp.Matrix.vstack(*vecs)

    a_norm = sp.sqrt(a.dot(a))
    b_norm = sp.sqrt(b.dot(b))
    c_norm = sp.sqrt(c.dot(c))
    eps = a_norm * (1 + prestrain) - 1
    curvature = a.cross(a_x) / a.dot(a)  # rotation rate per unit reference length
    n3 = a.cross(b)
    d3 = n3 / sp.sqrt(n3.dot(n3))
    d2 = d3.cross(a) / a_norm
    kappa = sp.Matrix([(c.dot(b_x) - b.dot(c_x)) / (2 * b_norm * c_norm), curvature.dot(d2), curvature.dot(d3)])

    scale = 1 / (1 + prestrain)
    energy_density = scale * (
        E * A * eps**2 / 2 + G * J * kappa[0] ** 2 / 2 + E * Iy * kappa[1] ** 2 / 2 + E * Iz * kappa[2] ** 2 / 2
    )
    # Damping acts on the rates of small-strain measures built from dot products of the
    # co-rotating gradients (objective, and far cheaper to differentiate than eps and kappa).
    damped = [
        (a.dot(a) / 2 * (1 + prestrain), E * A, tau_axial),
        ((c.dot(b_x) - b.dot(c_x)) / 2, G * J, tau_bending),
        (a_x.dot(c), E * Iy, tau_bending),
        (a_x.dot(b), E * Iz, tau_bending),
    ]
    gamma_y = a.dot(b) / (a_norm * b_norm)
    gamma_z = a.dot(c) / (a_norm * c_norm)
    gamma_yz = b.dot(c) / (b_norm * c_norm)
    section_density = scale * (
        kshear * G * A * (gamma_y**2 + gamma_z**2) / 2
        + E * A * ((b_norm - 1) ** 2 + (c_norm - 1) ** 2) / 2
        + G * A * gamma_yz**2 / 2
    )

    x = sp.Symbol("x")
    shape_x = [sp.expand(s.subs(xi, x / length)) for s in shape]
    rho_s = rho * scale
    blocks = sp.zeros(8, 8)
    for i in range(8):
        for j in range(i, 8):
            integrand = _section_integral(shape_x[i] * shape_x[j], y, z, A, Iy, Iz)
            blocks[i, j] = blocks[j, i] = sp.factor(sp.integrate(integrand, (x, 0, length)))
    mass = sp.kronecker_product(blocks, sp.eye(3)) * rho_s
    gravity = sp.kronecker_product(
        sp.Matrix([sp.integrate(_section_integral(s, y, z, A, Iy, Iz), (x, 0, length)) for s in shape_x]),
        sp.eye(3),
    ) * rho_s

    return ElementDefinition(
        name="beam3d",
        dim=3,
        node_coordinates=list(spec.node_coordinates),
        e=e,
        params=param_specs(spec.params),
        p=p,
        xi=xi,
        local=local,
        local_map=linear_map(kinematics, e),
        position=centre,
        slope=r_x,
        energy_density=energy_density,
        section_density=section_density,
        damped_strains=damped,
        axial_strain=eps,
        bending_strain=kappa,
        extra_strains={"gamma_y": gamma_y, "gamma_z": gamma_z, "gamma_yz": gamma_yz},
        mass_matrix=mass,
        gravity_shape=gravity,
        gauss_points=4,
        description="fully parameterized 3D ANCF beam (Shabana-Yakoub), 2 nodes x 12 coordinates "
        "[r, r_x, r_y, r_z], elastic-line strain measures",
    )
