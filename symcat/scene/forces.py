"""Force elements: spring-dampers (linear, cubic, tension-only), bushings, rotational springs, loads."""
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
    ``axis`` (global, initial), ``phi`` the rotation of ``body_j`` relative to ``body_i``: torque ``stiffness (phi - angle0 - rate t) + damping (phi_dot -
    rate)`` (N m). With ``stiffness = 0`` and a ``rate`` (rad/s) it is a speed servo: a motor
    between the bodies that holds their relative angular velocity near ``rate`` (traction)."""

    name: str
    body_i: str
    body_j: str
    axis: tuple = (0.0, 0.0, 1.0)
    stiffness: float = 0.0
    damping: float = 0.0
    angle0: float = 0.0
    rate: float = 0.0


@dataclass
class Bushing:
    """Linear bushing between rigid bodies ``body_i`` and ``body_j`` (``body_j`` may be
    ``"ground"``) at the point ``at`` (global, initial), in axes fixed to ``body_i``: the global
    directions ``axes`` (rows: the bushing's x, y, z; default the global axes) in the initial
    configuration.

    Per axis the force on ``body_j`` is ``-(k d + c d_dot) + preload`` plus a stop beyond the free
    play ``clearance``: ``-stop_stiffness (|d| - clearance) sign(d)``; ``d`` is the displacement of
    ``body_j``'s point relative to ``body_i``'s (m), zero initially. The torque is
    ``-(k_rot theta + c_rot theta_dot)`` with ``theta`` the small relative rotation (rad) about the
    axes, for suspensions whose relative rotations stay small (do not use torsion terms on a
    spinning wheelset; its translational terms are fine when ``at`` lies on the axle).

    Parameters
    ----------
    stiffness : 3 floats, N/m
    damping : 3 floats, N s/m
    preload : 3 floats, N
        Force on ``body_j`` along the axes at zero deflection (the static load a spring carries
        in the initial configuration).
    clearance : 3 floats, m
        Free play before the stop (only where ``stop_stiffness`` is nonzero).
    stop_stiffness : 3 floats, N/m
    rotational_stiffness : 3 floats, N m/rad
    rotational_damping : 3 floats, N m s/rad
    """

    name: str
    body_i: str
    body_j: str
    at: tuple
    stiffness: tuple = (0.0, 0.0, 0.0)
    damping: tuple = (0.0, 0.0, 0.0)
    preload: tuple = (0.0, 0.0, 0.0)
    clearance: tuple = (0.0, 0.0, 0.0)
    stop_stiffness: tuple = (0.0, 0.0, 0.0)
    rotational_stiffness: tuple = (0.0, 0.0, 0.0)
    rotational_damping: tuple = (0.0, 0.0, 0.0)
    axes: tuple | None = None

    #: Attributes with three components each, in kernel order of symcat's bushing law.
    LAW = (("stiffness", "k"), ("damping", "c"), ("preload", "f0"), ("clearance", "gap"),
           ("stop_stiffness", "kstop"), ("rotational_stiffness", "kr"), ("rotational_damping", "cr"))
    UNITS = (("stiffness", "N/m"), ("damping", "N s/m"), ("preload", "N"), ("clearance", "m"),
             ("stop_stiffness", "N/m"), ("rotational_stiffness", "N m/rad"), ("rotational_damping", "N m s/rad"))


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
