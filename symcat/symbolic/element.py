"""Common description of a symbolic ANCF element.

An :class:`ElementDefinition` holds SymPy expressions only. The strain energy of every element
depends on its coordinates ``e`` only through a few *local kinematic quantities* at a point of
the axis, ``g = B(xi) e`` (for a cable ``g = [r_x, r_xx]``), with ``B`` constant in time. The
energy and dissipation densities are written in terms of ``g``; :mod:`symcat.codegen` integrates
them by quadrature and forms ``f = -L sum_k w_k B_k^T grad u(g_k)`` and
``K = L sum_k w_k B_k^T hess u(g_k) B_k``, so that CasADi differentiates small local functions
instead of the whole element (about ten times less code than differentiating ``f`` in ``e``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp


@dataclass(frozen=True)
class ParameterSpec:
    """One physical input of a kernel: name, unit and meaning."""

    name: str
    unit: str
    doc: str


@dataclass
class ElementDefinition:
    """Symbolic content of one ANCF element type.

    Attributes
    ----------
    name : str
        Kernel prefix, e.g. ``"cable3d"``.
    dim : int
        Spatial dimension (2 or 3).
    node_coordinates : list of str
        Names of the coordinates of one node, e.g. ``["x", "y", "z", "x_x", ...]``.
    e : sympy.Matrix
        Element coordinates (both nodes).
    params : list of ParameterSpec
        Physical inputs, in kernel order; ``p`` holds their symbols (``p[0]`` is the length).
    xi : sympy.Symbol
        Normalized axial coordinate ``x / L`` in [0, 1].
    local : sympy.Matrix
        Symbols of the local kinematic quantities ``g``.
    local_map : sympy.Matrix
        ``B(xi, L)`` with ``g = B e``.
    position, slope : sympy.Matrix
        Centre-line position ``r(xi)`` (m) and ``dr/dx`` in terms of ``e``.
    energy_density : sympy.Expr
        Strain energy per unit mesh length (J/m) in terms of ``g``; Gauss quadrature.
    section_density : sympy.Expr or None
        Energy per unit mesh length collocated at the two nodes (trapezoidal weights); the
        beam's shear and cross-section terms, which must not lock.
    damped_strains : list of (strain, stiffness, time constant)
        Kelvin-Voigt dissipation ``1/2 sum stiffness * tau * strain_rate^2`` per unit
        stress-free length, strains in terms of ``g``.
    rate_tangent : sympy.Matrix or None
        Unit tangent (in ``g``); if given, the rotation of the tangent is removed from the
        rates of the curvature components ``1..3`` of ``damped_strains`` (objective rates for
        the 3D cable, which has no material frame).
    axial_strain, bending_strain, extra_strains
        Strain measures in terms of ``g``, for output.
    mass_matrix : sympy.Matrix
        Exact constant mass matrix.
    gravity_shape : sympy.Matrix
        ``Q_g = gravity_shape * g_vec`` with ``g_vec`` the gravity vector (m/s^2).
    gauss_points : int
        Gauss-Legendre points along the element.
    """

    name: str
    dim: int
    node_coordinates: list[str]
    e: sp.Matrix
    params: list[ParameterSpec]
    p: sp.Matrix
    xi: sp.Symbol
    local: sp.Matrix
    local_map: sp.Matrix
    position: sp.Matrix
    slope: sp.Matrix
    energy_density: sp.Expr
    damped_strains: list[tuple[sp.Expr, sp.Expr, sp.Symbol]]
    axial_strain: sp.Expr
    bending_strain: sp.Matrix
    mass_matrix: sp.Matrix
    gravity_shape: sp.Matrix
    gauss_points: int
    section_density: sp.Expr | None = None
    rate_tangent: sp.Matrix | None = None
    extra_strains: dict[str, sp.Expr] = field(default_factory=dict)
    description: str = ""

    @property
    def n_coordinates(self) -> int:
        return self.e.rows

    def param(self, name: str) -> sp.Symbol:
        """Symbol of the parameter called ``name``."""
        for spec, sym in zip(self.params, self.p):
            if spec.name == name:
                return sym
        raise KeyError(name)

    def in_coordinates(self, expr):
        """Rewrite an expression (or matrix) in ``g`` in terms of the element coordinates ``e``."""
        return sp.sympify(expr).xreplace(dict(zip(self.local, self.local_map * self.e)))


def symbols_vector(prefix: str, n: int) -> sp.Matrix:
    """Column of real symbols ``prefix_0 .. prefix_{n-1}``."""
    return sp.Matrix(sp.symbols(f"{prefix}_0:{n}", real=True))


def node_vectors(e: sp.Matrix, dim: int) -> list[sp.Matrix]:
    """Split an element coordinate vector into consecutive ``dim``-vectors."""
    return [e[k : k + dim, 0] for k in range(0, e.rows, dim)]


def linear_map(exprs: sp.Matrix, e: sp.Matrix) -> sp.Matrix:
    """Matrix ``B`` with ``exprs = B e`` for expressions linear in ``e``."""
    return exprs.jacobian(e)


def param_specs(params) -> list[ParameterSpec]:
    """ParameterSpec list from the catalog's (name, unit, doc) tuples."""
    return [ParameterSpec(*entry) for entry in params]


def param_symbols(params) -> sp.Matrix:
    """Real symbols named after the catalog's parameters, in kernel order."""
    return sp.Matrix([sp.Symbol(entry[0], real=True) for entry in params])
