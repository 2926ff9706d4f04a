"""Pantographs: lumped-mass models (for the line-scale passages, and as scene bodies under any
wire: :func:`add_lumped_pantograph`), and the seed paper's four-body pantograph as a scene
fragment added under any wire with one call (:func:`add_seo2005_pantograph`)."""
from .lumped import LumpedPantograph, benchmark2015_pantograph, en50318_pantograph, en50367_mean_force
from .lumped_scene import add_lumped_pantograph
from .seo2005 import add_seo2005_pantograph, contact_history, static_contact_force

__all__ = ["LumpedPantograph", "benchmark2015_pantograph", "en50318_pantograph", "en50367_mean_force",
           "add_seo2005_pantograph", "contact_history", "static_contact_force", "add_lumped_pantograph"]
