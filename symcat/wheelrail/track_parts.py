"""The pieces a track layout is made of and what it returns (SI units; conventions in
:mod:`symcat.wheelrail.track`): the segments (tangent, circular curve, clothoid transition), a
rail profile frame with its derivatives, a cubic frame piece for compiled kernels, and the
lateral offset that places a rail profile at the gauge."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Tangent:
    """Straight track of ``length_m`` [m]."""

    length_m: float


@dataclass(frozen=True)
class Curve:
    """Circular curve.

    Attributes
    ----------
    length_m : float
        Length along the centreline [m].
    radius_m : float
        Radius of the centreline [m], > 0.
    direction : str
        ``"left"`` or ``"right"``.
    cant_m : float
        Superelevation of the outer rail over the inner one [m] (negative: inner rail high).
    """

    length_m: float
    radius_m: float
    direction: str = "left"
    cant_m: float = 0.0


#: Superelevation ramps of a :class:`Transition`.
CANT_RAMPS = ("linear", "smooth")


@dataclass(frozen=True)
class Transition:
    """Clothoid of ``length_m`` [m]: curvature linear in ``s`` from that at the end of the
    previous segment to that at the start of the next (a tangent before the first or after the
    last segment), and the superelevation ramped between theirs: ``cant_ramp="linear"`` (the
    classic ramp; its ends are kinks of the raised rail, crossed by a rigid wheel/rail contact
    as impacts) or ``"smooth"`` (the cubic ``3 x^2 - 2 x^3`` of ``x = s / length_m``, Bloss's
    cant: the cant rate starts and ends at zero, so the rails have no kinks)."""

    length_m: float
    cant_ramp: str = "linear"


def cant_ramp_values(h0, rate, length, smooth, u):
    """Superelevation ``h`` [m] and its first two derivatives along the track at ``u`` [m] into
    segments starting at ``h0`` and changing by ``rate * length`` over ``length`` (arrays, one
    entry per point): linear, or where ``smooth`` the cubic ``3 x^2 - 2 x^3`` of
    ``x = u / length`` (:class:`Transition`)."""
    h, dh, d2h = h0 + rate * u, rate + 0.0 * u, 0.0 * u
    if np.any(smooth):
        x = u[smooth] / length[smooth]
        rise = rate[smooth] * length[smooth]
        h[smooth] = h0[smooth] + rise * x * x * (3.0 - 2.0 * x)
        dh[smooth] = rise * 6.0 * x * (1.0 - x) / length[smooth]
        d2h[smooth] = rise * (6.0 - 12.0 * x) / length[smooth] ** 2
    return h, dh, d2h


@dataclass(frozen=True)
class RailFrame:
    """A rail profile frame and its derivatives along the track, vectorised over ``n`` points.

    Attributes
    ----------
    R, dR_ds, d2R_ds2 : ndarray (n, 3)
        Origin [m] and its first [-] and second [1/m] derivatives with respect to ``s``.
    A, dA_ds, d2A_ds2 : ndarray (n, 3, 3)
        Orientation (columns: tangent, lateral to the left, up) and its derivatives [1/m],
        [1/m^2].
    """

    R: np.ndarray
    dR_ds: np.ndarray
    d2R_ds2: np.ndarray
    A: np.ndarray
    dA_ds: np.ndarray
    d2A_ds2: np.ndarray


@dataclass(frozen=True)
class FramePiece:
    """Cubic Hermite approximation of a rail frame on ``[s_start_m, s_end_m]``, exact in value and
    first derivative at both ends: ``R(s) = sum_k position_coeffs[k] t**k`` with
    ``t = s - s_start_m`` (ascending powers), the same for ``A`` with ``orientation_coeffs``.

    Attributes
    ----------
    s_start_m, s_end_m : float
        Ends of the piece [m].
    position_coeffs : ndarray (4, 3)
    orientation_coeffs : ndarray (4, 3, 3)
    """

    s_start_m: float
    s_end_m: float
    position_coeffs: np.ndarray
    orientation_coeffs: np.ndarray

    def evaluate(self, s_m, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """``(R, A)`` or their ``order``-th derivative at ``s_m`` (scalar) [m]."""
        t = float(s_m) - self.s_start_m
        k = np.arange(order, 4)
        fac = np.array([math.perm(int(j), order) for j in k], float)
        w = fac * t ** (k - order)
        return (np.tensordot(w, self.position_coeffs[order:], 1),
                np.tensordot(w, self.orientation_coeffs[order:], 1))


def rail_offset_for(rail, gauge_m: float = 1.435, gauge_depth_m: float = 0.014,
                    rail_inclination_rad: float | None = None) -> float:
    """Lateral distance from the track centre to a rail profile's origin [m], placing its gauge
    point (``gauge_depth_m`` below the top) at ``gauge_m / 2``: the convention of
    :func:`.geometry.contact_geometry`.

    Parameters
    ----------
    rail : Profile
        Rail profile (``y`` toward the field side).
    gauge_m, gauge_depth_m : float
        Track gauge and its measuring depth [m].
    rail_inclination_rad : float or None
        As :class:`TrackLayout`: ``None`` keeps the profile's built-in inclination.
    """
    from .geometry import gauge_point

    if rail_inclination_rad is not None:
        rail = rail.transformed(rail_inclination_rad - rail.inclination_rad)
    return 0.5 * gauge_m - float(gauge_point(rail, gauge_depth_m)[0])
