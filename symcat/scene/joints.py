"""Joints, driving constraints and the sliding joint, placed by global positions and axes in
the initial configuration (symcat converts them to body-frame parameters).

A body is named by a string: a rigid body's name, ``"ground"``, or for ANCF nodes the tuple
``(body_name, node)``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

GROUND = "ground"


def unit(v, name="axis") -> np.ndarray:
    from ..errors import ParameterError

    v = np.asarray(v, dtype=float)
    n = np.linalg.norm(v)
    if v.shape != (3,) or not n > 0:
        raise ParameterError(f"{name}={tuple(v)}: must be a nonzero 3-vector")
    return v / n


def perpendiculars(axis) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors completing ``axis`` to a right-handed frame."""
    a = unit(axis)
    helper = np.array([1.0, 0, 0]) if abs(a[0]) < 0.9 else np.array([0, 1.0, 0])
    x = np.cross(helper, a)
    x /= np.linalg.norm(x)
    return x, np.cross(a, x)


@dataclass
class Spherical:
    """Ball joint: ``body_i`` and ``body_j`` share the point ``at`` (m, global, initial)."""

    name: str
    body_i: object
    body_j: object
    at: tuple


@dataclass
class Revolute:
    """Hinge about ``axis`` (global, initial) through ``at``."""

    name: str
    body_i: str
    body_j: str
    at: tuple
    axis: tuple = (0.0, 0.0, 1.0)


@dataclass
class Prismatic:
    """Slider along ``axis`` (global, initial); ``at`` is a point of both bodies initially."""

    name: str
    body_i: str
    body_j: str
    at: tuple
    axis: tuple = (1.0, 0.0, 0.0)


@dataclass
class Fixed:
    """Rigid connection of two bodies (or a body to the ground) at ``at``."""

    name: str
    body_i: str
    body_j: str = GROUND
    at: tuple = (0.0, 0.0, 0.0)


@dataclass
class Driving:
    """Prescribed motion of a point of a rigid body along ``direction``:
    ``direction . r(t) = x0 + velocity t + amplitude sin(2 pi frequency t + phase)``, with ``x0``
    the initial value. Units: m, m/s, m, Hz, rad."""

    name: str
    body: str
    direction: tuple = (1.0, 0.0, 0.0)
    at: tuple | None = None
    velocity: float = 0.0
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0


@dataclass
class SlidingJoint:
    """Seed paper eqs. (5)-(14): the point ``at`` of rigid body ``body`` (default: its centre of
    mass) slides along the centre line of ANCF body ``wire``, located by the arc-length
    parameter ``s`` (m from node 0, measured in the undeformed wire).

    ``reference_direction`` (global) builds the tangent frame of a gradient-deficient cable,
    which has no ``r_y``: ``k_t = i_t x d / |i_t x d|``; it must not be parallel to the wire.
    """

    name: str
    wire: str
    body: str
    s0: float
    at: tuple | None = None
    reference_direction: tuple = (0.0, 1.0, 0.0)
