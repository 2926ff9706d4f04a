"""Linear lateral stability of a suspended wheelset: state matrix, eigenvalues, critical speed.

The classical linear model (Wickens; Knothe and Stichel, *Rail Vehicle Dynamics*): a rigid
wheelset of mass ``m`` and yaw inertia ``Iz`` with coned wheels (conicity ``lambda``, rolling
radius ``r0``, contact points ``+-b`` from the axle centre), attached to a carrier that moves at
constant speed ``V`` along straight track by a lateral stiffness ``ky`` and a yaw stiffness
``kpsi``; Kalker's linear creep forces with the coefficients ``f11 = G a b C11``,
``f22 = G a b C22`` and optionally the spin terms ``f23 = G (ab)^1.5 C23``,
``f33 = G (ab)^2 C33`` (conventions of :mod:`symcat.wheelrail.creep`). Coordinates: lateral
displacement ``y`` (m, toward the left rail) and yaw ``psi`` (rad, about the upward axis); the
wheel's spin speed is taken as ``V / r0`` (its perturbation and the longitudinal motion are
decoupled from ``y, psi`` by symmetry).

Linear creepages of the left (``+b``) and right (``-b``) wheel::

    xi_x = -+ (lambda y / r0 + b psi_dot / V)
    xi_y = kappa y_dot / V - psi
    phi  = psi_dot / V

Coned wheels on rounded rails roll with the lateral shift, ``roll = rho y`` (``rho`` in 1/m,
about ``lambda / b``; 0 in the textbook model). Then (i) the contact points, ``r0`` below the
axle, move laterally ``kappa = 1 + r0 rho`` times as fast as the axle centre, and the lateral
creep forces act on ``y`` through the same ``kappa`` (virtual work); (ii) the roll inertia
``Ix`` adds ``Ix rho^2`` to the lateral mass; (iii) the spinning wheelset (``Iy``, angular
speed ``V / r0``) couples yaw and lateral motion gyroscopically, ``g = Iy V rho / r0``. The
equations of motion ``M q'' + D q' + K q = 0``, ``q = (y, psi)``::

    M = diag(m + Ix rho^2, Iz)
    D = [[2 f22 kappa^2,  2 f23 kappa        ],  / V  +  [[0, -g],
         [-2 f23 kappa,   2 f11 b^2 + 2 f33  ]]           [g,  0]]
    K = [[ky + kg,              -2 f22 kappa ],
         [2 f11 b lambda / r0,  kpsi + 2 f23 ]]

``kg`` is the (optional) gravitational stiffness of the contact angles, ``W d^2 z/dy^2`` for an
axle centre at height ``z(y)`` under the vertical load ``W``. Without spin terms
(``f23 = f33 = 0``), roll (``rho = 0``) and ``kg`` this is the textbook model; at low speed the
creep forces dominate the inertia and the motion tends to Klingel's kinematic oscillation of
angular frequency ``V sqrt(lambda / (kappa b r0))``.

Neglected: the cosines of the contact angle in the creepages and forces (1 - cos^2 0.05 = 0.25 %
for a 1:20 cone), the constant spin creepage of the contact angles (equal and opposite on the
two wheels) and the gravitational yaw stiffness (of order ``N delta^2 r0``, ~100 N m/rad).

Functions: :func:`linear_creep_coefficients` (``f11 ... f33`` from an ellipse),
:func:`state_matrix` (the 4x4 first-order matrix ``A(V)`` of ``(y, psi, y_dot, psi_dot)``),
:func:`eigenvalues` and :func:`critical_speed` (the lowest speed at which the largest real part
of the eigenvalues crosses zero, by bracketing on a speed grid and bisection). SI units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from symcat.errors import ParameterError
from symcat.wheelrail.creep import SHEAR_MODULUS_STEEL_PA, KalkerCoefficients, kalker_coefficients
from symcat.wheelrail.hertz import POISSON_RATIO_STEEL

__all__ = [
    "CreepCoefficients",
    "CriticalSpeed",
    "SuspendedWheelset",
    "critical_speed",
    "eigenvalues",
    "linear_creep_coefficients",
    "state_matrix",
]


class CreepCoefficients(NamedTuple):
    """Kalker's linear creep coefficients of one contact: ``f11``, ``f22`` (N), ``f23`` (N m),
    ``f33`` (N m^2)."""

    f11_N: float
    f22_N: float
    f23_N_m: float
    f33_N_m2: float


class CriticalSpeed(NamedTuple):
    """Result of :func:`critical_speed`.

    Attributes
    ----------
    speed_m_s : float
        Critical speed (m/s); ``inf`` if the wheelset is stable over the whole searched range.
    angular_frequency_rad_s : float
        Imaginary part of the eigenvalue that crosses the imaginary axis (rad/s; NaN if none).
    frequency_Hz : float
        The same in Hz.
    wavelength_m : float
        Distance travelled per cycle at the critical speed, ``2 pi V / omega`` (m).
    """

    speed_m_s: float
    angular_frequency_rad_s: float
    frequency_Hz: float
    wavelength_m: float


def _check(name: str, value, minimum: float = 0.0, allow_equal: bool = False, unit: str = "") -> float:
    """``value`` as a float, or :class:`ParameterError` naming ``name`` if not finite or not
    above (or, with ``allow_equal``, at least) ``minimum``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}={value!r}: must be a number") from None
    ok = math.isfinite(v) and (v >= minimum if allow_equal else v > minimum)
    if not ok:
        relation = ">=" if allow_equal else ">"
        raise ParameterError(f"{name}={value!r}{' ' + unit if unit else ''}: must be finite and {relation} {minimum:g}")
    return v


def linear_creep_coefficients(a_m: float, b_m: float, coefficients: KalkerCoefficients | None = None,
                              poisson_ratio: float = POISSON_RATIO_STEEL,
                              shear_modulus_Pa: float = SHEAR_MODULUS_STEEL_PA) -> CreepCoefficients:
    """Kalker's linear creep coefficients of a contact ellipse.

    ``f11 = G a b C11``, ``f22 = G a b C22``, ``f23 = G (ab)^1.5 C23``, ``f33 = G (ab)^2 C33``,
    so that :func:`symcat.wheelrail.creep.kalker_linear_forces` reads ``Fx = -f11 xi_x``,
    ``Fy = -f22 xi_y - f23 phi``, ``Mz = f23 xi_y - f33 phi``.

    Parameters
    ----------
    a_m, b_m : float
        Semi-axes of the ellipse along and across the rolling direction (m), > 0 (e.g. from
        :func:`symcat.wheelrail.hertz.hertz_contact`).
    coefficients : KalkerCoefficients, optional
        Kalker's ``C11, C22, C23, C33``; default :func:`symcat.wheelrail.creep.kalker_coefficients`
        at ``a/b`` (clamped into the table) and ``poisson_ratio``.
    poisson_ratio : float
        Poisson's ratio (-), used only without ``coefficients``; default 0.3.
    shear_modulus_Pa : float
        Shear modulus ``G`` (Pa), > 0; default steel.

    Returns
    -------
    CreepCoefficients
    """
    a = _check("a_m", a_m, unit="m")
    b = _check("b_m", b_m, unit="m")
    g = _check("shear_modulus_Pa", shear_modulus_Pa, unit="Pa")
    if coefficients is None:
        coefficients = kalker_coefficients(a / b, poisson_ratio, clamp=True)
    c11, c22, c23, c33 = (float(c) for c in coefficients)
    ab = a * b
    return CreepCoefficients(g * ab * c11, g * ab * c22, g * ab**1.5 * c23, g * ab**2 * c33)


@dataclass(frozen=True)
class SuspendedWheelset:
    """Parameters of the linear wheelset model (module docstring), validated on creation.

    Parameters
    ----------
    mass_kg : float
        Wheelset mass ``m`` (kg), > 0.
    yaw_inertia_kg_m2 : float
        Moment of inertia about the vertical axis ``Iz`` (kg m^2), > 0.
    conicity : float
        Equivalent conicity ``lambda`` (-), > 0: ``r_left - r_right = 2 lambda y``.
    rolling_radius_m : float
        Centred rolling radius ``r0`` (m), > 0.
    contact_half_distance_m : float
        Half the lateral distance between the two contact points ``b`` (m), > 0.
    f11_N, f22_N : float
        Longitudinal and lateral creep coefficients of one contact (N), > 0.
    lateral_stiffness_N_m : float
        Lateral stiffness ``ky`` between wheelset and carrier (N/m), >= 0.
    yaw_stiffness_N_m_rad : float
        Yaw stiffness ``kpsi`` between wheelset and carrier (N m/rad), >= 0.
    f23_N_m : float
        Lateral-spin coefficient of one contact (N m), >= 0; 0 (default) neglects spin.
    f33_N_m2 : float
        Spin coefficient of one contact (N m^2), >= 0; default 0.
    gravitational_stiffness_N_m : float
        Lateral gravitational stiffness ``kg`` of the contact angles (N/m), any sign; default 0.
    roll_coefficient_per_m : float
        ``rho = d(roll)/dy`` (1/m), >= 0; default 0 (no roll: the textbook model).
    roll_inertia_kg_m2 : float
        ``Ix`` about the forward axis (kg m^2), >= 0; acts only with ``rho > 0``. Default 0.
    spin_inertia_kg_m2 : float
        ``Iy`` about the axle (kg m^2), >= 0; gyroscopic coupling only with ``rho > 0``.
        Default 0.
    """

    mass_kg: float
    yaw_inertia_kg_m2: float
    conicity: float
    rolling_radius_m: float
    contact_half_distance_m: float
    f11_N: float
    f22_N: float
    lateral_stiffness_N_m: float
    yaw_stiffness_N_m_rad: float
    f23_N_m: float = 0.0
    f33_N_m2: float = 0.0
    gravitational_stiffness_N_m: float = 0.0
    roll_coefficient_per_m: float = 0.0
    roll_inertia_kg_m2: float = 0.0
    spin_inertia_kg_m2: float = 0.0

    def __post_init__(self):
        positive = (("mass_kg", "kg"), ("yaw_inertia_kg_m2", "kg m^2"), ("conicity", ""),
                    ("rolling_radius_m", "m"), ("contact_half_distance_m", "m"), ("f11_N", "N"), ("f22_N", "N"))
        for name, unit in positive:
            object.__setattr__(self, name, _check(name, getattr(self, name), unit=unit))
        non_negative = (("lateral_stiffness_N_m", "N/m"), ("yaw_stiffness_N_m_rad", "N m/rad"), ("f23_N_m", "N m"),
                        ("f33_N_m2", "N m^2"), ("roll_coefficient_per_m", "1/m"), ("roll_inertia_kg_m2", "kg m^2"),
                        ("spin_inertia_kg_m2", "kg m^2"))
        for name, unit in non_negative:
            object.__setattr__(self, name, _check(name, getattr(self, name), allow_equal=True, unit=unit))
        kg = _check("gravitational_stiffness_N_m", self.gravitational_stiffness_N_m, minimum=-math.inf, unit="N/m")
        object.__setattr__(self, "gravitational_stiffness_N_m", kg)

    @property
    def contact_lateral_ratio(self) -> float:
        """``kappa = 1 + r0 rho`` (-): lateral velocity of the contact points over the axle's."""
        return 1.0 + self.rolling_radius_m * self.roll_coefficient_per_m

    def matrices(self, speed_m_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(M, D, K)`` of ``M q'' + D q' + K q = 0``, ``q = (y, psi)``, at ``speed_m_s``
        (m/s, > 0); SI units (kg, kg m^2; N s/m ...; N/m ...)."""
        v = _check("speed_m_s", speed_m_s, unit="m/s")
        lam, r0, b = self.conicity, self.rolling_radius_m, self.contact_half_distance_m
        f11, f22, f23, f33 = self.f11_N, self.f22_N, self.f23_N_m, self.f33_N_m2
        rho = self.roll_coefficient_per_m
        kap = self.contact_lateral_ratio
        gyro = self.spin_inertia_kg_m2 * v * rho / r0
        mass = np.diag([self.mass_kg + self.roll_inertia_kg_m2 * rho**2, self.yaw_inertia_kg_m2])
        damping = np.array([[2 * f22 * kap**2, 2 * f23 * kap],
                            [-2 * f23 * kap, 2 * f11 * b**2 + 2 * f33]]) / v
        damping += np.array([[0.0, -gyro], [gyro, 0.0]])
        stiffness = np.array([[self.lateral_stiffness_N_m + self.gravitational_stiffness_N_m, -2 * f22 * kap],
                              [2 * f11 * b * lam / r0, self.yaw_stiffness_N_m_rad + 2 * f23]])
        return mass, damping, stiffness


def state_matrix(wheelset: SuspendedWheelset, speed_m_s: float) -> np.ndarray:
    """First-order state matrix ``A(V)`` of ``x = (y, psi, y_dot, psi_dot)``, ``x' = A x``.

    Parameters
    ----------
    wheelset : SuspendedWheelset
    speed_m_s : float
        Forward speed ``V`` (m/s), > 0.

    Returns
    -------
    ndarray (4, 4)
        ``[[0, I], [-M^-1 K, -M^-1 D]]`` (:meth:`SuspendedWheelset.matrices`): the identity block
        is dimensionless, the stiffness block in 1/s^2, the damping block in 1/s (for ``y`` in m
        and ``psi`` in rad).
    """
    if not isinstance(wheelset, SuspendedWheelset):
        raise ParameterError(f"wheelset={wheelset!r}: must be a SuspendedWheelset")
    mass, damping, stiffness = wheelset.matrices(speed_m_s)
    inv = np.diag(1.0 / np.diag(mass))
    a = np.zeros((4, 4))
    a[:2, 2:] = np.eye(2)
    a[2:, :2] = -inv @ stiffness
    a[2:, 2:] = -inv @ damping
    return a


def eigenvalues(wheelset: SuspendedWheelset, speed_m_s: float) -> np.ndarray:
    """The four eigenvalues of :func:`state_matrix` (1/s), sorted by decreasing real part.

    Parameters
    ----------
    wheelset : SuspendedWheelset
    speed_m_s : float
        Forward speed (m/s), > 0.

    Returns
    -------
    ndarray (4,) complex
        ``Re`` is the growth rate (1/s, > 0 unstable), ``|Im|`` the angular frequency (rad/s).
    """
    lam = np.linalg.eigvals(state_matrix(wheelset, speed_m_s))
    return lam[np.lexsort((-np.abs(lam.imag), -lam.real))]


def _growth(wheelset: SuspendedWheelset, speed: float) -> float:
    return float(eigenvalues(wheelset, speed)[0].real)


def critical_speed(wheelset: SuspendedWheelset, v_min_m_s: float = 0.5, v_max_m_s: float = 500.0,
                   n_grid: int = 200, rtol: float = 1e-10) -> CriticalSpeed:
    """Lowest speed in ``[v_min, v_max]`` at which the wheelset becomes unstable.

    The largest real part of :func:`eigenvalues` is sampled on a geometric grid of ``n_grid``
    speeds; the first change from negative to non-negative is refined by bisection to the
    relative width ``rtol``.

    Parameters
    ----------
    wheelset : SuspendedWheelset
    v_min_m_s, v_max_m_s : float
        Searched speed range (m/s), ``0 < v_min < v_max``. The wheelset must be stable at
        ``v_min``.
    n_grid : int
        Grid speeds, >= 2 (more finds narrow unstable windows).
    rtol : float
        Relative width of the final bracket, in (0, 0.1).

    Returns
    -------
    CriticalSpeed
        ``speed_m_s = inf`` (and NaN frequency) if stable over the whole range.

    Raises
    ------
    ParameterError
        On invalid arguments, or if the wheelset is already unstable at ``v_min``.
    """
    if not isinstance(wheelset, SuspendedWheelset):
        raise ParameterError(f"wheelset={wheelset!r}: must be a SuspendedWheelset")
    lo = _check("v_min_m_s", v_min_m_s, unit="m/s")
    hi = _check("v_max_m_s", v_max_m_s, unit="m/s")
    if not hi > lo:
        raise ParameterError(f"v_max_m_s={v_max_m_s!r} m/s: must be > v_min_m_s={v_min_m_s!r} m/s")
    if isinstance(n_grid, bool) or not isinstance(n_grid, (int, np.integer)) or n_grid < 2:
        raise ParameterError(f"n_grid={n_grid!r}: must be an integer >= 2")
    if not (isinstance(rtol, (int, float)) and 0 < rtol < 0.1):
        raise ParameterError(f"rtol={rtol!r}: must lie in (0, 0.1)")
    speeds = np.geomspace(lo, hi, int(n_grid))
    growth = [_growth(wheelset, v) for v in speeds]
    if growth[0] >= 0:
        raise ParameterError(f"v_min_m_s={v_min_m_s!r} m/s: the wheelset is already unstable there (largest real "
                             f"part {growth[0]:.3g} 1/s); lower v_min_m_s")
    k = next((i for i in range(1, len(speeds)) if growth[i] >= 0), None)
    if k is None:
        return CriticalSpeed(math.inf, math.nan, math.nan, math.nan)
    a, b = float(speeds[k - 1]), float(speeds[k])
    while b - a > rtol * b:
        mid = 0.5 * (a + b)
        if _growth(wheelset, mid) < 0:
            a = mid
        else:
            b = mid
    v = 0.5 * (a + b)
    omega = abs(float(eigenvalues(wheelset, v)[0].imag))
    wavelength = 2 * math.pi * v / omega if omega > 0 else math.inf
    return CriticalSpeed(v, omega, omega / (2 * math.pi), wavelength)
