"""Creepages of a wheel/rail contact from its kinematics (conventions of :mod:`symcat.wheelrail.creep`).

:func:`creepages_from_slip` and :func:`contact_creepages` work from the slip velocity or the
motion of the bodies at the contact point; :func:`wheelset_creepages` is the classic linearised
wheelset form (both agree to second order in the motion, tested).
"""
from __future__ import annotations

import numpy as np

from symcat.errors import ParameterError

from .creep import Creepages, _check_frame

__all__ = ["contact_creepages", "creepages_from_slip", "wheelset_creepages"]



def creepages_from_slip(slip_velocity_mps, relative_angular_velocity_radps, t1, t2, n, rolling_speed_mps):
    """Creepages from the slip velocity and relative angular velocity at a contact.

    Parameters
    ----------
    slip_velocity_mps : array (..., 3)
        Velocity of the wheel material point at the contact minus that of the
        rail material point (m/s), any frame (the same as the t's).
    relative_angular_velocity_radps : array (..., 3)
        Angular velocity of the wheel minus that of the rail (rad/s).
    t1, t2, n : array (..., 3)
        Contact frame (see the module docstring): orthonormal, right-handed.
    rolling_speed_mps : float or array
        Rolling speed V (m/s), > 0.

    Returns
    -------
    Creepages
        ``xi_x = v.t1/V``, ``xi_y = v.t2/V``, ``phi = omega.n/V`` (1/m).
    """
    t1, t2, n = _check_frame(t1, t2, n)
    speed = np.asarray(rolling_speed_mps, dtype=float)
    if np.any(~(speed > 0)):
        raise ParameterError(
            f"rolling_speed_mps must be > 0 m/s (creepages are undefined at rest), got {rolling_speed_mps}")
    v = np.asarray(slip_velocity_mps, dtype=float)
    w = np.asarray(relative_angular_velocity_radps, dtype=float)
    return Creepages(np.sum(v * t1, axis=-1) / speed, np.sum(v * t2, axis=-1) / speed,
                     np.sum(w * n, axis=-1) / speed)


def contact_creepages(wheel_velocity_mps, wheel_angular_velocity_radps, wheel_centre_m, contact_point_m,
                      t1, t2, n, rolling_speed_mps=None, rail_velocity_mps=0.0,
                      rail_angular_velocity_radps=0.0):
    """Creepages from the rigid-body motion of a wheel over a rail.

    Parameters
    ----------
    wheel_velocity_mps : array (..., 3)
        Velocity of the wheel's reference point (m/s).
    wheel_angular_velocity_radps : array (..., 3)
        Angular velocity of the wheel (wheelset) body (rad/s).
    wheel_centre_m : array (..., 3)
        Position of the wheel's reference point (m).
    contact_point_m : array (..., 3)
        Position of the contact point (m).
    t1, t2, n : array (..., 3)
        Contact frame (module docstring).
    rolling_speed_mps : float or array, optional
        Rolling speed V (m/s); default the speed of the wheel's reference
        point along t1 (the vehicle speed; pass it for a roller rig).
    rail_velocity_mps : array (..., 3)
        Velocity of the rail material point at the contact (m/s); 0 for track.
    rail_angular_velocity_radps : array (..., 3)
        Angular velocity of the rail (rad/s); 0 for track.

    Returns
    -------
    Creepages
    """
    v_c = np.asarray(wheel_velocity_mps, dtype=float)
    omega = np.asarray(wheel_angular_velocity_radps, dtype=float)
    arm = np.asarray(contact_point_m, dtype=float) - np.asarray(wheel_centre_m, dtype=float)
    slip = v_c + np.cross(omega, arm) - np.asarray(rail_velocity_mps, dtype=float)
    if rolling_speed_mps is None:
        rolling_speed_mps = np.abs(np.sum(v_c * np.asarray(t1, dtype=float), axis=-1))
    return creepages_from_slip(slip, omega - np.asarray(rail_angular_velocity_radps, dtype=float),
                               t1, t2, n, rolling_speed_mps)


def wheelset_creepages(speed_mps, lateral_velocity_mps, yaw_angle_rad, yaw_rate_radps, rolling_radius_m,
                       contact_angle_rad, half_contact_distance_m, nominal_radius_m, spin_radps=None,
                       roll_rate_radps=0.0):
    """Linearised creepages of a wheelset on straight track (left and right wheel).

    Frame: x forward along the track, y to the left, z up; yaw positive nose
    left. The contact angle is positive when the contact normal leans towards
    the track centre (tread with positive conicity, flange). The wheel is
    assumed to stay on the rail (no normal velocity at the contact), whence
    the ``1/cos`` on the lateral creepage (Garg and Dukkipati, 1984):

        xi_x = 1 - Omega r / V - s l0 yaw_rate / V
        xi_y = ((lateral_velocity + r roll_rate) / V - yaw) / cos(angle)
        phi  = (yaw_rate cos(angle) - s Omega sin(angle)) / V

    with ``s = +1`` left, ``-1`` right, ``Omega`` the spin about the axle.
    The roll rate term is often dropped: on coned wheels the roll rate is
    about ``-conicity lateral_velocity / l0``, a few per cent of the lateral
    velocity term on treads but not at the flange.

    Parameters
    ----------
    speed_mps : float
        Forward speed V (m/s), > 0.
    lateral_velocity_mps : float
        Lateral velocity of the wheelset centre (m/s).
    yaw_angle_rad, yaw_rate_radps : float
        Yaw angle (rad) and yaw rate (rad/s).
    rolling_radius_m : array (..., 2)
        Rolling radii of the left and right contact (m).
    contact_angle_rad : array (..., 2)
        Contact angles, left and right (rad).
    half_contact_distance_m : float
        Half the lateral distance between the contact points (m).
    nominal_radius_m : float
        Nominal rolling radius r0 (m), for the default spin.
    spin_radps : float, optional
        Spin Omega of the wheelset about its axle (rad/s); default V / r0
        (pure rolling at the nominal radius).
    roll_rate_radps : float
        Roll rate of the wheelset about the track's x axis (rad/s); default 0.

    Returns
    -------
    Creepages
        Each an array (..., 2): [left, right].
    """
    speed = np.asarray(speed_mps, dtype=float)
    if np.any(~(speed > 0)):
        raise ParameterError(f"speed_mps must be > 0 m/s, got {speed_mps}")
    if np.any(~(np.asarray(nominal_radius_m, dtype=float) > 0)):
        raise ParameterError(f"nominal_radius_m must be > 0 m, got {nominal_radius_m}")
    radius = np.asarray(rolling_radius_m, dtype=float)
    angle = np.asarray(contact_angle_rad, dtype=float)
    for name, value, given in (("rolling_radius_m", radius, rolling_radius_m),
                               ("contact_angle_rad", angle, contact_angle_rad)):
        if value.shape[-1:] != (2,):
            raise ParameterError(f"{name} must hold [left, right] in its last axis, got shape {value.shape}")
    if np.any(~(radius > 0)):
        raise ParameterError(f"rolling_radius_m must be > 0 m, got {rolling_radius_m}")
    if np.any(~(np.abs(angle) < 0.5 * np.pi)):
        raise ParameterError(f"contact_angle_rad must lie in (-pi/2, pi/2), got {contact_angle_rad}")
    speed = speed[..., None]
    omega = speed / nominal_radius_m if spin_radps is None else np.asarray(spin_radps, dtype=float)[..., None]
    side = np.array([1.0, -1.0])
    yaw_rate = np.asarray(yaw_rate_radps, dtype=float)[..., None]
    xi_x = 1.0 - omega * radius / speed - side * half_contact_distance_m * yaw_rate / speed
    roll_rate = np.asarray(roll_rate_radps, dtype=float)[..., None]
    lateral = np.asarray(lateral_velocity_mps, dtype=float)[..., None] + radius * roll_rate
    xi_y = (lateral / speed - np.asarray(yaw_angle_rad, dtype=float)[..., None]) / np.cos(angle)
    phi = (yaw_rate * np.cos(angle) - side * omega * np.sin(angle)) / speed
    return Creepages(xi_x, xi_y, phi)
