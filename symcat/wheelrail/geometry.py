"""Rigid contact geometry of a wheelset on two rails (cross-section approach, no yaw).

Track frame: ``Y`` lateral, positive toward the **left** rail, ``Z`` up, origin on the track
centre line at the rail-top level. A lateral shift ``y > 0`` moves the wheelset toward the left
rail; the roll angle ``phi`` turns it about the forward axis, ``phi > 0`` lifting the left wheel.
Both sides use the profile frames of :mod:`.profiles` mirrored: on the left, ``Y = Y0 + y_local``;
on the right, ``Y = -(Y0 + y_local)``.

For each shift the wheelset is lowered onto the rails: with ``roll`` off, each wheel is lowered
onto its rail on its own (the usual approximation neglecting the roll angle ``delta_r / (2 b)``,
a fraction of a milliradian on the tread); with ``roll`` on, the axle height and roll angle are
found so that both wheels touch (bracketed Newton on the height difference, derivative from the
envelope theorem). Contact on a wheel is the minimum of the vertical gap ``Z_wheel - Z_rail``
along the wheel profile, found by :mod:`.gap_search` (grid of ``grid_m`` = 0.2 mm, local
refinement on the exact splines and a Newton polish, for the best two local minima). When the
second minimum lies within ``two_point_tolerance_m`` of the first and more than 1 mm away along
the wheel, the wheel is in two-point contact (tread and flange), reported as the second contact.

Outputs per shift: rolling radii (distance of the contact point from the axle), their difference
``delta_r = r_left - r_right`` (positive for ``y > 0``), and contact angles: the inclination of
the common tangent to the track plane, positive when the contact normal on the wheel points
toward the track centre (both positive on a centred coned wheelset; near 70 deg on a flange).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from symcat.errors import ParameterError

from .gap_search import NoContact, WheelOnRail
from .profiles import Profile


@dataclass(frozen=True)
class TrackCrossSection:
    """Rails of a straight track in cross-section.

    Attributes
    ----------
    gauge_m : float
        Distance between the gauge faces [m], measured ``gauge_depth_m`` below the rail top.
    gauge_depth_m : float
        Depth of the gauge measurement below the top of the rail [m] (14 mm, EN 13848-1).
    rail_inclination_rad : float or None
        Rail inclination toward the track centre [rad]; ``None`` keeps the inclination built
        into the rail profile (the shipped UIC60 1:40 and EN 15302 rail A are already inclined),
        a value rotates the profile by the difference from its built-in inclination.
    """

    gauge_m: float = 1.435
    gauge_depth_m: float = 0.014
    rail_inclination_rad: float | None = None


@dataclass(frozen=True)
class WheelsetDimensions:
    """Rigid wheelset dimensions.

    Attributes
    ----------
    tape_circle_distance_m : float
        Lateral distance between the tape circles (the wheel profiles' origins) [m]; 1.5 m is a
        flange-back distance of 1.360 m with profiles whose flange back is 70 mm from the tape
        circle (S1002, EN 15302 wheel A).
    nominal_radius_m : float
        Rolling radius at the tape circle [m] (0.46 m for the Manchester vehicle and the
        EN 15302 reference cases).
    """

    tape_circle_distance_m: float = 1.5
    nominal_radius_m: float = 0.46


@dataclass
class ContactGeometry:
    """Contact geometry against lateral shift (arrays of length ``n`` shifts; NaN where absent).

    Attributes
    ----------
    lateral_shift_m : ndarray
        Lateral shift of the wheelset toward the left rail [m].
    roll_angle_rad : ndarray
        Roll angle (left wheel up) [rad]; zero with ``roll`` off.
    axle_height_m : ndarray
        Height of the axle centre above the rail-top level [m] (with ``roll`` off, the mean of
        the two wheels' heights).
    rolling_radius_m : dict
        ``{"left": ..., "right": ...}`` rolling radii [m].
    contact_angle_rad : dict
        Contact angles [rad] (convention in the module docstring).
    contact_y_m, contact_z_m : dict
        Contact points in the track frame [m].
    wheel_y_m, rail_y_m : dict
        Lateral coordinates of the contact points on the wheel and rail profiles [m].
    two_point : dict
        Boolean arrays: a second contact within the two-point tolerance.
    second_rolling_radius_m, second_contact_angle_rad, second_contact_y_m : dict
        The second contact where ``two_point``; NaN elsewhere.
    gap_difference_m : dict
        Vertical gap at the second-best contact candidate minus that at the contact [m].
    rail_origin_y_m : float
        Track ``Y`` of the left rail profile's origin (the right one is at ``-Y``) [m].
    """

    lateral_shift_m: np.ndarray
    roll_angle_rad: np.ndarray
    axle_height_m: np.ndarray
    rolling_radius_m: dict
    contact_angle_rad: dict
    contact_y_m: dict
    contact_z_m: dict
    wheel_y_m: dict
    rail_y_m: dict
    two_point: dict
    second_rolling_radius_m: dict
    second_contact_angle_rad: dict
    second_contact_y_m: dict
    gap_difference_m: dict
    rail_origin_y_m: float

    @property
    def rolling_radius_difference_m(self) -> np.ndarray:
        """``r_left - r_right`` [m]."""
        return self.rolling_radius_m["left"] - self.rolling_radius_m["right"]


def gauge_point(rail: Profile, depth_m: float = 0.014) -> np.ndarray:
    """Gauge point ``(y, z)`` [m] of a rail profile in its installed position: the innermost
    (smallest ``y``) point of the profile within ``depth_m`` below its top, which on an ordinary
    gauge face is the point at exactly ``depth_m`` below the top.

    Raises
    ------
    ParameterError
        If the profile does not reach ``depth_m`` below its top on the gauge side.
    """
    s, p = rail.sample(1e-5)
    level = p[:, 1].max() - depth_m
    above = p[:, 1] >= level
    first = int(np.argmax(above))
    if first == 0:
        raise ParameterError(f"rail profile {rail.name!r}: reaches only {(p[:, 1].max() - p[0, 1]) * 1e3:.2f} mm "
                             f"below its top on the gauge side; the gauge is measured {depth_m * 1e3:g} mm below")
    i = int(np.flatnonzero(above)[np.argmin(p[above, 0])])  # innermost point of the top region
    if p[i, 0] < p[first, 0] - 1e-7:  # undercut face: the innermost point is inside the region
        return p[i]
    # Refine the crossing of z = level between samples first-1 and first (bisection on the spline).
    lo, hi = s[first - 1], s[first]
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        if rail.position(mid)[1] >= level:
            hi = mid
        else:
            lo = mid
    return rail.position(hi)


def contact_geometry(wheel: Profile, rail: Profile, shifts_m, *, track: TrackCrossSection | None = None,
                     wheelset: WheelsetDimensions | None = None, roll: bool = False,
                     wheel_right: Profile | None = None, rail_right: Profile | None = None,
                     grid_m: float = 2e-4, two_point_tolerance_m: float = 1e-5,
                     max_centred_angle_rad: float = 0.6) -> ContactGeometry:
    """Rigid contact geometry of a wheelset against lateral shift.

    Parameters
    ----------
    wheel, rail : Profile
        Left wheel and rail profiles (used on the right too unless given separately).
    shifts_m : array_like
        Lateral shifts of the wheelset toward the left rail [m].
    track : TrackCrossSection, optional
        Gauge, its measuring depth and the rail inclination (default: 1.435 m, 14 mm, as built).
    wheelset : WheelsetDimensions, optional
        Tape-circle distance and nominal rolling radius (default: 1.5 m, 0.46 m).
    roll : bool
        Solve for the roll angle that lets both wheels touch; off (default, as in EN 15302's
        reference results), each wheel is lowered onto its rail on its own.
    wheel_right, rail_right : Profile, optional
        Right-hand profiles, in the same profile frame as the left ones.
    grid_m : float
        Spacing of the coarse search along the wheel profile [m].
    two_point_tolerance_m : float
        A second contact candidate within this vertical gap is reported as two-point contact [m].
    max_centred_angle_rad : float
        Largest contact angle accepted at the centred position [rad]: above it the wheelset
        does not fit between the rails (flanges on the rail heads). The centred contact must
        also lie more than 5 mm on the tread side of the flange tip (the largest radius).

    Raises
    ------
    ParameterError
        If the wheelset is off the rails at some shift (a wheel touches at the end of a
        profile or behind its flange tip, or is nowhere above its rail) or does not fit between
        them; the message names the gauge and the shift.
    """
    track = track or TrackCrossSection()
    wheelset = wheelset or WheelsetDimensions()
    for label, value in (("gauge_m", track.gauge_m), ("gauge_depth_m", track.gauge_depth_m),
                         ("tape_circle_distance_m", wheelset.tape_circle_distance_m),
                         ("nominal_radius_m", wheelset.nominal_radius_m), ("grid_m", grid_m)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ParameterError(f"{label}={value!r}: must be a number > 0")
    shifts = np.atleast_1d(np.asarray(shifts_m, float))
    if shifts.ndim != 1 or not np.all(np.isfinite(shifts)):
        raise ParameterError("shifts_m: must be a one-dimensional array of finite numbers (m)")
    sides = {}
    origin = None
    for name, sign, w, r in (("left", 1.0, wheel, rail), ("right", -1.0, wheel_right or wheel, rail_right or rail)):
        for prof, kind in ((w, "wheel"), (r, "rail")):
            if prof.kind != kind:
                raise ParameterError(f"{name} {kind}: profile {prof.name!r} is a {prof.kind} profile")
        if track.rail_inclination_rad is not None:
            r = r.transformed(track.rail_inclination_rad - r.inclination_rad)
        yg = gauge_point(r, track.gauge_depth_m)[0]
        o = 0.5 * track.gauge_m - yg
        origin = o if origin is None else origin
        sides[name] = WheelOnRail(name, sign, w, r, o, 0.5 * wheelset.tape_circle_distance_m,
                                  wheelset.nominal_radius_m, grid_m)
    # The centred position first: the wheelset must fit between the rails.
    all_shifts = np.r_[0.0, shifts]
    try:
        res = _solve(sides, all_shifts, roll, two_point_tolerance_m)
    except NoContact as exc:
        y = all_shifts[exc.index]
        raise ParameterError(f"gauge_m={track.gauge_m:g} m, lateral shift {y * 1e3:+.2f} mm: {exc.what}; "
                             "the profiles do not meet there (wheelset off the rails)") from None
    centred = max(res.contact_angle_rad["left"][0], res.contact_angle_rad["right"][0])
    if centred > max_centred_angle_rad:
        raise ParameterError(f"gauge_m={track.gauge_m:g} m: too narrow for the wheelset; centred, the wheels touch "
                             f"the rails at a contact angle of {math.degrees(centred):.0f} deg (flanges on the rail "
                             f"heads, more than {math.degrees(max_centred_angle_rad):.0f} deg allowed)")
    for name, side in sides.items():
        if res.wheel_y_m[name][0] < side.tip_y + 5e-3:
            raise ParameterError(f"gauge_m={track.gauge_m:g} m: too narrow for the wheelset; centred, the {name} wheel "
                                 f"touches its rail at wheel y = {res.wheel_y_m[name][0] * 1e3:.1f} mm, on the flange "
                                 f"(tip at {side.tip_y * 1e3:.1f} mm), not on the tread")
    for key in ("lateral_shift_m", "roll_angle_rad", "axle_height_m"):
        setattr(res, key, getattr(res, key)[1:])
    for key in ("rolling_radius_m", "contact_angle_rad", "contact_y_m", "contact_z_m", "wheel_y_m", "rail_y_m",
                "two_point", "second_rolling_radius_m", "second_contact_angle_rad", "second_contact_y_m",
                "gap_difference_m"):
        setattr(res, key, {k: v[1:] for k, v in getattr(res, key).items()})
    res.rail_origin_y_m = origin
    return res


def _solve(sides, shifts, roll, tol2) -> ContactGeometry:
    n = len(shifts)
    phi = np.zeros(n)

    def touch(phi):
        # Axle height at which each wheel touches (minus the minimum gap at height 0).
        out = {}
        for name, side in sides.items():
            s1, v1, s2, v2 = side.search(shifts, phi)
            out[name] = (s1, v1, s2, v2)
        return out

    found = touch(phi)
    if roll:
        lo, hi = np.full(n, -0.2), np.full(n, 0.2)
        for _ in range(40):
            cl, cr = -found["left"][1], -found["right"][1]
            f = cl - cr  # decreasing in phi
            if np.all(np.abs(f) < 1e-13):
                break
            lo = np.where(f > 0, phi, lo)
            hi = np.where(f <= 0, phi, hi)
            dl = sides["left"].describe(found["left"][0], shifts, phi, 0.0)["droll"]
            dr = sides["right"].describe(found["right"][0], shifts, phi, 0.0)["droll"]
            with np.errstate(divide="ignore", invalid="ignore"):
                newton = phi - f / (dl - dr)
            inside = np.isfinite(newton) & (newton > lo) & (newton < hi)
            phi = np.where(np.abs(f) < 1e-13, phi, np.where(inside, newton, 0.5 * (lo + hi)))
            found = touch(phi)
    heights = {k: -found[k][1] for k in sides}
    height = 0.5 * (heights["left"] + heights["right"])
    out = {k: {} for k in ("rolling_radius_m", "contact_angle_rad", "contact_y_m", "contact_z_m", "wheel_y_m",
                           "rail_y_m", "two_point", "second_rolling_radius_m", "second_contact_angle_rad",
                           "second_contact_y_m", "gap_difference_m")}
    for name, side in sides.items():
        s1, v1, s2, v2 = found[name]
        h = heights[name]
        d1 = side.describe(s1, shifts, phi, h)
        _check_edges(side, name, s1, d1)
        dv = v2 - v1
        two = dv < tol2
        d2 = side.describe(np.where(np.isfinite(s2), s2, s1), shifts, phi, h)
        out["rolling_radius_m"][name] = d1["radius"]
        out["contact_angle_rad"][name] = d1["angle"]
        out["contact_y_m"][name] = d1["Y"]
        out["contact_z_m"][name] = d1["Z"]
        out["wheel_y_m"][name] = d1["wheel_y"]
        out["rail_y_m"][name] = d1["rail_y"]
        out["two_point"][name] = two
        out["second_rolling_radius_m"][name] = np.where(two, d2["radius"], np.nan)
        out["second_contact_angle_rad"][name] = np.where(two, d2["angle"], np.nan)
        out["second_contact_y_m"][name] = np.where(two, d2["Y"], np.nan)
        out["gap_difference_m"][name] = dv
    return ContactGeometry(shifts, phi, height, rail_origin_y_m=0.0, **out)


def _check_edges(side: WheelOnRail, name: str, s, d) -> None:
    margin = 1e-4
    at_wheel_end = (s <= side.wheel.s_min + side.h) | (s >= side.wheel.s_max - side.h)
    ry0, ry1 = side.rail_range
    at_rail_end = (d["rail_y"] <= ry0 + margin) | (d["rail_y"] >= ry1 - margin)
    behind_tip = d["wheel_y"] < side.tip_y - 1e-4
    bad = at_wheel_end | at_rail_end | behind_tip
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        if at_wheel_end[k]:
            what = (f"the {name} wheel touches at the end of the wheel profile "
                    f"(wheel y = {d['wheel_y'][k] * 1e3:.1f} mm)")
        elif at_rail_end[k]:
            what = (f"the {name} wheel touches the rail at the end of the rail profile "
                    f"(rail y = {d['rail_y'][k] * 1e3:.1f} mm)")
        else:
            what = (f"the {name} wheel touches on the back of its flange (wheel y = {d['wheel_y'][k] * 1e3:.1f} mm, "
                    f"flange tip at {side.tip_y * 1e3:.1f} mm)")
        raise NoContact(k, what)
