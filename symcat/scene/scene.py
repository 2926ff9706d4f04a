"""A scene: ANCF bodies, loads and gravity. It is plain data; :func:`symcat.assembly.assemble`
turns it into numeric functions."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from .ancf import AncfBody
from .loads import NodalForce, SlopeMoment


@dataclass
class Scene:
    """Bodies and loads of one analysis.

    Parameters
    ----------
    gravity : sequence of 3 floats
        Gravity vector (m/s^2). Planar elements live in the xy-plane and use its x and y parts.
    """

    gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    bodies: list[AncfBody] = field(default_factory=list)
    loads: list[NodalForce | SlopeMoment] = field(default_factory=list)

    def add(self, item):
        """Add a body or a load and return it."""
        if isinstance(item, AncfBody):
            if any(b.name == item.name for b in self.bodies):
                raise ParameterError(f"body name {item.name!r}: already used in this scene")
            self.bodies.append(item)
        elif isinstance(item, (NodalForce, SlopeMoment)):
            body = self.body(item.body)
            body.node_index(item.node)
            if isinstance(item, NodalForce) and len(item.force) != body.element.dim:
                raise ParameterError(
                    f"force={item.force}: body {body.name!r} is {body.element.dim}D, give {body.element.dim} components"
                )
            self.loads.append(item)
        else:
            raise ParameterError(f"cannot add {type(item).__name__} to a scene")
        return item

    def body(self, name: str) -> AncfBody:
        for b in self.bodies:
            if b.name == name:
                return b
        known = ", ".join(b.name for b in self.bodies) or "none"
        raise ParameterError(f"body={name!r}: no such body in the scene (bodies: {known})")

    def gravity_vector(self) -> np.ndarray:
        return np.asarray(self.gravity, dtype=float)
