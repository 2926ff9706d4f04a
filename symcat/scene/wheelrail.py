"""Wheel/rail contact of a rigid wheelset on a ground-fixed rail (seed paper, Section 4).

A :class:`WheelRailJoint` is one wheel on one rail: four surface parameters and five
constraints (seed eqs. 15-22, see :mod:`symcat.symbolic.wheelrail`), the normal force coming
from their Lagrange multipliers (:func:`symcat.assembly.wheelrail.normal_directions`). Its optional :class:`CreepModel` adds the tangential
creep forces at the contact point (assembled in :mod:`symcat.assembly.wheelrail`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import ParameterError

CREEP_LAWS = ("linear", "polach")


@dataclass
class CreepModel:
    """Creep forces of one contact.

    The contact ellipse and Kalker's coefficients follow the contact point: inside the creep
    function's graph they are computed by Hertz's theory at ``nominal_normal_force_N`` from the
    profile curvatures at the current contact point (wheel and rail profile curvature across,
    ``cos(angle) / r`` of the wheel along the rolling direction), so they change as the point
    moves over a worn profile and jumps between tread, flange root and flange flank
    (:mod:`symcat.assembly.creep_ellipse`; a nearly conformal contact is floored at
    ``B >= 1e-3 A``). ``linear`` is Kalker's linear theory with these coefficients. ``polach``
    is Polach's saturating law with friction coefficient ``friction_coefficient``; its ellipse
    also grows with the actual normal force (the multiplier) as ``(N / N_nominal)^(1/3)`` at
    the shape of the nominal load.

    Parameters
    ----------
    law : {"linear", "polach"}
    nominal_normal_force_N : float
        Normal force for the contact ellipse (N), > 0: the static wheel load.
    friction_coefficient : float
        Coulomb friction coefficient of the ``polach`` law (-), in (0, 1].
    coefficient_factor : float
        Multiplies Kalker's coefficients (-), in (0, 1] (a common reduction for real rail
        surfaces, e.g. 0.6-0.8).
    reference_speed_m_s : float
        Regularizes the rolling speed ``V`` in the creepages, ``sqrt(V^2 + v_ref^2)`` (m/s), > 0:
        the creepages stay finite at rest.
    """

    law: str = "linear"
    nominal_normal_force_N: float = 80e3
    friction_coefficient: float = 0.3
    coefficient_factor: float = 1.0
    reference_speed_m_s: float = 0.01

    def __post_init__(self):
        if self.law not in CREEP_LAWS:
            raise ParameterError(f"creep law={self.law!r}: must be one of {', '.join(CREEP_LAWS)}")
        checks = (("nominal_normal_force_N", self.nominal_normal_force_N, 0.0, math.inf, "N"),
                  ("friction_coefficient", self.friction_coefficient, 0.0, 1.0, "-"),
                  ("coefficient_factor", self.coefficient_factor, 0.0, 1.0, "-"),
                  ("reference_speed_m_s", self.reference_speed_m_s, 0.0, math.inf, "m/s"))
        for name, value, lo, hi, unit in checks:
            if not (isinstance(value, (int, float)) and lo < value <= hi):
                raise ParameterError(f"creep {name}={value!r} {unit}: must be > {lo:g}" + (f" and <= {hi:g}" if hi < math.inf else ""))


@dataclass
class WheelRailJoint:
    """One wheel of a rigid wheelset on its rail (constraint contact).

    The wheelset body's frame has its origin on the axle centre and the axle along the body
    ``y`` axis. Tangent track (``track`` a cross-section or ``None``) runs along global ``x``
    with ``y`` toward the left rail and ``z`` up, the rail tops at ``z = 0``; curved track
    (``track`` a :class:`symcat.wheelrail.track.TrackLayout`) follows the layout, ``s1r`` being
    its chainage (see :mod:`symcat.wheelrail.constraint_contact`; place the wheelset with
    :func:`symcat.vehicle.wheelset_on_track` and the same ``track``).

    Parameters
    ----------
    name : str
    body : str
        The wheelset (a rigid body).
    side : {"left", "right"}
        Which wheel: ``left`` is on the body's ``+y`` end and runs on the rail at ``y > 0``.
    wheel, rail : symcat.wheelrail.Profile
        Profiles (mirrored on the right).
    wheelset : symcat.wheelrail.WheelsetDimensions, optional
        Tape-circle distance and nominal radius (default 1.5 m, 0.46 m).
    track : symcat.wheelrail.TrackCrossSection or symcat.wheelrail.track.TrackLayout, optional
        Tangent track: gauge and rail inclination (default 1.435 m, as built into the rail
        profile); the cheaper ``wheelrail_*_rigid_ground`` kernels. Curved track: a layout
        (circular curves, clothoid transitions, cant, gradient, irregularities; give it
        ``rail_offset_m=rail_offset_for(rail)``), the ``wheelrail_*_rigid_track`` kernels (the
        ends of cant ramps are kinks of the rails: see :mod:`symcat.wheelrail.track_pieces`).
    cant_rad : float
        Cant of a tangent track's cross-section (rad); 0 with a layout (it has its own).
    form : {"railframe", "global"}
        Constraint form: eq. 22 (default) or eq. 21. Rail frame: rows 0-1 are the coincidence
        of the wheel and rail points along the rail's tangents, row 2 their normal gap (its
        multiplier is minus the normal force), rows 3-4 the tangency; only this form can lift
        off (:mod:`symcat.wheelrail_events.contact_switching`) and run in the embedded formulation.
        Global: rows 0-2 are the coincidence ``r^w - r^r`` in global components, rows 3-4 the
        tangency; the normal force is minus their multipliers projected on the rail's outward
        normal (``C_s^T lambda = 0`` makes them normal to the rail); a negative one ends the
        run. Both forms take creep forces and move a wheelset the same.
    creep : CreepModel, optional
        Creep forces; none (frictionless) by default.
    track_piece_length_m : float
        Longest cubic piece of a curved track's rail frame (m).
    """

    name: str
    body: str
    side: str
    wheel: object
    rail: object
    wheelset: object = None
    track: object = None
    cant_rad: float = 0.0
    form: str = "railframe"
    creep: CreepModel | None = field(default=None)
    track_piece_length_m: float = 1.0

    def __post_init__(self):
        if self.side not in ("left", "right"):
            raise ParameterError(f"wheel/rail contact {self.name!r}: side={self.side!r} must be 'left' or 'right'")
        if self.creep is not None and not isinstance(self.creep, CreepModel):
            raise ParameterError(f"wheel/rail contact {self.name!r}: creep={self.creep!r} must be a CreepModel or None")
        if self.form not in ("railframe", "global"):
            raise ParameterError(f"wheel/rail contact {self.name!r}: form={self.form!r} must be 'railframe' or 'global'")

    def contact(self):
        """The run-time contact (:class:`symcat.wheelrail.WheelRailContact`) of this joint."""
        from ..wheelrail.constraint_contact import WheelRailContact

        return WheelRailContact(self.wheel, self.rail, self.side, wheelset=self.wheelset, track=self.track,
                                cant_rad=self.cant_rad, form=self.form, track_piece_length_m=self.track_piece_length_m)
