"""What the user describes: ANCF and rigid bodies, joints, force elements, supports and loads."""
from .ancf import AncfBody
from .contact import PenaltyContact
from .damping import RayleighDamping
from .forces import Bushing, PointLoad, RotationalSpring, SpringDamper
from .joints import GROUND, Driving, Fixed, Prismatic, Revolute, SlidingJoint, Spherical
from .loads import NodalForce, NodalMass, SlopeMoment
from .rigid import RigidBody
from .scene import Scene
from .sections import Material, Section
from .wheelrail import CreepModel, WheelRailJoint

__all__ = [
    "GROUND", "AncfBody", "Bushing", "CreepModel", "Driving", "Fixed", "Material", "NodalForce", "NodalMass", "PenaltyContact", "PointLoad", "Prismatic", "RayleighDamping",
    "Revolute", "RigidBody", "RotationalSpring", "Scene", "Section", "SlidingJoint", "SlopeMoment", "Spherical", "SpringDamper", "WheelRailJoint",
]
