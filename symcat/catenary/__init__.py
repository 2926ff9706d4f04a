"""Catenaries: design data, meshing into ANCF wires with droppers and supports, form finding."""
from .design import CatenaryDesign, Wire
from .formfinding import FormFindingResult, coupled_equilibrium, find_form
from .reference import benchmark2015, en50318
from .scene import catenary_scene
from .seed import add_seed_catenary
from .structure import CatenaryStructure, stations

__all__ = ["CatenaryDesign", "Wire", "CatenaryStructure", "stations", "find_form", "FormFindingResult",
           "coupled_equilibrium", "benchmark2015", "en50318", "catenary_scene", "add_seed_catenary"]
