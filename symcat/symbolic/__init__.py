"""SymPy-only layer: ANCF shape functions, strain measures, energies, mass matrices.

Nothing here knows CasADi; :mod:`symcat.codegen` turns these expressions into kernels.
"""
from .beam import beam3d
from .cable import cable2d, cable3d
from .loads import slope_moment

#: Element builders by kernel prefix.
ELEMENTS = {"beam3d": beam3d, "cable3d": cable3d, "cable2d": cable2d}
#: Load builders by kernel prefix.
LOADS = {"slope_moment": slope_moment}
