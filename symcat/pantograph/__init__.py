"""Pantographs: lumped-mass models (the multibody pantograph is built from symcat.scene)."""
from .lumped import LumpedPantograph, benchmark2015_pantograph, en50318_pantograph, en50367_mean_force

__all__ = ["LumpedPantograph", "benchmark2015_pantograph", "en50318_pantograph", "en50367_mean_force"]
