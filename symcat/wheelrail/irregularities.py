"""Track irregularities: measured data as C2 splines against ``s``, and synthetic ones from a PSD.

How they move the rails is described in :mod:`symcat.wheelrail.track` (translations in the
canted track frame: alignment and level move both rails, gauge spreads them, cross level lifts
the left and lowers the right).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicSpline

from symcat.errors import ParameterError


def _positive(name, value):
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ParameterError(f"{name}={value!r}: must be a finite number > 0")
    return float(value)


class Irregularities:
    """Measured track irregularities against ``s``, each a C2 cubic spline (not-a-knot).

    Parameters
    ----------
    s_m : array_like
        Strictly increasing positions along the track [m], at least 4.
    alignment_m, level_m, cross_level_m, gauge_m : array_like, optional
        Lateral (toward the left) and vertical (up) displacement of the track, height of the
        left rail over the right one, widening of the gauge [m]; omitted ones are zero.

    Notes
    -----
    Outside ``[s_m[0], s_m[-1]]`` every irregularity is zero; data that do not start and end
    at zero therefore step there (taper them).
    """

    NAMES = ("alignment_m", "level_m", "cross_level_m", "gauge_m")

    def __init__(self, s_m, alignment_m=None, level_m=None, cross_level_m=None, gauge_m=None):
        s = np.asarray(s_m, float)
        if s.ndim != 1 or s.size < 4 or not np.all(np.isfinite(s)) or np.any(np.diff(s) <= 0):
            raise ParameterError(f"s_m (irregularities): {s.size} values; must be at least 4 finite, "
                                 "strictly increasing positions [m]")
        data = []
        for name, v in zip(self.NAMES, (alignment_m, level_m, cross_level_m, gauge_m)):
            v = np.zeros_like(s) if v is None else np.asarray(v, float)
            if v.shape != s.shape or not np.all(np.isfinite(v)):
                raise ParameterError(f"{name} (irregularities): shape {v.shape}; must be finite numbers [m], "
                                     f"one per s_m value ({s.size})")
            data.append(v)
        self.s_range_m = (float(s[0]), float(s[-1]))
        self._spline = CubicSpline(s, np.stack(data, axis=1), axis=0)

    def evaluate(self, s_m, order: int = 0) -> np.ndarray:
        """Irregularities (columns in the order of :attr:`NAMES`) or their ``order``-th derivative
        at ``s_m`` [m]; shape ``(n, 4)``."""
        s = np.atleast_1d(np.asarray(s_m, float))
        out = self._spline(s, order)
        out[(s < self.s_range_m[0]) | (s > self.s_range_m[1])] = 0.0
        return out


def read_irregularities(path, start_m: float = 0.0) -> Irregularities:
    """Measured irregularities from a CSV file.

    The file has a header row naming its columns, comma-separated, and one row per position:
    ``s_m`` (required: distance along the track [m], at least 4 strictly increasing values) and
    any of ``alignment_m``, ``level_m``, ``cross_level_m``, ``gauge_m`` (as :class:`Irregularities`
    takes them [m]; omitted ones are zero). Lines starting with ``#`` are comments.

    Parameters
    ----------
    path : str or os.PathLike
    start_m : float
        Added to ``s_m`` (e.g. the chainage of the point the file's ``s_m = 0`` refers to) [m].

    Raises
    ------
    ParameterError
        For a missing or unreadable file, an unknown or missing column, a value that is not a
        number, or data :class:`Irregularities` refuses; the message names the file.
    """
    columns = _read_columns(path)
    unknown = sorted(set(columns) - {"s_m", *Irregularities.NAMES})
    if "s_m" not in columns or unknown:
        raise ParameterError(f"{path}: columns {', '.join(columns) or 'none'}; need s_m and any of "
                             f"{', '.join(Irregularities.NAMES)}" + (f" (unknown: {', '.join(unknown)})" if unknown else ""))
    try:
        return Irregularities(columns.pop("s_m") + float(start_m), **columns)
    except ParameterError as err:
        raise ParameterError(f"{path}: {err}") from None


def _read_columns(path) -> dict:
    """Header name -> values (float arrays) of a comma-separated file with a header row."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = [line.strip() for line in f if line.strip() and not line.lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError) as err:
        raise ParameterError(f"{path}: cannot be read ({err.strerror if isinstance(err, OSError) else err})") from None
    if not lines:
        raise ParameterError(f"{path}: empty; needs a header row (s_m, ...) and data rows")
    names = [n.strip() for n in lines[0].split(",")]
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        try:
            values = [float(c) for c in cells]
        except ValueError:
            raise ParameterError(f"{path}: data row {number} ({line!r}) has a value that is not a number") from None
        if len(values) != len(names):
            raise ParameterError(f"{path}: data row {number} has {len(values)} values for {len(names)} columns")
        rows.append(values)
    data = np.array(rows, float).reshape(len(rows), len(names))
    return {name: data[:, k] for k, name in enumerate(names)}


ERRI_B176 = {"low": 2.119e-7, "high": 4.032e-7, "omega_c": 0.8246, "omega_r": 0.0206}


def erri_b176_psd(wavenumber_rad_m, level: str = "low") -> np.ndarray:
    """ERRI B176 one-sided PSD of level or alignment,
    ``S = A omega_c^2 / ((W^2 + omega_r^2) (W^2 + omega_c^2))`` [m^2/(rad/m)], at wavenumbers
    ``W`` [rad/m]; ``level`` ``"low"`` or ``"high"`` (track quality for high-speed lines)."""
    if level not in ("low", "high"):
        raise ParameterError(f"level={level!r}: must be 'low' or 'high'")
    w2 = np.asarray(wavenumber_rad_m, float) ** 2
    wc, wr = ERRI_B176["omega_c"], ERRI_B176["omega_r"]
    return ERRI_B176[level] * wc**2 / ((w2 + wr**2) * (w2 + wc**2))


def synthetic_irregularities(length_m: float, *, level: str = "low", seed: int = 0,
                             wavelengths_m=(1.0, 120.0), spacing_m: float = 0.25, taper_m: float = 10.0,
                             n_waves: int = 2000, psd=None) -> Irregularities:
    """Alignment and level irregularities from a PSD as sums of cosines with random phases.

    ``x(s) = sum_k sqrt(2 S(W_k) dW) cos(W_k s + theta_k)`` over ``n_waves`` wavenumbers evenly
    spread between ``2 pi / wavelengths_m[1]`` and ``2 pi / wavelengths_m[0]``, so the variance is
    the PSD's integral over that band; alignment and level are independent draws. The ends are
    tapered to zero over ``taper_m`` (cosine ramp) so the track joins the ideal geometry.

    Parameters
    ----------
    length_m : float
        Length covered, from ``s = 0`` [m].
    level : str
        ERRI B176 level (``"low"``/``"high"``) when ``psd`` is not given.
    seed : int
        Seed of the random phases (``numpy.random.default_rng``).
    wavelengths_m : (float, float)
        Shortest and longest wavelength [m].
    spacing_m : float
        Sample spacing of the returned data [m].
    taper_m : float
        Length of the end ramps [m].
    n_waves : int
        Number of cosines.
    psd : callable, optional
        One-sided PSD ``S(W)`` [m^2/(rad/m)] of wavenumber ``W`` [rad/m] for both directions.
    """
    length_m = _positive("length_m", length_m)
    spacing_m = _positive("spacing_m", spacing_m)
    lo, hi = (float(w) for w in wavelengths_m)
    if not (0 < lo < hi):
        raise ParameterError(f"wavelengths_m={wavelengths_m!r}: must be (shortest, longest) with 0 < shortest "
                             "< longest [m]")
    if not (0 <= taper_m <= 0.5 * length_m):
        raise ParameterError(f"taper_m={taper_m!r}: must lie in [0, length_m / 2 = {0.5 * length_m:g}] m")
    if not (isinstance(n_waves, int) and n_waves >= 1):
        raise ParameterError(f"n_waves={n_waves!r}: must be an integer >= 1")
    psd = psd or (lambda w: erri_b176_psd(w, level))
    rng = np.random.default_rng(seed)
    edges = np.linspace(2 * np.pi / hi, 2 * np.pi / lo, n_waves + 1)
    w = 0.5 * (edges[1:] + edges[:-1])
    amp = np.sqrt(2.0 * psd(w) * np.diff(edges))
    s = np.linspace(0.0, length_m, int(math.ceil(length_m / spacing_m)) + 1)
    ramp = np.ones_like(s)
    if taper_m > 0:
        ramp = np.minimum(1.0, np.minimum(s, length_m - s) / taper_m)
        ramp = 0.5 - 0.5 * np.cos(np.pi * ramp)
    out = []
    for _ in range(2):
        theta = rng.uniform(0.0, 2 * np.pi, w.size)
        out.append(ramp * (np.cos(np.multiply.outer(s, w) + theta) @ amp))
    return Irregularities(s, alignment_m=out[0], level_m=out[1])
