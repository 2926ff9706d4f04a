"""Creepages and creep forces of a wheel/rail contact.

Conventions (all functions of this module)
------------------------------------------
* Contact frame ``(t1, t2, n)``: right-handed unit vectors, ``t1`` along the
  rolling direction (the direction the wheel travels over the rail), ``t2``
  across it, ``n = t1 x t2`` the contact normal pointing from the rail into
  the wheel. Ellipse semi-axes: ``a`` along ``t1``, ``b`` along ``t2``.
* Creepages (dimensionless; spin in 1/m) are the rigid slip of the wheel
  material relative to the rail, divided by the rolling speed ``V > 0``:
  ``xi_x = v_slip.t1 / V``, ``xi_y = v_slip.t2 / V``,
  ``phi = (omega_wheel - omega_rail).n / V``, so that a point ``(x, y)`` of
  the contact area slips by ``V (xi_x - phi y, xi_y + phi x)`` (Kalker).
* Forces are those the rail exerts on the wheel, in the contact plane:
  ``fx_N`` along ``t1``, ``fy_N`` along ``t2``, ``mz_Nm`` about ``n``. They
  oppose the creepage; Kalker's linear theory reads

      Fx = -G a b C11 xi_x
      Fy = -G a b C22 xi_y - G (ab)^1.5 C23 phi
      Mz =  G (ab)^1.5 C23 xi_y - G (ab)^2 C33 phi

* ``G`` is the shear modulus of wheel and rail (one material), ``mu`` the
  Coulomb friction coefficient (default 0.3, dry rail), SI units throughout.

Laws: :func:`kalker_linear_forces` (plain arithmetic: floats, NumPy arrays
and CasADi symbols alike), :func:`shen_hedrick_elkins_forces` (cheap
saturation of the linear forces), :func:`polach_forces` (Polach's closed form
with spin; floats and arrays) and :func:`fastsim_forces` (Kalker's simplified
theory on a strip grid; the reference).
"""

from __future__ import annotations

import csv
from functools import lru_cache
from importlib.resources import files
from typing import NamedTuple

import numpy as np
from scipy.interpolate import PchipInterpolator

from symcat.errors import ParameterError
from symcat.wheelrail.hertz import POISSON_RATIO_STEEL, YOUNGS_MODULUS_STEEL_PA

SHEAR_MODULUS_STEEL_PA = YOUNGS_MODULUS_STEEL_PA / (2.0 * (1.0 + POISSON_RATIO_STEEL))
FRICTION_COEFFICIENT = 0.3

__all__ = [
    "FRICTION_COEFFICIENT",
    "SHEAR_MODULUS_STEEL_PA",
    "CreepForces",
    "Creepages",
    "KalkerCoefficients",
    "contact_creepages",
    "creep_forces",
    "creepages_from_slip",
    "fastsim_forces",
    "kalker_coefficients",
    "kalker_linear_forces",
    "kalker_pieces",
    "polach_forces",
    "polach_friction_coefficient",
    "shen_hedrick_elkins_forces",
    "wheelset_creepages",
]


class KalkerCoefficients(NamedTuple):
    """Kalker's linear creep coefficients (dimensionless)."""

    c11: np.ndarray
    c22: np.ndarray
    c23: np.ndarray
    c33: np.ndarray


class Creepages(NamedTuple):
    """Longitudinal and lateral creepage (-) and spin (1/m)."""

    xi_x: np.ndarray
    xi_y: np.ndarray
    phi_per_m: np.ndarray


class CreepForces(NamedTuple):
    """Creep forces on the wheel along t1 and t2 (N) and moment about n (N m)."""

    fx_N: np.ndarray
    fy_N: np.ndarray
    mz_Nm: np.ndarray


# --------------------------------------------------------------------------
# Kalker's coefficients
# --------------------------------------------------------------------------

_TABLE_NU = (0.0, 0.25, 0.5)
_NAMES = ("C11", "C22", "C23", "C33")


@lru_cache(maxsize=1)
def _kalker_table():
    """PCHIP interpolant in ln(a/b) of the 12 table columns (4 coefficients x 3 nu)."""
    path = files("symcat.reference_data").joinpath("kalker_linear_coefficients.csv")
    with path.open() as handle:
        rows = list(csv.DictReader(line for line in handle if not line.startswith("#")))
    a_over_b = np.array([float(r["a_over_b"]) for r in rows])
    columns = [f"{c}_nu{s}" for c in _NAMES for s in ("0", "025", "05")]
    values = np.array([[float(r[c]) for c in columns] for r in rows])
    # monotone cubic: no overshoot between the table's nodes, smooth across a/b = 1
    return PchipInterpolator(np.log(a_over_b), values, axis=0, extrapolate=False), a_over_b


def kalker_coefficients(a_over_b, poisson_ratio=POISSON_RATIO_STEEL, clamp=False):
    """Kalker's coefficients C11, C22, C23, C33 for an ellipse shape and nu.

    Interpolated from ``symcat/reference_data/kalker_linear_coefficients.csv``
    (Kalker's table, nu = 0, 0.25, 0.5): monotone cubic (PCHIP) in
    ``ln(a/b)``, which passes through the nodes and never overshoots them,
    then quadratic (Lagrange) in nu through the three table columns.

    Parameters
    ----------
    a_over_b : float or array
        Semi-axis ratio, rolling over lateral, in the table range [0.1, 10].
    poisson_ratio : float
        In [0, 0.5]; default 0.3.
    clamp : bool
        Clamp ``a_over_b`` into the table range instead of raising
        (for very long ellipses at the flange).

    Returns
    -------
    KalkerCoefficients
    """
    interpolant, nodes = _kalker_table()
    ratio = np.asarray(a_over_b, dtype=float)
    lo, hi = nodes[0], nodes[-1]
    if clamp:
        ratio = np.clip(ratio, lo, hi)
    elif np.any(~((ratio >= lo * (1 - 1e-12)) & (ratio <= hi * (1 + 1e-12)))):
        raise ParameterError(
            f"a_over_b must lie in Kalker's table range [{lo}, {hi}] (or clamp=True), got {a_over_b}")
    weights = _poisson_weights(poisson_ratio)
    table = interpolant(np.clip(np.log(ratio), np.log(lo), np.log(hi)))
    table = table.reshape(ratio.shape + (4, 3))
    c = table @ weights
    return KalkerCoefficients(c[..., 0], c[..., 1], c[..., 2], c[..., 3])


def kalker_pieces(poisson_ratio=POISSON_RATIO_STEEL):
    """The piecewise cubic behind :func:`kalker_coefficients` at one Poisson ratio.

    For evaluating the coefficients elsewhere (in a CasADi graph): on piece ``i``,
    ``C(x) = sum_j coefficients[j, i] (x - breaks[i])**(3 - j)`` with ``x = ln(a/b)``
    in ``[breaks[0], breaks[-1]]`` (the table range; clamp outside).

    Parameters
    ----------
    poisson_ratio : float
        In [0, 0.5]; default 0.3.

    Returns
    -------
    breaks : ndarray (n + 1,)
        ``ln(a/b)`` at the table's nodes.
    coefficients : ndarray (4, n, 4)
        Polynomial coefficients (highest power first), piece, and C11, C22, C23, C33.
    """
    interpolant, _ = _kalker_table()
    weights = _poisson_weights(poisson_ratio)
    # the nu weights combine the 12 columns linearly, so they combine the polynomials too
    c = interpolant.c.reshape(interpolant.c.shape[:2] + (4, 3)) @ weights
    return np.array(interpolant.x), c


def _poisson_weights(poisson_ratio):
    """Lagrange weights of the table's three nu columns at ``poisson_ratio``."""
    nu = float(poisson_ratio)
    if not 0.0 <= nu <= 0.5:
        raise ParameterError(f"poisson_ratio must lie in [0, 0.5], got {poisson_ratio}")
    n0, n1, n2 = _TABLE_NU
    return np.array([
        (nu - n1) * (nu - n2) / ((n0 - n1) * (n0 - n2)),
        (nu - n0) * (nu - n2) / ((n1 - n0) * (n1 - n2)),
        (nu - n0) * (nu - n1) / ((n2 - n0) * (n2 - n1)),
    ])


# --------------------------------------------------------------------------
# Creep force laws
# --------------------------------------------------------------------------


def kalker_linear_forces(xi_x, xi_y, phi_per_m, a_m, b_m, coefficients, shear_modulus_Pa=SHEAR_MODULUS_STEEL_PA):
    """Kalker's linear theory (plain arithmetic: floats, arrays, CasADi symbols).

    Parameters
    ----------
    xi_x, xi_y : float or array
        Longitudinal and lateral creepage (-).
    phi_per_m : float or array
        Spin creepage (1/m).
    a_m, b_m : float or array
        Contact ellipse semi-axes along t1 and t2 (m).
    coefficients : KalkerCoefficients
        From :func:`kalker_coefficients` at ``a/b``.
    shear_modulus_Pa : float
        Shear modulus G (Pa); default steel 80.8 GPa.

    Returns
    -------
    CreepForces
    """
    c11, c22, c23, c33 = coefficients
    g = shear_modulus_Pa
    ab = a_m * b_m
    c = ab**0.5
    return CreepForces(
        -g * ab * c11 * xi_x,
        -g * ab * (c22 * xi_y + c * c23 * phi_per_m),
        g * ab * c * (c23 * xi_y - c * c33 * phi_per_m),
    )


def shen_hedrick_elkins_forces(linear, normal_force_N, friction_coefficient=FRICTION_COEFFICIENT):
    """Saturate linear creep forces by Shen, Hedrick and Elkins (1983).

    With ``F = |(Fx, Fy)|`` of the linear forces and ``u = F / (mu N)``, all
    three components are scaled by ``u' / u``, ``u' = u - u²/3 + u³/27`` for
    ``u < 3`` and 1 beyond, so that ``|(Fx, Fy)| <= mu N``.

    Parameters
    ----------
    linear : CreepForces
        From :func:`kalker_linear_forces`.
    normal_force_N : float or array
        Normal force (N), >= 0.
    friction_coefficient : float
        Coulomb friction coefficient; default 0.3.
    """
    bound = _friction_bound(normal_force_N, friction_coefficient)
    fx, fy, mz = (np.asarray(f, dtype=float) for f in linear)
    u = np.hypot(fx, fy) / np.where(bound > 0, bound, 1.0)
    u_sat = np.where(u < 3.0, u - u**2 / 3.0 + u**3 / 27.0, 1.0)
    scale = np.where((u > 0) & (bound > 0), u_sat / np.where(u > 0, u, 1.0), 0.0)
    return CreepForces(fx * scale, fy * scale, mz * scale)


def polach_forces(xi_x, xi_y, phi_per_m, normal_force_N, a_m, b_m, coefficients,
                  shear_modulus_Pa=SHEAR_MODULUS_STEEL_PA, friction_coefficient=FRICTION_COEFFICIENT,
                  k_adhesion=1.0, k_slip=1.0):
    """Polach's creep forces with spin (Polach 1999, 2005), elementwise on arrays.

    The force ``F = (2 mu N / pi) (kA e / (1 + (kA e)²) + atan(kS e))``,
    ``e = G pi a b c_jj s_C / (4 mu N)``, ``c_jj = |(C11 xi_x, C22 xi_y)| / s``,
    ``s = |(xi_x, xi_y)|``, acts against ``(xi_x, xi_y)``. For a single
    creepage without spin this is exactly FASTSIM with Hertz's (elliptic)
    pressure; for combined creepages the force stays parallel to the
    creepage, so at small creepage it differs from Kalker's linear theory by
    the C11/C22 anisotropy.

    Spin enters twice (Polach 1999): the lateral creepage becomes
    ``xi_yC = xi_y + phi a`` where that exceeds ``|xi_y|`` (spin and lateral
    creepage pushing the same way), giving the resultant
    ``s_C = |(xi_x, xi_yC)|`` above, and a spin force
    ``F_yS = (9/16) a mu N K_M k phi / s_C``, ``k = 1 + 6.3 (1 - exp(-a/b))``,
    ``K_M = |e_M| (d³/3 - d²/2 + 1/6) - sqrt((1 - d²)³) / 3``,
    ``d = (e_M² - 1) / (e_M² + 1)``,
    ``e_M = 8 G b sqrt(ab) C23 |xi_yC| / (3 mu N k)``; at small spin it is
    Kalker's linear spin force when ``xi_x = 0`` (reduced by ``|xi_yC|/s_C``
    otherwise). The sign of ``phi`` is the module's, for which the linear
    spin force has the sign of the lateral creep force; published
    transcriptions differ here, and this sign is the one that keeps
    ``|F| <= mu N`` (the other gives up to 2.4 mu N).

    ``k_adhesion = k_slip = 1`` is the 1999 method; smaller values
    (``kS <= kA <= 1``) are Polach's 2005 reduction for traction at the
    adhesion limit. Polach's method has no spin moment: ``mz_Nm`` is 0.

    Parameters
    ----------
    xi_x, xi_y, phi_per_m : float or array
        Creepages (-, -, 1/m), module conventions.
    normal_force_N : float or array
        Normal force (N), >= 0 (0 gives zero forces).
    a_m, b_m : float or array
        Semi-axes along t1 and t2 (m).
    coefficients : KalkerCoefficients
        C11, C22, C23 at ``a/b`` (C33 unused).
    shear_modulus_Pa : float
        G (Pa).
    friction_coefficient : float or array
        mu (may come from :func:`polach_friction_coefficient`); default 0.3.
    k_adhesion, k_slip : float
        Polach's reduction factors kA, kS in (0, 1].

    Returns
    -------
    CreepForces
    """
    xi_x, xi_y, phi = (np.asarray(v, dtype=float) for v in (xi_x, xi_y, phi_per_m))
    a = np.asarray(a_m, dtype=float)
    b = np.asarray(b_m, dtype=float)
    bound = _friction_bound(normal_force_N, friction_coefficient)
    _check_axes(a, b)
    for name, k in (("k_adhesion", k_adhesion), ("k_slip", k_slip)):
        if not 0.0 < k <= 1.0:
            raise ParameterError(f"{name} must lie in (0, 1], got {k}")
    c11, c22, c23, _ = coefficients
    g = shear_modulus_Pa
    live = (bound > 0) & (a > 0) & (b > 0)
    bound_safe = np.where(live, bound, 1.0)
    b_safe = np.where(live, b, 1.0)

    # lateral rigid slip at x = a; larger than xi_y when spin and lateral creep push alike
    xi_y_edge = xi_y + phi * a
    xi_y_c = np.where(np.abs(xi_y_edge) > np.abs(xi_y), xi_y_edge, xi_y)
    s = np.hypot(xi_x, xi_y)
    s_c = np.hypot(xi_x, xi_y_c)
    s_safe = np.where(s > 0, s, 1.0)
    s_c_safe = np.where(s_c > 0, s_c, 1.0)
    c_jj = np.where(s > 0, np.hypot(c11 * xi_x / s_safe, c22 * xi_y / s_safe), c11)

    eps = g * np.pi * a * b * c_jj * s_c / (4.0 * bound_safe)
    ka_eps = k_adhesion * eps
    force = 2.0 * bound / np.pi * (ka_eps / (1.0 + ka_eps**2) + np.arctan(k_slip * eps))

    k_spin = 1.0 + 6.3 * (1.0 - np.exp(-a / b_safe))
    eps_m = 8.0 / 3.0 * g * b * np.sqrt(a * b) * c23 * np.abs(xi_y_c) / (bound_safe * k_spin)
    delta = (eps_m**2 - 1.0) / (eps_m**2 + 1.0)
    k_m = eps_m * (delta**3 / 3.0 - delta**2 / 2.0 + 1.0 / 6.0) - np.sqrt((1.0 - delta**2) ** 3) / 3.0
    f_spin = 9.0 / 16.0 * a * bound * k_m * k_spin * phi / s_c_safe

    fx = np.where(live & (s_c > 0), -force * xi_x / s_c_safe, 0.0)
    fy = np.where(live & (s_c > 0), -force * xi_y / s_c_safe + f_spin, 0.0)
    return CreepForces(fx, fy, np.zeros_like(fx))


def polach_friction_coefficient(slip_velocity_mps, static_friction, ratio_A, decay_B_s_per_m):
    """Friction falling with the slip velocity (Polach 2005): ``mu0 ((1-A) exp(-B w) + A)``.

    Parameters
    ----------
    slip_velocity_mps : float or array
        Magnitude of the slip velocity w = V s_C (m/s).
    static_friction : float
        Friction coefficient at zero slip velocity mu0.
    ratio_A : float
        Ratio of the friction at infinite slip velocity to mu0, in (0, 1].
    decay_B_s_per_m : float
        Exponential decay rate B (s/m), >= 0.
    """
    if not 0.0 < ratio_A <= 1.0:
        raise ParameterError(f"ratio_A must lie in (0, 1], got {ratio_A}")
    if not decay_B_s_per_m >= 0.0:
        raise ParameterError(f"decay_B_s_per_m must be >= 0 s/m, got {decay_B_s_per_m}")
    if not static_friction > 0.0:
        raise ParameterError(f"static_friction must be > 0, got {static_friction}")
    w = np.abs(np.asarray(slip_velocity_mps, dtype=float))
    return static_friction * ((1.0 - ratio_A) * np.exp(-decay_B_s_per_m * w) + ratio_A)


def creep_forces(creepages, contact, law="polach", friction_coefficient=FRICTION_COEFFICIENT,
                 poisson_ratio=POISSON_RATIO_STEEL, shear_modulus_Pa=SHEAR_MODULUS_STEEL_PA, **options):
    """Creep forces of one law from creepages and a Hertz contact.

    Parameters
    ----------
    creepages : Creepages
        Creepages at the contact(s).
    contact : symcat.wheelrail.hertz.HertzContact
        The contact ellipse (its ``a/b`` selects Kalker's coefficients,
        clamped into the table range).
    law : {"linear", "shen_hedrick_elkins", "polach", "fastsim"}
        The creep force law.
    friction_coefficient : float
        mu (unused by "linear"); default 0.3.
    poisson_ratio, shear_modulus_Pa : float
        Material of wheel and rail.
    **options
        Passed to the law (``n_strips``, ``pressure``, ``k_adhesion`` ...).

    Returns
    -------
    CreepForces
    """
    a, b, n_force = contact.semi_axis_a_m, contact.semi_axis_b_m, contact.normal_force_N
    coeff = kalker_coefficients(a / b, poisson_ratio, clamp=True)
    xi_x, xi_y, phi = creepages
    if law == "linear":
        return kalker_linear_forces(xi_x, xi_y, phi, a, b, coeff, shear_modulus_Pa)
    if law == "shen_hedrick_elkins":
        linear = kalker_linear_forces(xi_x, xi_y, phi, a, b, coeff, shear_modulus_Pa)
        return shen_hedrick_elkins_forces(linear, n_force, friction_coefficient)
    if law == "polach":
        return polach_forces(xi_x, xi_y, phi, n_force, a, b, coeff, shear_modulus_Pa, friction_coefficient, **options)
    if law == "fastsim":
        return fastsim_forces(xi_x, xi_y, phi, n_force, a, b, coeff, shear_modulus_Pa, friction_coefficient, **options)
    raise ParameterError(f"law must be one of 'linear', 'shen_hedrick_elkins', 'polach', 'fastsim', got {law!r}")


def _friction_bound(normal_force_N, friction_coefficient):
    n_force = np.asarray(normal_force_N, dtype=float)
    mu = np.asarray(friction_coefficient, dtype=float)
    if np.any(~(n_force >= 0)):
        raise ParameterError(f"normal_force_N must be >= 0 N, got {normal_force_N}")
    if np.any(~(mu > 0)):
        raise ParameterError(f"friction_coefficient must be > 0, got {friction_coefficient}")
    return mu * n_force


def _check_axes(a, b):
    if np.any(~(a >= 0)) or np.any(~(b >= 0)):
        raise ParameterError(f"semi-axes a_m, b_m must be >= 0 m, got a={a}, b={b}")


def _check_frame(t1, t2, n):
    t1, t2, n = (np.asarray(v, dtype=float) for v in (t1, t2, n))
    for name, v in (("t1", t1), ("t2", t2), ("n", n)):
        if v.shape[-1:] != (3,):
            raise ParameterError(f"{name} must be a 3-vector (last axis 3), got shape {v.shape}")
        if np.any(np.abs(np.linalg.norm(v, axis=-1) - 1.0) > 1e-6):
            raise ParameterError(f"{name} must be a unit vector, got norm {np.linalg.norm(v, axis=-1)}")
    if np.any(np.linalg.norm(np.cross(t1, t2) - n, axis=-1) > 1e-6):
        raise ParameterError("contact frame (t1, t2, n) must be orthonormal and right-handed (n = t1 x t2)")
    return t1, t2, n


from .creepage import contact_creepages, creepages_from_slip, wheelset_creepages  # noqa: E402  (re-exported)
from .fastsim import fastsim_forces  # noqa: E402  (re-exported; creep_forces dispatches to it)
