"""Static equilibrium and linearized modes of an assembled system."""
from .modes import ModalResult, modes
from .statics import StaticResult, solve_static

__all__ = ["ModalResult", "StaticResult", "modes", "solve_static"]
