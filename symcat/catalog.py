"""What every element and load kernel looks like from the outside (no SymPy, no CasADi).

The runtime reads kernel inputs from here, so a warm run needs neither the symbolic layer nor
the code generator; :mod:`symcat.symbolic` builds its symbols from the same lists.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ElementType:
    """Interface of one element kernel library.

    Attributes
    ----------
    name : str
        Kernel prefix and element-type name used in scenes (``element="cable3d"``).
    dim : int
        Spatial dimension.
    node_coordinates : tuple of str
        Coordinates of one node, in order.
    params : tuple of (name, unit, doc)
        Kernel parameter vector, in order.
    """

    name: str
    dim: int
    node_coordinates: tuple[str, ...]
    params: tuple[tuple[str, str, str], ...]
    description: str

    @property
    def dofs_per_node(self) -> int:
        return len(self.node_coordinates)

    @property
    def n_coordinates(self) -> int:
        return 2 * self.dofs_per_node

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(p[0] for p in self.params)


_PRESTRAIN_DOC = (
    "axial strain of the mesh configuration relative to the stress-free state; the stress-free "
    "length is length / (1 + prestrain), so a straight wire meshed at its installed length "
    "carries the tension E A prestrain"
)
CABLE_PARAMS = (
    ("length", "m", "element length in the mesh (reference) configuration"),
    ("E", "Pa", "Young's modulus"),
    ("A", "m^2", "cross-section area"),
    ("I", "m^4", "second moment of area (bending)"),
    ("rho", "kg/m^3", "density of the stress-free material"),
    ("prestrain", "-", _PRESTRAIN_DOC),
    ("damping_axial", "s", "Kelvin-Voigt time constant of the axial strain rate"),
    ("damping_bending", "s", "Kelvin-Voigt time constant of the bending strain rate"),
)
BEAM_PARAMS = (
    ("length", "m", "element length in the mesh (reference) configuration"),
    ("E", "Pa", "Young's modulus"),
    ("G", "Pa", "shear modulus, E / (2 (1 + nu))"),
    ("A", "m^2", "cross-section area"),
    ("Iy", "m^4", "second moment of area int z^2 dA (bending about the local y axis)"),
    ("Iz", "m^4", "second moment of area int y^2 dA (bending about the local z axis)"),
    ("J", "m^4", "torsion constant"),
    ("shear_factor", "-", "shear correction factor k (5/6 rectangle, 6/7 circle)"),
    ("rho", "kg/m^3", "density of the stress-free material"),
    ("prestrain", "-", _PRESTRAIN_DOC),
    ("damping_axial", "s", "Kelvin-Voigt time constant of the axial strain rate"),
    ("damping_bending", "s", "Kelvin-Voigt time constant of the bending and torsion rates"),
)

ELEMENT_TYPES = {
    "cable2d": ElementType(
        "cable2d", 2, ("x", "y", "x_x", "y_x"), CABLE_PARAMS,
        "planar gradient-deficient ANCF cable, 2 nodes x [r, r_x]",
    ),
    "cable3d": ElementType(
        "cable3d", 3, ("x", "y", "z", "x_x", "y_x", "z_x"), CABLE_PARAMS,
        "spatial gradient-deficient ANCF cable, 2 nodes x [r, r_x]",
    ),
    "beam3d": ElementType(
        "beam3d", 3,
        ("x", "y", "z", "x_x", "y_x", "z_x", "x_y", "y_y", "z_y", "x_z", "y_z", "z_z"),
        BEAM_PARAMS,
        "fully parameterized 3D ANCF beam (Shabana-Yakoub), 2 nodes x [r, r_x, r_y, r_z]",
    ),
}

#: Load kernel libraries: name -> (coordinate count, parameter names).
LOAD_TYPES = {"slope_moment": (3, ("moment", "axis_x", "axis_y", "axis_z"))}


def element_type(name: str) -> ElementType:
    """Look up an element type, with a clear error for an unknown name."""
    try:
        return ELEMENT_TYPES[name]
    except KeyError:
        raise ValueError(f"element={name!r}: unknown element type; allowed: {', '.join(ELEMENT_TYPES)}") from None
