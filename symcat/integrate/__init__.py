"""Time integration with CasADi's IDAS."""
from .simulate import SimulationResult, simulate

__all__ = ["SimulationResult", "simulate"]
