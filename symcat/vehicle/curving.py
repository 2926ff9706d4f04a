"""The vehicle in a curve: a track layout that takes it from a tangent lead-in through a
transition into a circular curve, and the quasi-static lateral and vertical forces of steady
curving (the reference a simulated run settles to).

Steady curving (SI units; track frame of :mod:`symcat.wheelrail.track`): every body moves on a
circle of radius ``R`` about the curve centre at the forward speed ``v``, so its acceleration is
``v^2 / R`` horizontal toward the centre. The rails' forces on the wheels are the only external
forces besides gravity (suspension forces and traction torques are internal), so their sum
balances the vehicle's mass ``M`` times acceleration minus gravity. In the canted track frame at
cant angle ``phi`` (positive lifting the left rail) with lateral axis ``l = (0, cos phi,
sin phi)`` (toward the left rail) and up axis ``u = (0, -sin phi, cos phi)`` (components
tangent, horizontal left, vertical), and the signed curvature ``kappa`` (``+1/R`` for a curve to
the left):

* lateral: ``sum F . l = M (kappa v^2 cos phi + g sin phi)``,
* vertical: ``sum F . u = M (g cos phi - kappa v^2 sin phi)``.

The lateral sum vanishes at the balance speed ``v^2 = g tan|phi| R`` (outer rail raised). The
bodies' radii differ from the centre line's by their lateral positions in plan (of order
``h sin phi``, ``h`` a height), a relative error of order ``h |phi| / R`` left out.
"""
from __future__ import annotations

import math

from ..errors import ParameterError
from ..wheelrail.track import Curve, Tangent, TrackLayout, Transition, rail_offset_for
from .builder import vehicle_half_span_m
from .parameters import G, VehicleParameters

#: Clearance (m) between the vehicle's outermost wheelsets and the ends of its lead-in tangent.
LEAD_IN_MARGIN_M = 1.0


def curve_track(pair, radius_m: float, *, cant_m: float = 0.0, transition_length_m: float = 20.0,
                curve_length_m: float = 100.0, direction: str = "left",
                parameters: VehicleParameters | None = None, cant_ramp: str = "smooth") -> tuple[TrackLayout, float]:
    """A tangent lead-in holding the whole vehicle, a clothoid transition and a circular curve.

    Parameters
    ----------
    pair : ProfilePair
        Wheel and rail profiles (the rails are placed at the standard gauge for this rail).
    radius_m : float
        Radius of the circular curve (m), > 0.
    cant_m : float
        Superelevation of the outer rail in the curve (m), ramped linearly along the transition.
    transition_length_m : float
        Length of the clothoid transition (m); 0 puts the curve right after the tangent (a jump
        of curvature, allowed only without cant).
    curve_length_m : float
        Length of the circular curve (m), > 0.
    direction : {"left", "right"}
        Side of the curve centre.
    parameters : VehicleParameters, optional
        The vehicle (its length sets the lead-in).
    cant_ramp : {"smooth", "linear"}
        Superelevation ramp along the transition (:class:`symcat.wheelrail.track.Transition`):
        ``"smooth"`` (no kinks of the rails) or ``"linear"`` (kinks at its ends, impacts that a
        rigid wheel/rail contact of the vehicle does not get past).

    Returns
    -------
    track : TrackLayout
    x_m : float
        Chainage of the vehicle centre to start at (m): the vehicle's outermost wheelsets
        ``LEAD_IN_MARGIN_M`` from the ends of the lead-in.

    Raises
    ------
    ParameterError
        For a bad radius, length or direction, or a cant without a transition.
    """
    half = vehicle_half_span_m(parameters or VehicleParameters())
    if not (isinstance(transition_length_m, (int, float)) and transition_length_m >= 0):
        raise ParameterError(f"transition_length_m={transition_length_m!r}: must be >= 0 (m)")
    if transition_length_m == 0 and cant_m != 0:
        raise ParameterError(f"cant_m={cant_m!r} with transition_length_m=0: a cant needs a transition to "
                             "ramp it (give transition_length_m > 0)")
    lead_in = 2.0 * (half + LEAD_IN_MARGIN_M)
    segments = [Tangent(lead_in)]
    if transition_length_m > 0:
        segments.append(Transition(float(transition_length_m), cant_ramp))
    segments.append(Curve(float(curve_length_m), float(radius_m), direction, float(cant_m)))
    return TrackLayout(segments, rail_offset_m=rail_offset_for(pair.rail)), half + LEAD_IN_MARGIN_M


def steady_curving_forces_N(mass_kg: float, speed_ms: float, curvature_per_m: float,
                            cant_angle_rad: float) -> tuple[float, float]:
    """Quasi-static sums of the rails' lateral and vertical forces on a vehicle in steady curving
    (module docstring): ``(lateral toward the left rail, up)`` in the canted track frame (N).

    Parameters
    ----------
    mass_kg : float
        Mass of the whole vehicle (kg).
    speed_ms : float
        Forward speed (m/s).
    curvature_per_m : float
        Signed curvature (1/m), positive for a curve to the left.
    cant_angle_rad : float
        Cant angle (rad), positive lifting the left rail.
    """
    a = curvature_per_m * speed_ms**2
    c, s = math.cos(cant_angle_rad), math.sin(cant_angle_rad)
    return mass_kg * (a * c + G * s), mass_kg * (G * c - a * s)
