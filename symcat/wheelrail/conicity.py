"""Equivalent conicity from the rolling-radius-difference function (EN 15302).

Two evaluations of ``tan(gamma_e)`` at a wheelset amplitude ``y_hat``, both from ``delta_r(y)``
(piecewise linear between the given shifts; EN 15302 asks for steps of at most 0.1 mm):

* ``"integration"`` (EN 15302, Annex B: the Klingel wavelength of the nonlinear kinematic
  motion). The kinematic wheelset obeys ``y'' = -delta_r(y) / (2 b r0)`` (``x`` the distance
  travelled, ``b`` half the contact distance), whose first integral gives the half wavelength
  between the turning points ``y-`` and ``y+`` (``F(y+) = F(y-)``, ``y+ - y- = 2 y_hat``,
  ``F(y) = int_y0^y delta_r``, ``y0`` the zero of ``delta_r``). Comparing the wavelength with
  Klingel's ``2 pi sqrt(b r0 / gamma)`` gives ``gamma_e = pi^2 / I^2`` with
  ``I = int dy / sqrt(F(y+) - F(y))`` over ``[y-, y+]``, independent of ``b r0``. The integral is
  taken with ``y = c + y_hat sin(theta)``, which removes the end singularities, by Gauss-Legendre
  quadrature. This is the method behind the standard's reference results.
* ``"regression"`` (harmonic linearisation, the idea of EN 15302's linear-regression method):
  the least-squares slope of ``delta_r`` against ``2 y`` over one harmonic period
  ``y = y0 + y_hat sin(theta)`` sampled at equal time steps, i.e. the describing function
  ``gamma_e = (1 / (2 pi y_hat)) int_0^2pi delta_r(y0 + y_hat sin(theta)) sin(theta) dtheta``.

Both give ``gamma`` exactly for a coned wheelset (``delta_r = 2 gamma y``).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.optimize import brentq

from symcat.errors import ParameterError

METHODS = ("integration", "regression")


def equivalent_conicity(shift_m, delta_r_m, amplitudes_m, method: str = "integration", n_quad: int = 256) -> np.ndarray:
    """Equivalent conicity ``tan(gamma_e)`` [-] at each amplitude.

    Parameters
    ----------
    shift_m : array_like
        Lateral shifts, strictly increasing [m].
    delta_r_m : array_like
        Rolling radius difference ``r_left - r_right`` at the shifts [m] (increasing through
        zero for a stable wheelset).
    amplitudes_m : array_like
        Amplitudes ``y_hat`` (half the peak-to-peak lateral motion) [m].
    method : str
        ``"integration"`` (EN 15302 Annex B) or ``"regression"`` (harmonic linearisation).
    n_quad : int
        Quadrature nodes.

    Returns
    -------
    ndarray
        ``tan(gamma_e)`` per amplitude; NaN where the motion would leave the shift range.
    """
    y = np.asarray(shift_m, float)
    dr = np.asarray(delta_r_m, float)
    amps = np.atleast_1d(np.asarray(amplitudes_m, float))
    if method not in METHODS:
        raise ParameterError(f"method={method!r}: must be one of {', '.join(METHODS)}")
    if y.ndim != 1 or y.shape != dr.shape or len(y) < 3 or not np.all(np.diff(y) > 0):
        raise ParameterError("shift_m: must be at least 3 strictly increasing shifts, one delta_r_m value each")
    if not (np.all(np.isfinite(dr)) and np.all(np.isfinite(amps)) and np.all(amps > 0)):
        raise ParameterError("delta_r_m and amplitudes_m: must be finite; amplitudes > 0")
    y0 = _zero(y, dr)
    if method == "regression":
        theta = 2 * np.pi * (np.arange(n_quad) + 0.5) / n_quad
        out = []
        for a in amps:
            yy = y0 + a * np.sin(theta)
            if yy.min() < y[0] or yy.max() > y[-1]:
                out.append(np.nan)
                continue
            d = np.interp(yy, y, dr)
            out.append(np.sum(d * np.sin(theta)) / (2 * a * np.sum(np.sin(theta) ** 2)))
        return np.array(out)
    # Integration: F(y) piecewise quadratic, exact for piecewise linear delta_r.
    cum = np.r_[0.0, np.cumsum(0.5 * (dr[1:] + dr[:-1]) * np.diff(y))]

    def F(q):
        q = np.asarray(q, float)
        i = np.clip(np.searchsorted(y, q) - 1, 0, len(y) - 2)
        h = q - y[i]
        slope = (dr[i + 1] - dr[i]) / (y[i + 1] - y[i])
        return cum[i] + dr[i] * h + 0.5 * slope * h * h

    F0 = F(y0)
    xg, wg = _gauss(n_quad)
    theta = 0.5 * np.pi * xg
    out = []
    for a in amps:
        g = lambda up: F(up) - F(up - 2 * a)  # noqa: E731 - zero where both turning points share the energy
        lo, hi = max(y0, y[0] + 2 * a), min(y0 + 2 * a, y[-1])
        if not (lo <= hi and g(lo) <= 0 <= g(hi)):
            out.append(np.nan)
            continue
        up = brentq(g, lo, hi, xtol=1e-14) if g(lo) < 0 < g(hi) else (lo if g(lo) == 0 else hi)
        c = up - a
        e = F(up) - F0
        rest = F(up) - F(c + a * np.sin(theta))
        with np.errstate(divide="ignore", invalid="ignore"):
            integrand = a * np.cos(theta) / np.sqrt(np.maximum(rest, 0.0))
        if not np.all(np.isfinite(integrand)) or e <= 0:
            out.append(np.nan)
            continue
        integral = 0.5 * np.pi * np.sum(wg * integrand)
        out.append(np.pi**2 / integral**2)
    return np.array(out)


@lru_cache(maxsize=4)
def _gauss(n: int):
    return np.polynomial.legendre.leggauss(n)


def _zero(y, dr) -> float:
    """The zero of delta_r nearest to the centre (the wheelset's mean position)."""
    sign = np.sign(dr)
    exact = np.flatnonzero(dr == 0)
    cross = np.flatnonzero(sign[:-1] * sign[1:] < 0)
    cands = list(y[exact]) + [y[i] - dr[i] * (y[i + 1] - y[i]) / (dr[i + 1] - dr[i]) for i in cross]
    if not cands:
        raise ParameterError("delta_r_m: never changes sign over the shifts; there is no centred running position")
    return float(min(cands, key=abs))
