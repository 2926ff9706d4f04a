"""Equations of motion as semi-explicit DAEs: augmented (seed eq. 25) and embedded (eq. 26)
forms, each at index 1 (acceleration level, Baumgarte) or stabilized index 2 (GGL)."""
from .formulation import Formulation
from .initial import consistent_state

__all__ = ["Formulation", "consistent_state"]
