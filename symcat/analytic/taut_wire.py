"""Natural frequencies of a tensioned, pinned-pinned Euler-Bernoulli beam.

Small transverse vibration of a straight wire of length ``L`` under constant
axial tension ``T`` with bending stiffness ``E I``, simply supported (pinned,
zero moment) at both ends, obeys ``mu w_tt - T w_xx + E I w_xxxx = 0``. The
modes are ``sin(n pi x / L)`` exactly, which makes this a clean check of
the combined geometric (tension) and material (bending) stiffness of a beam
element about a pre-stressed state.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

__all__ = ["taut_wire_frequencies"]


def _real(name: str, value, *, allow_zero: bool) -> float:
    """Return ``value`` as a finite float ``> 0`` (or ``>= 0``), else raise."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name}={value!r}: must be a finite real number")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name}={value!r}: must be a finite real number")
    if allow_zero and x < 0.0:
        raise ValueError(f"{name}={value!r}: must be >= 0")
    if not allow_zero and x <= 0.0:
        raise ValueError(f"{name}={value!r}: must be > 0")
    return x


def taut_wire_frequencies(length: float, tension: float, mass_per_length: float,
                          bending_stiffness: float, n_modes: int) -> np.ndarray:
    """Natural frequencies of a pinned-pinned tensioned Euler-Bernoulli beam.

    ``f_n = n / (2 L) * sqrt(T / mu) * sqrt(1 + (E I / T) (n pi / L)**2)``
    for ``n = 1, ..., n_modes``, evaluated as
    ``n / (2 L) * sqrt((T + E I (n pi / L)**2) / mu)`` so that ``T = 0``
    (a pinned-pinned beam without tension) is also covered.

    Parameters
    ----------
    length : float
        Distance between the pins ``L`` in m, ``> 0``.
    tension : float
        Axial tension ``T`` in N, ``>= 0``.
    mass_per_length : float
        Mass per unit length ``mu`` in kg/m, ``> 0``.
    bending_stiffness : float
        Bending stiffness ``E I`` in N m**2, ``>= 0``; ``0`` gives the ideal
        string ``f_n = n / (2 L) sqrt(T / mu)``.
    n_modes : int
        Number of modes, ``>= 1``.

    Returns
    -------
    numpy.ndarray
        Shape ``(n_modes,)``: frequencies ``f_1 < f_2 < ...`` in Hz.

    Raises
    ------
    ValueError
        If a parameter is out of range, or if ``tension`` and
        ``bending_stiffness`` are both zero (no stiffness at all).

    Notes
    -----
    Rotary inertia and shear deformation are neglected (Euler-Bernoulli),
    which is accurate while the mode's half wavelength ``L / n`` is much
    longer than the cross-section.

    Examples
    --------
    >>> taut_wire_frequencies(2.0, 100.0, 1.0, 0.0, 3)
    array([2.5, 5. , 7.5])
    """
    length_m = _real("length", length, allow_zero=False)
    tension_n = _real("tension", tension, allow_zero=True)
    mu = _real("mass_per_length", mass_per_length, allow_zero=False)
    ei = _real("bending_stiffness", bending_stiffness, allow_zero=True)
    if tension_n == 0.0 and ei == 0.0:
        raise ValueError(
            f"tension={tension!r}, bending_stiffness={bending_stiffness!r}: "
            "at least one must be > 0"
        )
    if isinstance(n_modes, (bool, np.bool_)) or not isinstance(n_modes, numbers.Integral):
        raise ValueError(f"n_modes={n_modes!r}: must be an integer >= 1")
    if n_modes < 1:
        raise ValueError(f"n_modes={n_modes!r}: must be an integer >= 1")

    n = np.arange(1, int(n_modes) + 1, dtype=float)
    wavenumber = n * math.pi / length_m  # rad/m
    return n / (2.0 * length_m) * np.sqrt((tension_n + ei * wavenumber**2) / mu)
