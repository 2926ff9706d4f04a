"""Force elements: spring-dampers (linear, cubic, tension-only), rotational springs, loads."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class SpringDamper:
    """Spring-damper between point ``at_i`` of ``body_i`` and ``at_j`` of ``body_j`` (global,
    initial positions; bodies as for joints, ``"ground"`` or ``(ancf_body, node)`` allowed).

    Tension ``F = stiffness (l - l0) + cubic_stiffness (l - l0)^3 + damping l_dot`` (N), with
    ``l0 = free_length`` (m; default the initial distance). ``tension_only`` makes it a dropper:
    no force when slack or when the force would push.
    """

    name: str
    body_i: object
    body_j: object
    at_i: tuple
    at_j: tuple
    stiffness: float
    damping: float = 0.0
    free_length: float | None = None
    cubic_stiffness: float = 0.0
    tension_only: bool = False


@dataclass
class RotationalSpring:
    """Torsion spring-damper between two rigid bodies (or a body and the ground) about
    ``axis`` (global, initial): torque ``stiffness (phi - angle0) + damping phi_dot`` (N m)."""

    name: str
    body_i: str
    body_j: str
    axis: tuple = (0.0, 0.0, 1.0)
    stiffness: float = 0.0
    damping: float = 0.0
    angle0: float = 0.0


@dataclass
class PointLoad:
    """Force (N) at the point ``at`` (global, initial) of a rigid body and a torque (N m), both
    in global components: ``F0 + F1 sin(2 pi frequency t + phase)``."""

    name: str
    body: str
    at: tuple | None = None
    force: tuple = (0.0, 0.0, 0.0)
    force_amplitude: tuple = (0.0, 0.0, 0.0)
    torque: tuple = (0.0, 0.0, 0.0)
    torque_amplitude: tuple = (0.0, 0.0, 0.0)
    frequency: float = 0.0
    phase: float = 0.0
