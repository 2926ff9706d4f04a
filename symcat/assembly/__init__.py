"""Global vectors and sparse matrices from mapped element kernels."""
from .cholesky import CholeskyCoordinates
from .dofs import DofMap
from .element_set import ElementSet
from .system import System, assemble

__all__ = ["CholeskyCoordinates", "DofMap", "ElementSet", "System", "assemble"]
