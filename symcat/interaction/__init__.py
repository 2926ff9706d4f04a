"""Pantograph/catenary interaction: contact, coupled equations, time integration, statistics."""
from .coupled import CONTACT_MODELS, CoupledLine, PantographRun
from .generalized_alpha import AlphaParameters, integrate
from .recorder import PassageRecorder, load_passage

__all__ = ["CoupledLine", "PantographRun", "CONTACT_MODELS", "integrate", "AlphaParameters", "PassageRecorder",
           "load_passage"]
