"""FASTSIM: Kalker's simplified theory of rolling contact on a strip grid (conventions of
:mod:`symcat.wheelrail.creep`). The reference saturating law: slower than Polach's closed form
but with spin and the elliptic or parabolic traction bound on every strip."""
from __future__ import annotations

import numpy as np

from symcat.errors import ParameterError

from .creep import (FRICTION_COEFFICIENT, SHEAR_MODULUS_STEEL_PA, CreepForces, _check_axes, _friction_bound)

__all__ = ["fastsim_forces"]


def fastsim_forces(xi_x, xi_y, phi_per_m, normal_force_N, a_m, b_m, coefficients,
                   shear_modulus_Pa=SHEAR_MODULUS_STEEL_PA, friction_coefficient=FRICTION_COEFFICIENT,
                   n_strips=40, n_points=40, pressure="parabolic"):
    """Kalker's simplified theory (FASTSIM) on a grid of strips.

    The ellipse is cut into ``n_strips`` strips of equal width across ``y``;
    along each, ``n_points`` equal steps march from the leading edge
    ``x = a(y)`` (zero traction) to the trailing edge. The traction follows
    ``dp/dx = (xi_x/L1 - phi y/L3, xi_y/L2 + phi x/L3)`` and is scaled back to
    the traction bound ``mu p(x, y)`` wherever it would exceed it. The
    flexibilities ``L1 = 8a/(3 G C11)``, ``L2 = 8a/(3 G C22)``,
    ``L3 = pi a sqrt(a/b) / (4 G C23)``, kept apart, reproduce Kalker's
    linear Fx and Fy at small creepage for any combination of creepages (Mz
    only roughly: 0.76 and 0.83 of Kalker's C23 and C33 terms at a/b = 1.5).
    The price: in full slip the force leans from the slip direction towards
    ``(C11 xi_x, C22 xi_y)`` (a few degrees; Polach's method does not). The
    traction lives at the element centres; forces sum it by the midpoint
    rule in x and y.

    Parameters
    ----------
    xi_x, xi_y, phi_per_m : float or array (m,)
        Creepages (-, -, 1/m), module conventions.
    normal_force_N : float or array
        Normal force (N), >= 0.
    a_m, b_m : float or array
        Semi-axes along t1 and t2 (m).
    coefficients : KalkerCoefficients
        C11, C22, C23 at ``a/b``.
    shear_modulus_Pa : float
        G (Pa).
    friction_coefficient : float or array
        mu; default 0.3.
    n_strips, n_points : int
        Grid across (y) and along (x) the ellipse. Without spin the force
        error falls as 1/n² (0.6, 0.1, 0.02 % of mu N at n = 10, 20, 40);
        with spin only as 1/n (5.6, 3.0, 1.5 %), the strips saturating at
        once or not at all.
    pressure : {"parabolic", "elliptic"}
        Normal pressure for the traction bound: FASTSIM's parabolic
        ``(2N/(pi a b)) (1 - x²/a² - y²/b²)`` or Hertz's elliptic one.

    Returns
    -------
    CreepForces
        Arrays of the broadcast shape of the inputs.
    """
    if pressure not in ("parabolic", "elliptic"):
        raise ParameterError(f"pressure must be 'parabolic' or 'elliptic', got {pressure!r}")
    for name, count in (("n_strips", n_strips), ("n_points", n_points)):
        if int(count) != count or count < 1:
            raise ParameterError(f"{name} must be an integer >= 1, got {count}")
    bound_total = _friction_bound(normal_force_N, friction_coefficient)
    a = np.asarray(a_m, dtype=float)
    b = np.asarray(b_m, dtype=float)
    _check_axes(a, b)
    c11, c22, c23, _ = (np.asarray(c, dtype=float) for c in coefficients)
    arrays = np.broadcast_arrays(np.asarray(xi_x, float), np.asarray(xi_y, float), np.asarray(phi_per_m, float),
                                 bound_total, a, b, c11, c22, c23)
    shape = arrays[0].shape
    xi, eta, phi, mu_n, a, b, c11, c22, c23 = (v.reshape(-1, 1) for v in arrays)
    live = (mu_n > 0) & (a > 0) & (b > 0)
    a = np.where(live, a, 1.0)
    b = np.where(live, b, 1.0)
    g = shear_modulus_Pa
    l1 = 8.0 * a / (3.0 * g * c11)
    l2 = 8.0 * a / (3.0 * g * c22)
    l3 = np.pi * a * np.sqrt(a / b) / (4.0 * g * c23)
    inv_l1, inv_l2, inv_l3 = 1.0 / l1, 1.0 / l2, 1.0 / l3

    dy = 2.0 * b / n_strips
    y = b * (-1.0 + (2.0 * np.arange(n_strips) + 1.0) / n_strips)
    half = a * np.sqrt(1.0 - (y / b) ** 2)
    dx = 2.0 * half / n_points
    # element centres x[..., i] = half - (i + 1/2) dx: the trailing edge, where
    # the bound vanishes, is never a node, so the linear limit is exact
    x = half[..., None] - (np.arange(n_points) + 0.5) * dx[..., None]
    shape_xy = 1.0 - (x / a[..., None]) ** 2 - (y[..., None] / b[..., None]) ** 2
    if pressure == "elliptic":
        shape_xy = np.sqrt(shape_xy)
    # the grid's pressure sums to N exactly, so full slip gives mu N, never more
    area_integral = (shape_xy.sum(axis=2) * dx).sum(axis=1, keepdims=True) * dy
    bound = shape_xy * (mu_n / area_integral)[..., None]
    rate_x = xi * inv_l1 - phi * y * inv_l3

    px = np.zeros_like(half)
    py = np.zeros_like(half)
    x_prev = half
    fx = np.zeros_like(half)
    fy = np.zeros_like(half)
    mz = np.zeros_like(half)
    for i in range(n_points):
        x_i = x[..., i]
        step = x_prev - x_i
        px = px - rate_x * step
        py = py - (eta * inv_l2 + phi * 0.5 * (x_prev + x_i) * inv_l3) * step
        limit = bound[..., i]
        size = np.hypot(px, py)
        scale = np.where(size > limit, limit / np.where(size > 0, size, 1.0), 1.0)
        px = px * scale
        py = py * scale
        fx += px
        fy += py
        mz += x_i * py - y * px
        x_prev = x_i
    out = [np.where(live[:, 0], (f * dx * dy).sum(axis=1), 0.0).reshape(shape) for f in (fx, fy, mz)]
    return CreepForces(*out)
