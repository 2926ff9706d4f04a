"""Unilateral contact of a rigid body's point with a wire (seed paper, Section 8)."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import ParameterError


@dataclass
class PenaltyContact:
    """Penalty contact between the point ``at`` of rigid body ``body`` (default: its centre of
    mass) and the centre line of ANCF body ``wire``; loss of contact allowed.

    The wire point is located by the arc length ``s`` (m from node 0, undeformed) that solves
    the tangency condition ``i_t . (r_wire(s) - r_P) = 0`` (an algebraic equation, no
    multiplier); ``s0`` is the initial guess. The normal force along the tangent frame's
    ``k_t`` (up for a wire along x with ``reference_direction`` y) is
    ``f ~ max(stiffness * pen + damping * pen_dot, 0)`` with the penetration ``pen`` of the point
    into the wire, damping acting only in contact, no pulling force, and exactly zero once
    separated; the law is made C1 over ``smoothing`` (m) (see
    :mod:`symcat.codegen.multibody_kernels`).

    Parameters
    ----------
    name, wire, body : str
    s0 : float
        Initial arc length (m).
    stiffness : float
        Contact stiffness (N/m), > 0.
    damping : float
        Contact damping (N s/m), >= 0.
    smoothing : float
        Smoothing depth ``delta`` (m), > 0: in contact the force is
        ``stiffness * (pen - smoothing) + damping * pen_dot``.
    at : tuple, optional
        Contact point (global, initial configuration).
    reference_direction : tuple
        Builds the tangent frame of a cable (as for :class:`SlidingJoint`).
    """

    name: str
    wire: str
    body: str
    s0: float
    stiffness: float = 5.0e4
    damping: float = 0.0
    smoothing: float = 1.0e-5
    at: tuple | None = None
    reference_direction: tuple = (0.0, 1.0, 0.0)

    def __post_init__(self):
        if not self.stiffness > 0:
            raise ParameterError(f"contact {self.name!r}: stiffness={self.stiffness:g} N/m must be > 0")
        if not self.damping >= 0:
            raise ParameterError(f"contact {self.name!r}: damping={self.damping:g} N s/m must be >= 0")
        if not self.smoothing > 0:
            raise ParameterError(f"contact {self.name!r}: smoothing={self.smoothing:g} m must be > 0")
