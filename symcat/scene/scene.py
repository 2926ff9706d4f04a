"""A scene: ANCF bodies, loads and gravity. It is plain data; :func:`symcat.assembly.assemble`
turns it into numeric functions."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from .ancf import AncfBody
from .contact import PenaltyContact
from .damping import RayleighDamping
from .forces import Bushing, PointLoad, RotationalSpring, SpringDamper
from .joints import Driving, Fixed, Prismatic, Revolute, SlidingJoint, Spherical
from .loads import NodalForce, NodalMass, SlopeMoment
from .rigid import RigidBody
from .wheelrail import WheelRailJoint

JOINT_TYPES = (Spherical, Revolute, Prismatic, Fixed, Driving, SlidingJoint, WheelRailJoint)
FORCE_TYPES = (SpringDamper, Bushing, RotationalSpring, PointLoad, PenaltyContact)


@dataclass
class Scene:
    """Bodies and loads of one analysis.

    Parameters
    ----------
    gravity : sequence of 3 floats
        Gravity vector (m/s^2). Planar elements live in the xy-plane and use its x and y parts.
    linear_wires : bool
        Linearize the ANCF elements' elastic forces about the bodies' initial coordinates
        (``f(q0) - K(q0) (q - q0)``; damping, force elements, joints and contacts stay
        nonlinear): the usual model of a catenary, whose wires move by centimetres about their
        static state; a run with and without tells the size of the geometric nonlinearity.
    """

    gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    linear_wires: bool = False
    bodies: list[AncfBody] = field(default_factory=list)
    loads: list[NodalForce | NodalMass | SlopeMoment] = field(default_factory=list)
    rigid_bodies: list[RigidBody] = field(default_factory=list)
    joints: list = field(default_factory=list)
    force_elements: list = field(default_factory=list)
    damping: list[RayleighDamping] = field(default_factory=list)

    def add(self, item):
        """Add a body, joint, force element or load and return it."""
        if isinstance(item, (AncfBody, RigidBody)):
            if item.name == "ground" or item.name in self.body_names():
                raise ParameterError(f"body name {item.name!r}: already used in this scene")
            (self.bodies if isinstance(item, AncfBody) else self.rigid_bodies).append(item)
        elif isinstance(item, JOINT_TYPES + FORCE_TYPES):
            names = [x.name for x in self.joints + self.force_elements]
            if item.name in names:
                raise ParameterError(f"name {item.name!r}: already used by a joint or force element")
            for ref in _body_refs(item):
                self.check_body_ref(ref, item.name)
            if isinstance(item, (SlidingJoint, PenaltyContact)) and not isinstance(self.find(item.wire), AncfBody):
                kind = "sliding joint" if isinstance(item, SlidingJoint) else "contact"
                raise ParameterError(f"{kind} {item.name!r}: wire={item.wire!r} is not an ANCF body")
            (self.joints if isinstance(item, JOINT_TYPES) else self.force_elements).append(item)
        elif isinstance(item, (NodalForce, NodalMass, SlopeMoment)):
            body = self.body(item.body)
            body.node_index(item.node)
            if isinstance(item, NodalMass) and not (np.isfinite(item.mass) and item.mass >= 0):
                raise ParameterError(f"nodal mass on ({item.body!r}, {item.node}): mass={item.mass:g} kg must be >= 0")
            if isinstance(item, NodalForce) and len(item.force) != body.element.dim:
                raise ParameterError(
                    f"force={item.force}: body {body.name!r} is {body.element.dim}D, give {body.element.dim} components"
                )
            self.loads.append(item)
        elif isinstance(item, RayleighDamping):
            self._check_damping(item)
            self.damping.append(item)
        else:
            raise ParameterError(f"cannot add {type(item).__name__} to a scene")
        return item

    def _check_damping(self, item: RayleighDamping) -> None:
        bodies = item.bodies
        if isinstance(bodies, str) or not isinstance(bodies, (tuple, list)) or not bodies \
                or not all(isinstance(b, str) for b in bodies):
            raise ParameterError(f"RayleighDamping bodies={bodies!r}: must be a non-empty tuple of ANCF body names")
        if len(set(bodies)) != len(bodies):
            raise ParameterError(f"RayleighDamping bodies={tuple(bodies)!r}: a body is listed twice")
        for name in bodies:
            if not isinstance(self.find(name), AncfBody):
                raise ParameterError(f"RayleighDamping bodies: {name!r} is a rigid body; only ANCF bodies are allowed")
            for other in self.damping:
                if name in other.bodies:
                    raise ParameterError(f"RayleighDamping bodies: {name!r} is already damped by another RayleighDamping")
        for field_name, unit in (("alpha", "1/s"), ("beta", "s")):
            value = getattr(item, field_name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
                    or not (np.isfinite(value) and value >= 0):
                raise ParameterError(f"RayleighDamping {field_name}={value!r} {unit}: must be a finite number >= 0")
        n = sum(self.body(name).q0.size for name in bodies)
        if item.stiffness is not None:
            shape = getattr(item.stiffness, "shape", None)
            if shape != (n, n):
                raise ParameterError(f"RayleighDamping stiffness: shape {shape}; must be ({n}, {n}), the bodies' coordinates")
            if not np.all(np.isfinite(item.stiffness_matrix().data)):
                raise ParameterError("RayleighDamping stiffness: has non-finite entries; must be finite")
        elif not (isinstance(item.stiffness_at, str) and item.stiffness_at == "initial"):
            at = item.stiffness_at
            try:
                ok = not isinstance(at, str) and np.shape(at) == (n,) and bool(np.all(np.isfinite(np.asarray(at, dtype=float))))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ParameterError(f"RayleighDamping stiffness_at={at if isinstance(at, str) else np.shape(at)!r}: "
                                     f"must be 'initial' or {n} finite coordinates of the bodies")

    def body_names(self) -> list[str]:
        return [b.name for b in self.bodies] + [b.name for b in self.rigid_bodies]

    def find(self, name: str):
        """The ANCF or rigid body called ``name``."""
        for b in self.bodies + self.rigid_bodies:
            if b.name == name:
                return b
        known = ", ".join(self.body_names()) or "none"
        raise ParameterError(f"body={name!r}: no such body in the scene (bodies: {known})")

    def check_body_ref(self, ref, owner: str) -> None:
        """Validate a body reference: a rigid body name, "ground", or (ancf_body, node)."""
        if ref == "ground":
            return
        if isinstance(ref, tuple):
            body = self.find(ref[0])
            if not isinstance(body, AncfBody):
                raise ParameterError(f"{owner}: ({ref[0]!r}, {ref[1]}) names a node but {ref[0]!r} is not an ANCF body")
            body.node_index(ref[1])
            return
        body = self.find(ref) if isinstance(ref, str) else None
        if not isinstance(body, RigidBody):
            raise ParameterError(f"{owner}: body {ref!r} must be a rigid body, 'ground' or (ancf_body, node)")

    def body(self, name: str) -> AncfBody:
        for b in self.bodies:
            if b.name == name:
                return b
        known = ", ".join(b.name for b in self.bodies) or "none"
        raise ParameterError(f"body={name!r}: no such body in the scene (bodies: {known})")

    def gravity_vector(self) -> np.ndarray:
        return np.asarray(self.gravity, dtype=float)


def _body_refs(item) -> list:
    if isinstance(item, (SlidingJoint, PenaltyContact)):
        return [item.body]
    if isinstance(item, (Driving, PointLoad, WheelRailJoint)):
        return [item.body]
    return [item.body_i, item.body_j]
