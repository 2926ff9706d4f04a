"""Static equilibrium and linearized modes of an assembled system."""
from .equilibrium import EquilibriumResult, solve_equilibrium
from .modes import ModalResult, modes
from .statics import StaticResult, solve_static

__all__ = ["EquilibriumResult", "solve_equilibrium", "ModalResult", "StaticResult", "modes", "solve_static"]
