"""ANCF shape functions (SymPy).

All elements are straight in the reference configuration, with local coordinate
``x`` in [0, L] along the axis and ``xi = x / L``.
"""
from __future__ import annotations

import sympy as sp


def hermite_cubic(xi: sp.Symbol, length: sp.Symbol) -> list[sp.Expr]:
    """Cubic Hermite functions multiplying ``[r1, r1_x, r2, r2_x]``."""
    return [
        1 - 3 * xi**2 + 2 * xi**3,
        length * (xi - 2 * xi**2 + xi**3),
        3 * xi**2 - 2 * xi**3,
        length * (xi**3 - xi**2),
    ]


def shabana_yakoub(xi: sp.Symbol, eta: sp.Symbol, zeta: sp.Symbol, length: sp.Symbol) -> list[sp.Expr]:
    """Shape functions of the fully parameterized 3D ANCF beam (Shabana and Yakoub, 2001).

    They multiply the nodal vectors ``[r1, r1_x, r1_y, r1_z, r2, r2_x, r2_y, r2_z]``, with
    ``eta = y / L`` and ``zeta = z / L`` the normalized cross-section coordinates.
    """
    return [
        1 - 3 * xi**2 + 2 * xi**3,
        length * (xi - 2 * xi**2 + xi**3),
        length * (eta - xi * eta),
        length * (zeta - xi * zeta),
        3 * xi**2 - 2 * xi**3,
        length * (-(xi**2) + xi**3),
        length * xi * eta,
        length * xi * zeta,
    ]


def interpolate(functions: list[sp.Expr], nodal_vectors: list[sp.Matrix]) -> sp.Matrix:
    """Position field ``r = sum_k S_k * e_k`` for nodal vectors ``e_k``."""
    out = sp.zeros(nodal_vectors[0].rows, 1)
    for s, vec in zip(functions, nodal_vectors):
        out += s * vec
    return out
