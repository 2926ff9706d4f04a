"""The parameters of a model that runs the seed vehicle (``seo2005``, ``seo2005_line``): its
wheel/rail profiles, creep law and initial lateral offset, declared once."""
from __future__ import annotations

from ..model import Parameter
from ..wheelrail import PAIR_NAMES

#: The creep law names of the model parameter ``creep`` and the vehicle builder's names.
CREEP_LAWS = {"none": "none", "linear": "linear", "nonlinear": "polach"}


def running_parameters(lateral_offset_m: float = 0.0) -> list[Parameter]:
    """``profile``, ``creep``, ``friction_coefficient`` and ``lateral_offset_m`` (m, its
    default ``lateral_offset_m``), as :func:`symcat.vehicle.add_vehicle` takes them (``creep``
    through :data:`CREEP_LAWS`)."""
    return [
        Parameter("profile", "s1002_uic60", "", "wheel/rail profiles", choices=PAIR_NAMES),
        Parameter("creep", "linear", "", "wheel/rail creep forces", choices=tuple(CREEP_LAWS)),
        Parameter("friction_coefficient", 0.3, "-", "wheel/rail friction coefficient (nonlinear creep)", minimum=0.0,
                  maximum=1.0, exclusive_minimum=True),
        Parameter("lateral_offset_m", lateral_offset_m, "m", "initial lateral displacement of the vehicle toward the "
                  "left rail", minimum=-0.008, maximum=0.008),
    ]
