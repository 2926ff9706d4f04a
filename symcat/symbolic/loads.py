"""Configuration-dependent loads on ANCF nodes (SymPy).

``slope_moment``: a moment ``M`` (N m) about a fixed axis ``n`` applied through a node's slope
vector ``a = r_x``. Its potential is ``-M theta`` with ``theta`` the angle of ``a`` about ``n``,
so the generalized force on ``a`` is ``M (n x a) / |a_perp|^2`` with ``a_perp`` the part of ``a``
normal to ``n``. The load is conservative for any rotation (the roll-up of a beam to a full
circle needs exactly this), unlike a pair of dead forces.
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp


@dataclass
class LoadDefinition:
    """Symbolic generalized force of a load acting on ``coordinates``."""

    name: str
    coordinates: sp.Matrix
    params: sp.Matrix
    param_names: list[str]
    force: sp.Matrix
    potential: sp.Expr | None
    description: str


def slope_moment() -> LoadDefinition:
    """Moment about a fixed unit axis applied through a slope vector."""
    a = sp.Matrix(sp.symbols("a_0:3", real=True))
    n = sp.Matrix(sp.symbols("n_0:3", real=True))
    moment = sp.Symbol("M", real=True)
    a_perp = a - a.dot(n) * n
    force = moment * n.cross(a) / a_perp.dot(a_perp)
    return LoadDefinition(
        name="slope_moment",
        coordinates=a,
        params=sp.Matrix([moment, *n]),
        param_names=["moment", "axis_x", "axis_y", "axis_z"],
        force=force,
        potential=None,
        description="moment M (N m) about the unit axis n applied through a node slope r_x",
    )
