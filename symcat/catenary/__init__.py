"""Catenaries: design data, meshing into ANCF wires with droppers and supports, form finding."""
from .design import CatenaryDesign, Wire
from .formfinding import FormFindingResult, coupled_equilibrium, find_form
from .reference import benchmark2015, benchmark2015_dropper_lengths, en50318
from .scene import catenary_scene
from .seed import add_seed_catenary
from .span_statics import WireStatics, section_statics, span_statics
from .structure import CatenaryStructure, stations

__all__ = ["CatenaryDesign", "Wire", "CatenaryStructure", "stations", "find_form", "FormFindingResult",
           "coupled_equilibrium", "benchmark2015", "benchmark2015_dropper_lengths", "en50318",
           "span_statics", "section_statics", "WireStatics", "catenary_scene", "add_seed_catenary"]
