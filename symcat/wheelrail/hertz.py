"""Hertz's elliptic contact between wheel and rail.

Two bodies of the same material touch at a point where their relative
surface is ``z = A x**2 + B y**2``; ``x`` is the rolling direction, ``y`` the
lateral one, ``A`` and ``B`` (1/m) the principal relative curvatures (half the
sums of the bodies' curvatures, positive for convex surfaces). Pressed by a
normal force ``N`` the contact is an ellipse with semi-axes ``a`` (along x)
and ``b`` (along y) carrying the pressure ``p0 sqrt(1 - x²/a² - y²/b²)``.

With ``k = minor/major`` and Carlson's symmetric integrals
``D = R_D(0, k², 1) / 3`` (= (K - E)/e²) and ``K = R_F(0, k², 1)`` (the complete
integral of the first kind, parameter ``m = e² = 1 - k²``), Hertz's equations
(Johnson, Contact Mechanics, 1985, Sec. 4.2) read, with ``A_s <= B_s`` the
smaller and larger curvature and the major axis along the smaller one:

    B_s / A_s = R_D(0, 1, k²) / R_D(0, k², 1)
    major**3  = 3 N D / (2 pi A_s E*)
    approach  = A_s major**2 K / D
    p0        = 3 N / (2 pi a b)

``E* = E / (2 (1 - nu²))`` for two bodies of one material. The first equation
is solved for ``k`` by Newton's method in ``ln k`` (complex-step derivative),
so the result is exact to round-off rather than read from a table.

At fixed curvatures the shape does not change with load, hence the Hertz
law ``N = K_H approach**1.5`` with a constant ``K_H`` (N/m^1.5); it serves as
the elastic (penalty) normal contact where a constraint cannot describe
lift-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import elliprd, elliprf

from symcat.errors import ParameterError

YOUNGS_MODULUS_STEEL_PA = 210e9
POISSON_RATIO_STEEL = 0.3

__all__ = [
    "POISSON_RATIO_STEEL",
    "YOUNGS_MODULUS_STEEL_PA",
    "HertzContact",
    "contact_modulus",
    "hertz_contact",
    "hertz_normal_force",
    "hertz_stiffness_coefficient",
    "relative_curvatures",
]


@dataclass(frozen=True)
class HertzContact:
    """Hertz contact ellipse (arrays broadcast from the inputs).

    Attributes
    ----------
    semi_axis_a_m : semi-axis in the rolling direction (m).
    semi_axis_b_m : semi-axis in the lateral direction (m).
    approach_m : mutual approach of distant points of the bodies (m).
    max_pressure_Pa : peak pressure ``p0 = 3 N / (2 pi a b)`` (Pa).
    stiffness_coefficient_N_per_m1_5 : ``K_H`` in ``N = K_H approach**1.5``.
    tangent_stiffness_N_per_m : ``dN/d(approach) = 1.5 N / approach`` (N/m).
    normal_force_N : the normal force the ellipse carries (N).
    """

    semi_axis_a_m: np.ndarray
    semi_axis_b_m: np.ndarray
    approach_m: np.ndarray
    max_pressure_Pa: np.ndarray
    stiffness_coefficient_N_per_m1_5: np.ndarray
    tangent_stiffness_N_per_m: np.ndarray
    normal_force_N: np.ndarray

    @property
    def a_over_b(self):
        """Ratio of the rolling to the lateral semi-axis (Kalker's a/b)."""
        return self.semi_axis_a_m / self.semi_axis_b_m


def contact_modulus(youngs_modulus_Pa=YOUNGS_MODULUS_STEEL_PA, poisson_ratio=POISSON_RATIO_STEEL):
    """Contact modulus ``E* = E / (2 (1 - nu²))`` of two bodies of one material (Pa).

    Parameters
    ----------
    youngs_modulus_Pa : float
        Young's modulus of wheel and rail (Pa); steel 210 GPa.
    poisson_ratio : float
        Poisson's ratio in [0, 0.5); steel 0.3 (the default; 0.28 is also used).
    """
    _check_material(youngs_modulus_Pa, poisson_ratio)
    return youngs_modulus_Pa / (2.0 * (1.0 - poisson_ratio**2))


def relative_curvatures(rolling_radius_m, wheel_profile_curvature_per_m, rail_profile_curvature_per_m,
                        contact_angle_rad=0.0):
    """Principal relative curvatures ``(A, B)`` (1/m) of a wheel/rail contact.

    The principal directions are taken as the rolling (x) and lateral (y)
    directions (wheelset yaw neglected) and the rail straight along the track.

    Parameters
    ----------
    rolling_radius_m : float or array
        Wheel rolling radius at the contact (m).
    wheel_profile_curvature_per_m : float or array
        Curvature of the wheel profile at the contact, in the profile plane
        (1/m); positive where the profile is convex, negative where it is
        concave (worn hollow treads, the flange root); 0 for a coned tread.
        (``symcat.wheelrail.profiles.Profile.curvature`` has the opposite
        sign: pass its negative, for the rail too.)
    rail_profile_curvature_per_m : float or array
        Curvature of the rail head profile at the contact (1/m), positive
        where convex (1/0.3 m on the UIC60 crown).
    contact_angle_rad : float or array
        Angle between the contact normal and the vertical (rad). The wheel's
        normal curvature along the rolling direction is ``cos(angle) / r``
        (Meusnier), which matters at the flange.

    Returns
    -------
    (A, B) : tuple of arrays
        ``A = cos(angle) / (2 r)`` along the rolling direction and
        ``B = (wheel + rail profile curvature) / 2`` across it (1/m).
    """
    r = np.asarray(rolling_radius_m, dtype=float)
    if np.any(~(r > 0)):
        raise ParameterError(f"rolling_radius_m must be > 0 m, got {rolling_radius_m}")
    angle = np.asarray(contact_angle_rad, dtype=float)
    if np.any(~(np.abs(angle) < 0.5 * np.pi)):
        raise ParameterError(f"contact_angle_rad must lie in (-pi/2, pi/2), got {contact_angle_rad}")
    A = 0.5 * np.cos(angle) / r
    B = 0.5 * (np.asarray(wheel_profile_curvature_per_m, dtype=float)
               + np.asarray(rail_profile_curvature_per_m, dtype=float))
    if np.any(~(B > 0)):
        raise ParameterError(
            "wheel_profile_curvature_per_m + rail_profile_curvature_per_m must be > 0 "
            f"(a concave wheel must be less curved than the rail), got {2 * B} 1/m")
    return A, B


def hertz_contact(normal_force_N, A_per_m, B_per_m, youngs_modulus_Pa=YOUNGS_MODULUS_STEEL_PA,
                  poisson_ratio=POISSON_RATIO_STEEL):
    """Contact ellipse, approach, peak pressure and stiffness from Hertz's theory.

    Parameters
    ----------
    normal_force_N : float or array
        Normal force (N), > 0.
    A_per_m, B_per_m : float or array
        Relative curvatures along the rolling (A) and the lateral (B)
        direction (1/m), > 0 (see :func:`relative_curvatures`).
    youngs_modulus_Pa : float
        Young's modulus of both bodies (Pa); default steel 210 GPa.
    poisson_ratio : float
        Poisson's ratio of both bodies; default 0.3.

    Returns
    -------
    HertzContact
        Semi-axes ``a`` (rolling) and ``b`` (lateral); the larger one lies
        along the smaller curvature (swapping A and B swaps a and b).
    """
    N = np.asarray(normal_force_N, dtype=float)
    if np.any(~(N > 0)):
        raise ParameterError(f"normal_force_N must be > 0 N, got {normal_force_N}")
    A, B = _check_curvatures(A_per_m, B_per_m)
    e_star = contact_modulus(youngs_modulus_Pa, poisson_ratio)
    small, k = _shape(A, B)
    d = elliprd(0.0, k**2, 1.0) / 3.0
    major = np.cbrt(3.0 * N * d / (2.0 * np.pi * small * e_star))
    minor = k * major
    approach = small * major**2 * elliprf(0.0, k**2, 1.0) / d
    a = np.where(A <= B, major, minor)
    b = np.where(A <= B, minor, major)
    return HertzContact(
        semi_axis_a_m=a,
        semi_axis_b_m=b,
        approach_m=approach,
        max_pressure_Pa=3.0 * N / (2.0 * np.pi * a * b),
        stiffness_coefficient_N_per_m1_5=N / approach**1.5,
        tangent_stiffness_N_per_m=1.5 * N / approach,
        normal_force_N=N * np.ones_like(a),
    )


def hertz_stiffness_coefficient(A_per_m, B_per_m, youngs_modulus_Pa=YOUNGS_MODULUS_STEEL_PA,
                                poisson_ratio=POISSON_RATIO_STEEL):
    """``K_H`` (N/m^1.5) of the Hertz law ``N = K_H approach**1.5``.

    Independent of the load: ``K_H = 2 pi E* sqrt(D) / (3 sqrt(A_s) K**1.5)``
    (notation of the module docstring); ``4/3 E* sqrt(R)`` for a sphere of
    radius R on a plane.
    """
    A, B = _check_curvatures(A_per_m, B_per_m)
    e_star = contact_modulus(youngs_modulus_Pa, poisson_ratio)
    small, k = _shape(A, B)
    d = elliprd(0.0, k**2, 1.0) / 3.0
    return 2.0 * np.pi * e_star * np.sqrt(d / small) / (3.0 * elliprf(0.0, k**2, 1.0) ** 1.5)


def hertz_normal_force(penetration_m, A_per_m, B_per_m, youngs_modulus_Pa=YOUNGS_MODULUS_STEEL_PA,
                       poisson_ratio=POISSON_RATIO_STEEL):
    """Normal force (N) from the penetration (approach) by the Hertz law.

    ``N = K_H max(penetration, 0)**1.5``: zero when the bodies separate, so an
    elastic contact handles lift-off that a constraint cannot.

    Parameters
    ----------
    penetration_m : float or array
        Interpenetration of the undeformed surfaces along the normal (m);
        negative values mean a gap.
    A_per_m, B_per_m, youngs_modulus_Pa, poisson_ratio
        As in :func:`hertz_contact`.
    """
    k_h = hertz_stiffness_coefficient(A_per_m, B_per_m, youngs_modulus_Pa, poisson_ratio)
    delta = np.maximum(np.asarray(penetration_m, dtype=float), 0.0)
    return k_h * delta**1.5


def _check_material(youngs_modulus_Pa, poisson_ratio):
    if not np.all(np.asarray(youngs_modulus_Pa, dtype=float) > 0):
        raise ParameterError(f"youngs_modulus_Pa must be > 0 Pa, got {youngs_modulus_Pa}")
    nu = np.asarray(poisson_ratio, dtype=float)
    if not np.all((nu >= 0) & (nu < 0.5)):
        raise ParameterError(f"poisson_ratio must lie in [0, 0.5), got {poisson_ratio}")


def _check_curvatures(A_per_m, B_per_m):
    A = np.asarray(A_per_m, dtype=float)
    B = np.asarray(B_per_m, dtype=float)
    for name, value, given in (("A_per_m", A, A_per_m), ("B_per_m", B, B_per_m)):
        if np.any(~(value > 0)) or np.any(~np.isfinite(value)):
            raise ParameterError(f"{name} must be finite and > 0 1/m (convex relative surface), got {given}")
    return np.broadcast_arrays(A, B)


def _shape(A, B):
    """Smaller curvature and minor/major axis ratio k for curvatures A, B."""
    small = np.minimum(A, B)
    ratio = np.maximum(A, B) / small
    if np.any(ratio > 1e12):
        raise ParameterError(
            f"curvature ratio B/A must be <= 1e12 (a line contact is not Hertzian), got {ratio.max()}")
    return small, _axis_ratio(ratio)


def _log_ratio(t):
    # ln(B/A) as a function of t = ln(k); analytic, so complex arguments give its derivative
    k2 = np.exp(2.0 * t)
    return np.log(elliprd(0.0, 1.0, k2)) - np.log(elliprd(0.0, k2, 1.0))


def _axis_ratio(ratio):
    """Solve B/A = R_D(0,1,k²) / R_D(0,k²,1) for k = minor/major in (0, 1]."""
    target = np.log(ratio)
    # Hamrock & Brewe's fit a/b ~ 1.0339 (B/A)^0.636 as the start
    t = np.minimum(-(np.log(1.0339) + 0.636 * target), 0.0)
    h = 1e-30
    for _ in range(50):
        f = _log_ratio(t + 1j * h)
        step = (f.real - target) / (f.imag / h)
        t_new = np.minimum(t - step, 0.0)
        # f is monotone and smooth in t; Newton stays in range after the clip
        if np.all(np.abs(t_new - t) <= 1e-15 * np.maximum(1.0, np.abs(t))):
            t = t_new
            break
        t = t_new
    # a circle exactly, not within round-off of it
    return np.where(target == 0.0, 1.0, np.exp(t))
