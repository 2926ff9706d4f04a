"""Hertz contact ellipse and Kalker's coefficients inside a CasADi graph (SX, differentiable).

The creep forces of a wheel/rail contact (:func:`symcat.assembly.wheelrail.creep_function`)
follow the contact point: its profile curvatures give the relative curvatures ``A, B``
(:func:`relative_curvatures_sx`, as :func:`symcat.wheelrail.hertz.relative_curvatures`), Hertz's
theory the semi-axes ``a, b`` (:func:`hertz_semi_axes_sx`, as
:func:`symcat.wheelrail.hertz.hertz_contact`) and the table the coefficients
(:func:`kalker_coefficients_sx`, as ``kalker_coefficients(a / b, clamp=True)``).

Everything is straight-line arithmetic with a fixed number of iterations, so the graph is
cheap, differentiable and compiles to C:

* the complete elliptic integrals come from the arithmetic-geometric mean: with ``k`` the
  minor/major axis ratio and ``m = 1 - k²``, six AGM steps give ``K(m)`` and
  ``sigma = (K - E) / (m K)`` to round-off for ``k >= 1e-9`` (Carlson's ``R_D(0, k², 1) / 3 =
  K sigma``); ``sigma`` is summed from ``c_n² / m`` (``c_1² / m = (1 - k) / (4 (1 + k))``,
  ``c_{n+1} = c_n² / (4 a_{n+1})``), which stays exact at ``k -> 1`` where ``K - E`` and ``m``
  both vanish;
* Hertz's shape equation ``B_s / A_s = (1 - sigma) / (k² sigma)`` (= ``R_D(0, 1, k²) /
  R_D(0, k², 1)``) is solved for ``t = ln k`` by one Newton step from a polynomial guess
  (within 1e-4 of ``t``, fitted to the numeric solver), and ``ln(K sigma)`` at the solution is
  extrapolated linearly from the guess: one AGM (with its derivative) in all, 1e-8 relative or
  better on ``a, b`` over the range ``1e-12 <= B / A <= 1e12`` that
  :func:`~symcat.wheelrail.hertz.hertz_contact` accepts;
* Kalker's coefficients are the table's monotone cubic in ``ln(a/b)`` written with truncated
  powers (no piece look-up).

About 300 operations for the ellipse and 500 for the coefficients (the creep function grows from
about 440 to 1250 operations).
"""
from __future__ import annotations

import math
from functools import lru_cache

import casadi as ca
import numpy as np

from ..wheelrail.creep import kalker_pieces
from ..wheelrail.hertz import POISSON_RATIO_STEEL, _axis_ratio, contact_modulus

#: AGM steps: K and sigma to round-off for k >= 1e-9 (B/A up to 1e16).
AGM_STEPS = 6
#: Degree of the polynomial first guess of the axis ratio (one Newton step polishes it).
GUESS_DEGREE = 8
#: Floors that keep a Hertz ellipse where the profiles are (nearly) conformal or the contact
#: angle nears 90 degrees: B >= 1e-3 A (A/B <= 1000) and cos(angle) >= 1e-3.
MIN_CURVATURE_RATIO = 1e-3
MIN_COS_ANGLE = 1e-3

__all__ = [
    "elliptic_integrals_sx",
    "hertz_shape_sx",
    "hertz_semi_axes_sx",
    "kalker_coefficients_sx",
    "plane_curvature_sx",
    "relative_curvatures_sx",
]


def plane_curvature_sx(dy, dz, ddy, ddz):
    """Signed curvature (1/m) of a plane curve ``(y(s), z(s))`` from its derivatives, with the
    sign of :meth:`symcat.wheelrail.profiles.Profile.curvature` (positive for hollows)."""
    return (dy * ddz - dz * ddy) / (dy**2 + dz**2) ** 1.5


def relative_curvatures_sx(rolling_radius_m, cos_angle, wheel_curvature_per_m, rail_curvature_per_m):
    """``(A, B)`` (1/m) as :func:`symcat.wheelrail.hertz.relative_curvatures`, in SX.

    Curvatures convex positive (the negative of ``Profile.curvature``). ``cos_angle`` is the
    cosine of the angle between the wheel's profile normal and its radius (Meusnier). ``cos_angle``
    and ``B`` are floored (:data:`MIN_COS_ANGLE`, :data:`MIN_CURVATURE_RATIO`) where the numeric
    function refuses the geometry, so the graph keeps a finite ellipse there.
    """
    A = 0.5 * ca.fmax(cos_angle, MIN_COS_ANGLE) / rolling_radius_m
    B = 0.5 * (wheel_curvature_per_m + rail_curvature_per_m)
    return A, ca.fmax(B, MIN_CURVATURE_RATIO * A)


def elliptic_integrals_sx(k, steps: int = AGM_STEPS):
    """``K(m)`` and ``sigma = (K - E) / (m K)`` for ``m = 1 - k²``, ``0 < k <= 1``, by the AGM.

    ``sigma`` is 1/2 at ``k = 1`` and tends to 1 as ``k -> 0``; ``(K - E) / m = K sigma``.
    """
    m = (1 - k) * (1 + k)
    a, b = 1.0, k
    c2m = (1 - k) / (4 * (1 + k))  # c_1^2 / m
    sigma = 0.5 + c2m
    weight = 1.0
    for _ in range(steps):
        a, b = 0.5 * (a + b), ca.sqrt(a * b)
        c2m = c2m**2 * m / (4 * (a + b) ** 2)  # c_{n+1}^2 / m, c_{n+1} = c_n^2 / (4 a_{n+1}), a_{n+1} = (a + b) / 2
        weight *= 2.0
        sigma = sigma + weight * c2m
    return math.pi / (a + b), sigma


@lru_cache(maxsize=1)
def _shape_terms() -> ca.Function:
    """``t = ln k -> (f, df/dt, h, dh/dt)``, ``f = ln(B_s / A_s) + 2 t`` (Hertz's shape equation)
    and ``h = ln(K sigma)`` (the size of the major axis)."""
    t = ca.SX.sym("t")
    K, sigma = elliptic_integrals_sx(ca.exp(t))
    f, h = ca.log((1 - sigma) / sigma), ca.log(K * sigma)
    d = ca.jacobian(ca.vertcat(f, h), t)
    return ca.Function("hertz_shape", [t], [f, d[0], h, d[1]])


@lru_cache(maxsize=1)
def _guess_coefficients() -> np.ndarray:
    """Least-squares polynomial (degree 8) in ``w = L / (L + 8)`` of ``ln k + L / 2``,
    ``L = ln(B_s / A_s)`` in ``[0, ln 1e12]``, fitted to the numeric solution of
    :mod:`symcat.wheelrail.hertz`: within 1e-4 of ``ln k``."""
    L = np.linspace(0.0, math.log(1e12), 2001)
    t = np.log(_axis_ratio(np.exp(L)))
    return np.polynomial.polynomial.polyfit(L / (L + 8.0), t + 0.5 * L, GUESS_DEGREE)


def _guess(log_ratio):
    """``ln k`` within 1e-4 (:func:`_guess_coefficients`), by Horner."""
    w = log_ratio / (log_ratio + 8.0)
    y = 0.0
    for c in _guess_coefficients()[::-1]:
        y = y * w + float(c)
    return y - 0.5 * log_ratio


def hertz_shape_sx(log_ratio):
    """``k = minor / major`` and ``ln(K sigma)`` of a Hertz ellipse for ``log_ratio = ln(B_s /
    A_s) >= 0``: one Newton step on the shape equation from :func:`_guess` (its error squared,
    1e-8 at most), ``ln(K sigma)`` carried along to first order (the same error)."""
    t0 = _guess(log_ratio)
    f, df, h, dh = _shape_terms()(t0)
    step = -(f - 2 * t0 - log_ratio) / (df - 2)
    t = ca.fmin(t0 + step, 0.0)  # k <= 1, like the numeric solver
    return ca.exp(t), h + dh * (t - t0)


def hertz_semi_axes_sx(normal_force_N, A_per_m, B_per_m, contact_modulus_Pa=None):
    """Semi-axes ``(a, b)`` (m) of :func:`symcat.wheelrail.hertz.hertz_contact`, in SX.

    Parameters
    ----------
    normal_force_N : SX or float
        Normal force (N), > 0.
    A_per_m, B_per_m : SX or float
        Relative curvatures along the rolling and the lateral direction (1/m), > 0.
    contact_modulus_Pa : float, optional
        ``E*`` (Pa); default steel (:func:`symcat.wheelrail.hertz.contact_modulus`).
    """
    e_star = contact_modulus() if contact_modulus_Pa is None else contact_modulus_Pa
    small, large = ca.fmin(A_per_m, B_per_m), ca.fmax(A_per_m, B_per_m)
    k, log_k_sigma = hertz_shape_sx(ca.log(large / small))
    # major^3 = 3 N D / (2 pi A_s E*), D = R_D(0, k^2, 1) / 3 = K sigma
    major = (3 * normal_force_N * ca.exp(log_k_sigma) / (2 * math.pi * small * e_star)) ** (1.0 / 3.0)
    minor = k * major
    along = A_per_m <= B_per_m  # the major axis lies along the smaller curvature
    return ca.if_else(along, major, minor), ca.if_else(along, minor, major)


def kalker_coefficients_sx(a_over_b, poisson_ratio=POISSON_RATIO_STEEL, factor=1.0):
    """``factor * kalker_coefficients(a_over_b, poisson_ratio, clamp=True)`` in SX.

    The same piecewise cubic in ``x = ln(a/b)`` (:func:`symcat.wheelrail.creep.kalker_pieces`),
    written with truncated powers: the first piece's cubic plus, at each interior node ``x_i``,
    ``alpha_i u² + beta_i u³``, ``u = max(x - x_i, 0)`` (the interpolant is C1, so the pieces
    differ by these terms only). No piece look-up: about 20 operations per node, and values
    agree with the numeric interpolant to round-off.

    Returns
    -------
    tuple of SX
        ``(C11, C22, C23, C33)``.
    """
    breaks, first, jumps = _kalker_truncated_powers(float(poisson_ratio), float(factor))
    x = ca.fmin(ca.fmax(ca.log(a_over_b), breaks[0]), breaks[-1])
    d = x - breaks[0]
    values = [((first[0, n] * d + first[1, n]) * d + first[2, n]) * d + first[3, n] for n in range(4)]
    for x_i, (alpha, beta) in zip(breaks[1:-1], jumps):
        u = ca.fmax(x - x_i, 0.0)
        u2 = u * u
        values = [v + u2 * (alpha[n] + beta[n] * u) for n, v in enumerate(values)]
    return tuple(values)


@lru_cache(maxsize=8)
def _kalker_truncated_powers(poisson_ratio, factor):
    """Nodes, the first piece's coefficients (4, 4) and ``(alpha_i, beta_i)`` of every interior
    node (each 4 coefficients) of the table's interpolant times ``factor``
    (:func:`kalker_coefficients_sx`)."""
    breaks, c = kalker_pieces(poisson_ratio)
    c = factor * c
    jumps = []
    for i in range(1, len(breaks) - 1):
        h = breaks[i] - breaks[i - 1]
        # the previous piece about x_i: d^3 and d^2 coefficients
        prev3, prev2 = c[0, i - 1], 3 * c[0, i - 1] * h + c[1, i - 1]
        jumps.append((c[1, i] - prev2, c[0, i] - prev3))
    return breaks, c[:, 0], jumps
