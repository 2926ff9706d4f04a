"""Pantograph/catenary interaction: contact, coupled equations, time integration, statistics."""
from .coupled import CONTACT_MODELS, CoupledLine, PantographRun
from ..integrate.alpha_coefficients import AlphaCoefficients
from .generalized_alpha import integrate
from .recorder import PassageRecorder, load_passage

__all__ = ["CoupledLine", "PantographRun", "CONTACT_MODELS", "integrate", "AlphaCoefficients", "PassageRecorder",
           "load_passage"]
