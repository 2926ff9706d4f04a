"""What the user describes: ANCF bodies, materials and sections, supports and loads."""
from .ancf import AncfBody
from .loads import NodalForce, SlopeMoment
from .scene import Scene
from .sections import Material, Section

__all__ = ["AncfBody", "Material", "NodalForce", "Scene", "Section", "SlopeMoment"]
