"""The shipped wheel and rail profiles and analytic ones, all in the frame of :mod:`.profiles`.

The four data files in ``symcat/reference_data/profiles/`` each use their own frame (stated in
their first line); the loaders convert them:

================================  ==================================  ====================================
file                              file frame (mm)                     conversion to symcat's frame (m)
================================  ==================================  ====================================
``S1002.csv`` (wheel)             flange at +y, z = radius deviation  y -> -y
``EN15302_wheel_A.csv`` (wheel)   flange at -y, z negative to flange  z -> -z
``UIC60_canted_1in40.csv`` (rail) gauge side -y, z down, top at 0     z -> -z; already inclined 1:40
``EN15302_rail_A.csv`` (rail)     gauge side -y, z up, top +0.49 mm   z -> z - z_top; already inclined
================================  ==================================  ====================================

EN 15302 rail A is given in its installed position: its head axis leans 1:20 toward the track
centre (the centres of its two 13 mm corner arcs differ in height by 1/20 of their spacing), and
its lateral origin is where the EN 15302 wheel origin (tape circle) sits when the wheelset is
centred on the standard's track (gauge 1435.16 mm at 14 mm below the top, tape circles 1500 mm
apart).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np

from symcat.errors import ParameterError

from .profiles import DEFAULT_SMOOTHING_M, Profile

# file name, kind, sign of y, sign of z, shift the top to z = 0, inclination built into the data
_FILES = {
    "S1002": ("S1002.csv", "wheel", -1.0, 1.0, False, 0.0),
    "EN15302_wheel_A": ("EN15302_wheel_A.csv", "wheel", 1.0, -1.0, False, 0.0),
    "UIC60_canted_1in40": ("UIC60_canted_1in40.csv", "rail", 1.0, -1.0, True, math.atan(1 / 40)),
    "EN15302_rail_A": ("EN15302_rail_A.csv", "rail", 1.0, 1.0, True, math.atan(1 / 20)),
}
PROFILE_NAMES = tuple(_FILES)


@lru_cache(maxsize=16)
def load_profile(name: str, smoothing_m: float = DEFAULT_SMOOTHING_M) -> Profile:
    """Load a shipped profile by name (one of :data:`PROFILE_NAMES`), converted to metres and
    to symcat's frame.

    Parameters
    ----------
    name : str
        ``"S1002"``, ``"EN15302_wheel_A"``, ``"UIC60_canted_1in40"`` or ``"EN15302_rail_A"``.
    smoothing_m : float
        RMS deviation of the smoothing spline from the points [m].

    Notes
    -----
    Profiles are cached per ``(name, smoothing_m)``: treat the returned object as read-only.
    """
    if name not in _FILES:
        raise ParameterError(f"profile={name!r}: no such profile (available: {', '.join(PROFILE_NAMES)})")
    fname, kind, sy, sz, top_to_zero, incl = _FILES[name]
    text = resources.files("symcat.reference_data").joinpath("profiles", fname).read_text()
    lines = text.splitlines()
    source = lines[0].lstrip("# ").strip() if lines and lines[0].startswith("#") else ""
    rows = [ln for ln in lines if ln.strip() and not ln.startswith("#")]
    data = np.array([[float(v) for v in ln.split(",")] for ln in rows[1:]]) * 1e-3  # mm -> m
    y, z = sy * data[:, 0], sz * data[:, 1]
    if top_to_zero:
        z = z - z.max()
    return Profile.from_points(y, z, kind, name, smoothing_m=smoothing_m, inclination_rad=incl, source=source)


def s1002() -> Profile:
    """The S1002 wheel (Manchester contact benchmark data, CONTACT examples)."""
    return load_profile("S1002")


def uic60_canted() -> Profile:
    """The UIC60 rail inclined 1:40 (Manchester contact benchmark data, CONTACT examples)."""
    return load_profile("UIC60_canted_1in40")


def en15302_wheel_a() -> Profile:
    """EN 15302 reference wheel profile A."""
    return load_profile("EN15302_wheel_A")


def en15302_rail_a() -> Profile:
    """EN 15302 reference rail profile A (installed position, inclined 1:20)."""
    return load_profile("EN15302_rail_A")


def coned_wheel(conicity: float, y_range_m=(-0.070, 0.065), name: str = "") -> Profile:
    """A coned tread without flange: radius deviation ``z = -conicity * y``.

    Parameters
    ----------
    conicity : float
        Tangent of the cone half-angle (0.05 for 1:20, 0.025 for 1:40) [-], in (0, 0.5].
    y_range_m : (float, float)
        Lateral extent from the tape circle [m].
    """
    if not 0 < conicity <= 0.5:
        raise ParameterError(f"conicity={conicity:g}: must be > 0 and <= 0.5")
    y0, y1 = _check_range(y_range_m, "y_range_m")
    c = math.hypot(1.0, conicity)
    s = np.linspace(0.0, (y1 - y0) * c, 9)
    y = y0 + s / c
    return Profile.from_parametric(s, y, -conicity * y, "wheel", name or f"cone 1:{1 / conicity:g}")


def circular_wheel(radius_m: float, contact_angle_rad: float = 0.05, y_range_m=(-0.05, 0.05),
                   name: str = "") -> Profile:
    """A hollow circular-arc tread of radius ``radius_m`` (the groove's centre of curvature on the
    rail side, as for a worn wheel), sloping at the tape circle like a cone of conicity
    ``tan(contact_angle_rad)``: the smallest radius is at ``y = radius_m sin(contact_angle_rad)``
    and ``z(0) = 0``.

    Parameters
    ----------
    radius_m : float
        Arc radius [m] (larger than the radius of the rail head it runs on).
    contact_angle_rad : float
        Slope angle at the tape circle [rad], in [0, 0.5].
    y_range_m : (float, float)
        Lateral extent [m], within 0.9 radius_m of the groove's centre.
    """
    if not radius_m > 0:
        raise ParameterError(f"radius_m={radius_m:g}: must be > 0")
    if not 0 <= contact_angle_rad <= 0.5:
        raise ParameterError(f"contact_angle_rad={contact_angle_rad:g}: must be >= 0 and <= 0.5")
    y0, y1 = _check_range(y_range_m, "y_range_m")
    yc = radius_m * math.sin(contact_angle_rad)
    if not (abs(y0 - yc) < 0.9 * radius_m and abs(y1 - yc) < 0.9 * radius_m):
        raise ParameterError(f"y_range_m={y_range_m}: must lie within 0.9 radius_m of the groove's centre")
    zc = -radius_m * (1 - math.cos(contact_angle_rad))
    return _arc(radius_m, yc, zc, 1.0, y0, y1, "wheel", name or f"arc wheel R{radius_m:g}")


def circular_rail(radius_m: float, y_range_m=(-0.03, 0.03), inclination_rad: float = 0.0,
                  name: str = "") -> Profile:
    """A convex circular-arc rail head of radius ``radius_m``, top at ``y = 0, z = 0``.

    Parameters
    ----------
    radius_m : float
        Head radius [m].
    y_range_m : (float, float)
        Lateral extent [m], within 0.9 radius_m of the top.
    inclination_rad : float
        Recorded as the inclination built in (the arc itself is symmetric) [rad].
    """
    if not radius_m > 0:
        raise ParameterError(f"radius_m={radius_m:g}: must be > 0")
    y0, y1 = _check_range(y_range_m, "y_range_m")
    if not (abs(y0) < 0.9 * radius_m and abs(y1) < 0.9 * radius_m):
        raise ParameterError(f"y_range_m={y_range_m}: must lie within 0.9 radius_m of the top")
    return _arc(radius_m, 0.0, 0.0, -1.0, y0, y1, "rail", name or f"arc rail R{radius_m:g}",
                inclination_rad=inclination_rad)


def _arc(radius, yc, zc, bulge, y0, y1, kind, name, inclination_rad=0.0) -> Profile:
    # z = zc + bulge R (1 - cos theta), y = yc + R sin theta: parametrised by arc length R theta.
    th0, th1 = math.asin((y0 - yc) / radius), math.asin((y1 - yc) / radius)
    n = max(int(math.ceil((th1 - th0) * radius / 5e-4)), 8) + 1  # 0.5 mm steps: interpolation error ~1e-16 m
    th = np.linspace(th0, th1, n)
    y = yc + radius * np.sin(th)
    z = zc + bulge * radius * (1 - np.cos(th))
    return Profile.from_parametric(radius * (th - th0), y, z, kind, name, inclination_rad=inclination_rad)


def _check_range(r, label):
    try:
        y0, y1 = (float(v) for v in r)
    except (TypeError, ValueError):
        raise ParameterError(f"{label}={r!r}: must be two numbers (m)") from None
    if not (math.isfinite(y0) and math.isfinite(y1) and y1 - y0 >= 0.005):
        raise ParameterError(f"{label}={r!r}: must be finite with y_max - y_min >= 5 mm")
    return y0, y1


@dataclass(frozen=True)
class ProfilePair:
    """A wheel and a rail profile used together (the same on both sides of the track).

    Attributes
    ----------
    name : str
        Choice name (``conical``, ``s1002_uic60``, ``en15302_a``).
    wheel, rail : Profile
    """

    name: str
    wheel: Profile
    rail: Profile


PAIR_NAMES = ("conical", "s1002_uic60", "en15302_a")


def profile_pair(name: str, conicity: float = 0.05) -> ProfilePair:
    """The wheel/rail combinations the models offer.

    Parameters
    ----------
    name : str
        ``"conical"`` (a coned tread of ``conicity`` on the UIC60 rail inclined 1:40),
        ``"s1002_uic60"`` (S1002 on UIC60 1:40) or ``"en15302_a"`` (EN 15302 wheel A on rail A).
    conicity : float
        Cone conicity for ``"conical"`` [-].
    """
    if name == "conical":
        return ProfilePair(name, coned_wheel(conicity), uic60_canted())
    if name == "s1002_uic60":
        return ProfilePair(name, s1002(), uic60_canted())
    if name == "en15302_a":
        return ProfilePair(name, en15302_wheel_a(), en15302_rail_a())
    raise ParameterError(f"profile={name!r}: must be one of {', '.join(PAIR_NAMES)}")
