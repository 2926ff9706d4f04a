"""Time integration of multibody models: CasADi's IDAS (:func:`simulate`, variable step and
order) and the generalized-alpha method (:func:`generalized_alpha`, fixed step)."""
from .alpha_coefficients import AlphaCoefficients
from .generalized_alpha import generalized_alpha
from .simulate import SimulationResult, simulate

__all__ = ["SimulationResult", "simulate", "generalized_alpha", "AlphaCoefficients"]
