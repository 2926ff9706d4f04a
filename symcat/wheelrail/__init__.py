"""Wheel/rail geometry: profiles as C2 curves, the rigid contact geometry of a wheelset, and the
equivalent conicity (EN 15302). NumPy/SciPy only.

* :mod:`.profiles` - :class:`Profile` (a cubic spline curve with vectorised position,
  derivatives, curvature, graph look-ups and piecewise-polynomial export) and point validation;
* :mod:`.standard_profiles` - the shipped S1002, UIC60 1:40, EN 15302 wheel A and rail A, and
  analytic coned and circular-arc profiles, converted to one frame;
* :mod:`.geometry` - contact points, rolling radii and contact angles against lateral shift
  (the search itself in :mod:`.gap_search`);
* :mod:`.conicity` - equivalent conicity from the rolling radius difference;
* :mod:`.track` - track layouts (curves, clothoids, cant) and rail frames; :mod:`.track_pieces`
  their cubic pieces for the constraint contact (:mod:`.constraint_contact`). A wheelset placed
  on the track for a scene: :func:`symcat.vehicle.wheelset_on_track`.
"""
from .conicity import equivalent_conicity
from .geometry import ContactGeometry, TrackCrossSection, WheelsetDimensions, contact_geometry, gauge_point
from .profiles import Profile, validate_points
from .stability import CriticalSpeed, SuspendedWheelset, critical_speed
from .standard_profiles import (
    PAIR_NAMES,
    PROFILE_NAMES,
    ProfilePair,
    circular_rail,
    circular_wheel,
    coned_wheel,
    en15302_rail_a,
    en15302_wheel_a,
    load_profile,
    profile_pair,
    s1002,
    uic60_canted,
)

__all__ = [
    "PAIR_NAMES",
    "PROFILE_NAMES",
    "ContactGeometry",
    "CriticalSpeed",
    "Profile",
    "ProfilePair",
    "SuspendedWheelset",
    "TrackCrossSection",
    "WheelsetDimensions",
    "circular_rail",
    "circular_wheel",
    "coned_wheel",
    "contact_geometry",
    "critical_speed",
    "en15302_rail_a",
    "en15302_wheel_a",
    "equivalent_conicity",
    "gauge_point",
    "load_profile",
    "profile_pair",
    "s1002",
    "uic60_canted",
    "validate_points",
]
