"""Build the CasADi functions of each kernel library from the symbolic definitions.

A *library* is the unit that is generated, compiled and loaded: one per element type and one
per load type, so a scene only pays for what it uses. Function names follow
``<library>_<quantity>``; CasADi finds each derivative companion ``jac_<name>`` in the same
shared library.

Element library ``<el>`` (``e``: element coordinates, ``e_dot``: their rates, ``p``: the
physical parameters listed in :mod:`symcat.symbolic`):

``<el>_force(e, p) -> f``            elastic generalized force ``-dU/de`` (``jac_<el>_force``)
``<el>_stiffness(e, p) -> K``        tangent stiffness ``-df/de`` (assembly uses it directly)
``<el>_damping(e, e_dot, p) -> f``   Kelvin-Voigt force ``-dD/de_dot`` (``jac_<el>_damping``)
``<el>_damping_matrices(e, e_dot, p) -> D, C``  ``-df/de`` and ``-df/de_dot`` of the damping
``<el>_energy(e, p) -> U``           strain energy (J)
``<el>_mass(p) -> M``                exact constant mass matrix
``<el>_gravity(p, g) -> q``          generalized gravity force for the gravity vector ``g`` (m/s^2)
``<el>_position(e, xi, p) -> r, r_x``  centre-line point and slope at ``xi = x / L``
``<el>_strain(e, xi, p) -> eps, kappa[, section]``  strain measures at ``xi``

Damping is a separate kernel so that an undamped scene does not pay for it.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
from sympy import Matrix as sp_matrix

from ..symbolic import ELEMENTS, LOADS
from ..symbolic.element import ElementDefinition
from .sympy_to_casadi import SympyToCasadi, bind

FUNCTION_OPTIONS = {"cse": True}


def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1) / 2, w / 2


def _sparse_sx(matrix, conv) -> ca.SX:
    """Convert a SymPy matrix keeping its exact zeros structural (sparse products stay cheap)."""
    rows, cols, values = [], [], []
    for i in range(matrix.rows):
        for j in range(matrix.cols):
            if matrix[i, j] != 0:
                rows.append(i)
                cols.append(j)
                values.append(conv(matrix[i, j]))
    sparsity = ca.Sparsity.triplet(matrix.rows, matrix.cols, rows, cols)
    out = ca.SX(sparsity)
    for r, c, v in zip(rows, cols, values):
        out[r, c] = v
    return out


def _local_densities(defn: ElementDefinition, p: ca.SX) -> dict[str, ca.Function]:
    """Per-point densities in the local kinematic quantities ``g`` and their derivatives.

    ``elastic(g, p) -> (grad u, hess u, u)`` at the Gauss points, ``section(g, p)`` likewise at
    the nodes (beam only), ``damping(g, g_dot, p) -> (h, dh/dg, dh/dg_dot)`` with
    ``h = dD/dg_dot`` the gradient of the Kelvin-Voigt dissipation density.
    """
    ng = defn.local.rows
    g = ca.SX.sym("g", ng)
    g_dot = ca.SX.sym("g_dot", ng)
    conv = SympyToCasadi({**bind(defn.local, g), **bind(defn.p, p)})
    out = {}
    u = conv(defn.energy_density)
    hess, grad = ca.hessian(u, g)
    out["elastic"] = ca.Function("elastic", [g, p], [grad, hess, u])
    if defn.section_density is not None:
        us = conv(defn.section_density)
        hess_s, grad_s = ca.hessian(us, g)
        out["section"] = ca.Function("section", [g, p], [grad_s, hess_s, us])

    strains = ca.vertcat(*[conv(s) for s, _, _ in defn.damped_strains])
    weights = [conv(k) * conv(tau) for _, k, tau in defn.damped_strains]
    rates = ca.jtimes(strains, g, g_dot)
    if defn.rate_tangent is not None:
        # Objective curvature rate of a frameless cable: remove the rotation of the tangent.
        t = conv(defn.rate_tangent)
        spin = ca.cross(t, ca.jtimes(t, g, g_dot))  # angular velocity of the tangent
        rates = ca.vertcat(rates[0], rates[1:4] - ca.cross(spin, strains[1:4]))
    prestrain = conv(defn.param("prestrain"))
    dissipation = sum(weights[j] * rates[j] ** 2 for j in range(strains.numel())) / (2 * (1 + prestrain))
    h = ca.gradient(dissipation, g_dot)
    out["damping"] = ca.Function("damping", [g, g_dot, p], [h, ca.jacobian(h, g), ca.jacobian(h, g_dot)])
    return out


def _congruence(b: ca.SX, h: ca.SX, symmetric: bool) -> ca.SX:
    """``B^T H B`` computing only the upper triangle when ``H`` is symmetric."""
    hb = ca.mtimes(h, b)
    if not symmetric:
        return ca.mtimes(b.T, hb)
    n = b.size2()
    out = ca.SX(n, n)
    for j in range(n):
        col = ca.mtimes(b[:, : j + 1].T, hb[:, j])
        out[: j + 1, j] = col
    return ca.triu2symm(ca.triu(out))


def element_functions(defn: ElementDefinition) -> list[ca.Function]:
    """All CasADi functions of one element library (Jacobian companions included)."""
    n = defn.n_coordinates
    e = ca.SX.sym("e", n)
    e_dot = ca.SX.sym("e_dot", n)
    p = ca.SX.sym("p", defn.p.rows)
    xi = ca.SX.sym("xi")
    conv = SympyToCasadi({**bind(defn.e, e), **bind(defn.p, p), defn.xi: xi})
    length = p[0]
    dens = _local_densities(defn, p)

    force = ca.SX(n, 1)
    stiffness = ca.SX(n, n)
    f_damp = ca.SX(n, 1)
    d_e = ca.SX(n, n)
    d_e_dot = ca.SX(n, n)
    energy = 0
    points = [(x, length * w, "elastic") for x, w in zip(*gauss_legendre(defn.gauss_points))]
    if "section" in dens:
        points += [(0.0, length / 2, "section"), (1.0, length / 2, "section")]
    for x_k, weight, kind in points:
        b_k = _sparse_sx(defn.local_map.subs(defn.xi, x_k), conv)
        g_k = ca.mtimes(b_k, e)
        grad, hess, u = dens[kind](g_k, p)
        force -= weight * ca.mtimes(b_k.T, grad)
        stiffness += weight * _congruence(b_k, hess, symmetric=True)
        energy += weight * u
        if kind == "elastic":
            h, dh_dg, dh_dgd = dens["damping"](g_k, ca.mtimes(b_k, e_dot), p)
            f_damp -= weight * ca.mtimes(b_k.T, h)
            d_e += weight * _congruence(b_k, dh_dg, symmetric=False)
            d_e_dot += weight * _congruence(b_k, dh_dgd, symmetric=True)

    name = defn.name
    opts = FUNCTION_OPTIONS
    out_f = ca.SX.sym("out_f", ca.Sparsity(n, 1))
    functions = [
        ca.Function(f"{name}_force", [e, p], [force], ["e", "p"], ["f"], opts),
        ca.Function(f"jac_{name}_force", [e, p, out_f], [-stiffness, ca.jacobian(force, p)],
                    ["e", "p", "out_f"], ["jac_f_e", "jac_f_p"], opts),
        ca.Function(f"{name}_stiffness", [e, p], [stiffness], ["e", "p"], ["K"], opts),
        ca.Function(f"{name}_damping", [e, e_dot, p], [f_damp], ["e", "e_dot", "p"], ["f"], opts),
        ca.Function(f"jac_{name}_damping", [e, e_dot, p, out_f], [-d_e, -d_e_dot, ca.jacobian(f_damp, p)],
                    ["e", "e_dot", "p", "out_f"], ["jac_f_e", "jac_f_e_dot", "jac_f_p"], opts),
        ca.Function(f"{name}_damping_matrices", [e, e_dot, p], [d_e, d_e_dot],
                    ["e", "e_dot", "p"], ["D", "C"], opts),
        ca.Function(f"{name}_energy", [e, p], [energy], ["e", "p"], ["U"], opts),
    ]
    g = ca.SX.sym("g", defn.dim)
    functions.append(ca.Function(f"{name}_mass", [p], [conv(defn.mass_matrix)], ["p"], ["M"], opts))
    functions.append(ca.Function(f"{name}_gravity", [p, g], [ca.mtimes(conv(defn.gravity_shape), g)],
                                 ["p", "g"], ["q"], opts))
    functions.append(ca.Function(f"{name}_position", [e, xi, p], [conv(defn.position), conv(defn.slope)],
                                 ["e", "xi", "p"], ["r", "r_x"], opts))
    strain_out = [conv(defn.in_coordinates(defn.axial_strain)), conv(defn.in_coordinates(defn.bending_strain))]
    strain_names = ["eps", "kappa"]
    if defn.extra_strains:
        extra = sp_matrix(list(defn.extra_strains.values()))
        strain_out.append(conv(defn.in_coordinates(extra)))
        strain_names.append("section")
    functions.append(ca.Function(f"{name}_strain", [e, xi, p], strain_out, ["e", "xi", "p"], strain_names, opts))
    return functions


def load_functions(name: str) -> list[ca.Function]:
    """CasADi functions of one load library: ``<load>(x, p) -> f`` and its Jacobian."""
    defn = LOADS[name]()
    x = ca.SX.sym("x", defn.coordinates.rows)
    p = ca.SX.sym("p", defn.params.rows)
    conv = SympyToCasadi({**bind(defn.coordinates, x), **bind(defn.params, p)})
    f = ca.Function(name, [x, p], [conv(defn.force)], ["x", "p"], ["f"], FUNCTION_OPTIONS)
    return [f, _jacobian(f)]


def _jacobian(f: ca.Function) -> ca.Function:
    """``jac_<name>`` companion of ``f``, simplified by CSE like its parent."""
    jac = f.jacobian()
    args = jac.sx_in()
    return ca.Function(jac.name(), args, jac.call(args), jac.name_in(), jac.name_out(), FUNCTION_OPTIONS)


def library_names() -> list[str]:
    """Every kernel library symcat can generate."""
    from .multibody_kernels import multibody_library_names

    return sorted(ELEMENTS) + sorted(LOADS) + multibody_library_names()


def library_functions(name: str) -> list[ca.Function]:
    """The CasADi functions of library ``name``."""
    if name in ELEMENTS:
        return element_functions(ELEMENTS[name]())
    if name in LOADS:
        return load_functions(name)
    from .multibody_kernels import multibody_functions, multibody_library_names

    if name in multibody_library_names():
        return multibody_functions(name)
    raise KeyError(f"library={name!r}: unknown; known: {', '.join(library_names())}")


def library_interface(name: str) -> dict:
    """What the runtime needs to know about a library besides its functions (manifest)."""
    if name in ELEMENTS or name in LOADS:
        return {"kind": "element" if name in ELEMENTS else "load"}
    from .multibody_kernels import interface

    return interface(name)
