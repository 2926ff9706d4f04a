"""Elastic catenary between two supports at equal height (Irvine 1981).

A cable of unstretched length ``L0`` (m), weight ``w`` per unstretched
length (N/m, ``w = mu g``) and axial stiffness ``E A`` (N) hangs between
two supports at the same height a span ``l`` (m) apart. The horizontal
tension component ``H`` (N) is constant along the cable and each support
carries half the weight, ``V = w L0 / 2``. With the Lagrangian coordinate
``s`` in [0, L0] (unstretched arclength from the left support) Irvine's
solution reads

    x(s) = H s / EA + (H / w) [asinh(V / H) - asinh((V - w s) / H)]
    z(s) = w s (L0 - s) / (2 EA)
           + (H / w) [sqrt(1 + (V / H)**2) - sqrt(1 + ((V - w s) / H)**2)]

with ``z`` the depth below the supports (positive downward), hence

    l = x(L0)   = H L0 / EA + (2 H / w) asinh(w L0 / (2 H)),
    d = z(L0/2) = (H / w) (sqrt(1 + (w L0 / (2 H))**2) - 1) + w L0**2 / (8 EA).

The theory assumes linear elasticity and small strain (``T / EA << 1``);
``axial_stiffness = inf`` gives the inextensible catenary.

References
----------
H. M. Irvine, "Cable Structures", MIT Press, 1981, section 2.2.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

__all__ = [
    "ElasticCatenary",
    "elastic_catenary",
    "elastic_catenary_sag",
    "elastic_catenary_shape",
    "elastic_catenary_span",
]

_RTOL = 4.0 * np.finfo(float).eps


def _real(name: str, value, *, allow_inf: bool = False) -> float:
    """Return ``value`` as a float ``> 0`` (``inf`` only if allowed), else raise."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    what = "a positive real number" + (" or inf" if allow_inf else "")
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name}={value!r}: must be {what}")
    x = float(value)
    if math.isnan(x) or (math.isinf(x) and not (allow_inf and x > 0.0)):
        raise ValueError(f"{name}={value!r}: must be {what}")
    if x <= 0.0:
        raise ValueError(f"{name}={value!r}: must be > 0")
    return x


@dataclass(frozen=True)
class ElasticCatenary:
    """Static equilibrium of an elastic catenary with level supports.

    Build it with :func:`elastic_catenary`, which makes the fields mutually
    consistent; :func:`elastic_catenary_shape` turns it into coordinates.

    Attributes
    ----------
    span_m : float
        Horizontal distance between the supports ``l`` in m.
    unstretched_length_m : float
        Unstretched cable length ``L0`` in m.
    horizontal_tension_N : float
        Horizontal tension component ``H`` in N (constant along the cable).
    sag_m : float
        Midspan sag ``d`` (depth below the supports) in m.
    support_tension_N : float
        Cable tension at each support, ``sqrt(H**2 + (w L0 / 2)**2)``, in N
        (the maximum tension in the cable).
    weight_per_length_N_per_m : float
        Weight per unstretched length ``w`` in N/m.
    axial_stiffness_N : float
        Axial stiffness ``E A`` in N (``inf`` for an inextensible cable).
    """

    span_m: float
    unstretched_length_m: float
    horizontal_tension_N: float
    sag_m: float
    support_tension_N: float
    weight_per_length_N_per_m: float
    axial_stiffness_N: float


def _span(h: float, l0: float, w: float, ea: float) -> float:
    # H L0 / EA vanishes for EA = inf without special-casing
    return h * l0 / ea + 2.0 * h / w * math.asinh(0.5 * w * l0 / h)


def _sag(h: float, l0: float, w: float, ea: float) -> float:
    x = 0.5 * w * l0 / h
    # (H/w)(sqrt(1 + x^2) - 1) rewritten without the cancellation that would
    # spoil the shallow (parabolic) limit
    return 0.25 * w * l0 * l0 / h / (math.sqrt(1.0 + x * x) + 1.0) + w * l0 * l0 / (8.0 * ea)


def elastic_catenary_span(horizontal_tension: float, unstretched_length: float,
                          weight_per_length: float, axial_stiffness: float) -> float:
    """Span of a level elastic catenary, ``l = H L0/EA + (2H/w) asinh(w L0/(2H))``.

    Parameters
    ----------
    horizontal_tension : float
        Horizontal tension ``H`` in N, ``> 0``.
    unstretched_length : float
        Unstretched cable length ``L0`` in m, ``> 0``.
    weight_per_length : float
        Weight per unstretched length ``w = mu g`` in N/m, ``> 0``.
    axial_stiffness : float
        Axial stiffness ``E A`` in N, ``> 0``; ``inf`` for inextensible.

    Returns
    -------
    float
        Horizontal distance between the supports ``l`` in m.

    Raises
    ------
    ValueError
        If a parameter is not a positive real number (``inf`` is accepted
        only for ``axial_stiffness``).
    """
    h = _real("horizontal_tension", horizontal_tension)
    l0 = _real("unstretched_length", unstretched_length)
    w = _real("weight_per_length", weight_per_length)
    ea = _real("axial_stiffness", axial_stiffness, allow_inf=True)
    return _span(h, l0, w, ea)


def elastic_catenary_sag(horizontal_tension: float, unstretched_length: float,
                         weight_per_length: float, axial_stiffness: float) -> float:
    """Midspan sag of a level elastic catenary.

    ``d = (H/w) (sqrt(1 + (w L0/(2H))**2) - 1) + w L0**2 / (8 EA)``: the
    depth of the cable's midpoint below the line joining the supports.

    Parameters
    ----------
    horizontal_tension : float
        Horizontal tension ``H`` in N, ``> 0``.
    unstretched_length : float
        Unstretched cable length ``L0`` in m, ``> 0``.
    weight_per_length : float
        Weight per unstretched length ``w = mu g`` in N/m, ``> 0``.
    axial_stiffness : float
        Axial stiffness ``E A`` in N, ``> 0``; ``inf`` for inextensible.

    Returns
    -------
    float
        Midspan sag ``d`` in m (positive).

    Raises
    ------
    ValueError
        If a parameter is not a positive real number (``inf`` is accepted
        only for ``axial_stiffness``).
    """
    h = _real("horizontal_tension", horizontal_tension)
    l0 = _real("unstretched_length", unstretched_length)
    w = _real("weight_per_length", weight_per_length)
    ea = _real("axial_stiffness", axial_stiffness, allow_inf=True)
    return _sag(h, l0, w, ea)


def _solve_increasing(f, lo: float, hi: float) -> float:
    """Root of an increasing ``f`` with ``f(lo) <= 0 <= f(hi)``, to round-off."""
    f_lo, f_hi = f(lo), f(hi)
    if f_lo >= 0.0:  # the bound is already the root to round-off
        return lo
    if f_hi <= 0.0:
        return hi
    return brentq(f, lo, hi, xtol=1e-300, rtol=_RTOL, maxiter=500)


def _unstretched_length_for(span: float, h: float, w: float, ea: float) -> float:
    """Solve l(L0) = span for L0 with H given (l is increasing in L0)."""
    # asinh(x) <= x gives l(L0) <= L0 (1 + H/EA): a lower bracket.
    lo = span / (1.0 + h / ea)
    # l(L0) >= H L0/EA and l(L0) >= (2H/w) asinh(w L0/(2H)): either bound
    # reaching the span gives an upper bracket.
    x = 0.5 * w * span / h
    uppers = [span * ea / h] if math.isfinite(ea) else []
    if x < 700.0:  # sinh overflows beyond
        uppers.append(2.0 * h / w * math.sinh(x))
    if not uppers or not math.isfinite(min(uppers)):
        raise ValueError(
            f"horizontal_tension={h!r}: too small for span={span!r} with "
            f"weight_per_length={w!r} (the unstretched length would overflow)"
        )
    hi = max(min(uppers), lo)
    return _solve_increasing(lambda l0: _span(h, l0, w, ea) - span, lo, hi)


def _horizontal_tension_for(span: float, l0: float, w: float, ea: float) -> float:
    """Solve l(H) = span for H with L0 given (l is increasing in H)."""
    # l(H) rises from 0 (H -> 0) to L0 + H L0/EA (H -> inf): with finite EA
    # every span is reachable (the cable stretches), an inextensible cable
    # needs span < L0.
    if not math.isfinite(ea) and span >= l0:
        raise ValueError(
            f"span={span!r}: must be < unstretched_length={l0!r} for an "
            "inextensible cable (axial_stiffness=inf)"
        )
    # asinh(x) <= sqrt(2 x) gives l(H) <= H L0/EA + 2 sqrt(H L0 / w); each
    # term is <= span/2 below:
    lo = min(span * ea / (2.0 * l0), w * span * span / (16.0 * l0))
    # l(H) >= H L0/EA, and asinh(x) >= x - x^3/6 gives
    # l(H) >= L0 (1 - (w L0/(2H))^2 / 6); either reaching the span suffices.
    uppers = [span * ea / l0] if math.isfinite(ea) else []
    if span < l0:
        uppers.append(w * l0 / (2.0 * math.sqrt(6.0 * (1.0 - span / l0))))
    hi = max(min(uppers), lo)
    return _solve_increasing(lambda h: _span(h, l0, w, ea) - span, lo, hi)


def elastic_catenary(span: float, weight_per_length: float, axial_stiffness: float,
                     horizontal_tension: float | None = None,
                     unstretched_length: float | None = None) -> ElasticCatenary:
    """Solve the level elastic catenary for a given span.

    Exactly one of ``horizontal_tension`` and ``unstretched_length`` must be
    given; the other is found from the span equation
    ``span = H L0/EA + (2H/w) asinh(w L0/(2H))`` with
    :func:`scipy.optimize.brentq` on a bracket derived from elementary
    bounds on ``asinh``. The span is strictly increasing in both ``H`` and
    ``L0``, so the solution is unique.

    Parameters
    ----------
    span : float
        Horizontal distance between the supports ``l`` in m, ``> 0``.
    weight_per_length : float
        Weight per unstretched length ``w = mu g`` in N/m, ``> 0``.
    axial_stiffness : float
        Axial stiffness ``E A`` in N, ``> 0``; ``inf`` for inextensible.
    horizontal_tension : float, optional
        Horizontal tension ``H`` in N, ``> 0``. Any value is feasible.
    unstretched_length : float, optional
        Unstretched cable length ``L0`` in m, ``> 0``. With finite ``EA``
        any value is feasible (for ``L0 <= span`` the cable is stretched
        taut, see Notes); with ``axial_stiffness=inf`` it must exceed
        ``span``.

    Returns
    -------
    ElasticCatenary
        Span, unstretched length, horizontal tension, midspan sag, support
        tension, weight per length and axial stiffness (SI units).

    Raises
    ------
    ValueError
        If not exactly one of ``horizontal_tension`` / ``unstretched_length``
        is given, a parameter is not a positive real number, the span is
        unreachable (inextensible cable with ``span >= unstretched_length``)
        or the solution overflows (vanishing ``horizontal_tension``).

    Notes
    -----
    As ``H -> inf`` the span tends to ``L0 (1 + H/EA)`` without bound, so
    with finite ``EA`` there is no upper limit on the span for a given
    ``L0``; a span near or beyond ``L0`` simply means a large cable strain
    ``H / EA``. Irvine's linear theory is only meaningful while that strain
    is small, which the caller should check (``support_tension_N / EA``).

    Examples
    --------
    >>> c = elastic_catenary(100.0, 10.0, float("inf"), horizontal_tension=1000.0)
    >>> round(c.sag_m, 6), round(10.0 * 100.0**2 / (8 * 1000.0), 6)
    (12.762597, 12.5)
    """
    span_m = _real("span", span)
    w = _real("weight_per_length", weight_per_length)
    ea = _real("axial_stiffness", axial_stiffness, allow_inf=True)
    if (horizontal_tension is None) == (unstretched_length is None):
        raise ValueError(
            f"horizontal_tension={horizontal_tension!r}, "
            f"unstretched_length={unstretched_length!r}: exactly one must be given"
        )
    if horizontal_tension is not None:
        h = _real("horizontal_tension", horizontal_tension)
        l0 = _unstretched_length_for(span_m, h, w, ea)
    else:
        l0 = _real("unstretched_length", unstretched_length)
        h = _horizontal_tension_for(span_m, l0, w, ea)
    return ElasticCatenary(
        span_m=span_m,
        unstretched_length_m=l0,
        horizontal_tension_N=h,
        sag_m=_sag(h, l0, w, ea),
        support_tension_N=math.hypot(h, 0.5 * w * l0),
        weight_per_length_N_per_m=w,
        axial_stiffness_N=ea,
    )


def elastic_catenary_shape(c: ElasticCatenary, n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Equilibrium shape of a level elastic catenary at material points.

    Evaluates Irvine's Lagrangian solution at ``n_points`` material points
    equally spaced in unstretched arclength, ``s_i = i L0 / (n_points - 1)``,
    i.e. at the nodes of a uniform mesh of the undeformed cable: a ready
    initial guess for a finite-element static solve.

    Parameters
    ----------
    c : ElasticCatenary
        Solution from :func:`elastic_catenary`.
    n_points : int
        Number of points, ``>= 2`` (odd values put a point at midspan).

    Returns
    -------
    x : numpy.ndarray
        Shape ``(n_points,)``: horizontal coordinates in m, from ``0`` at the
        left support to ``span_m`` at the right one.
    z : numpy.ndarray
        Shape ``(n_points,)``: vertical coordinates in m, measured UPWARD
        from the supports (``z = 0`` at both ends, ``z = -sag_m`` at
        midspan), so gravity acts along ``-z``.

    Raises
    ------
    ValueError
        If ``c`` is not an :class:`ElasticCatenary` or ``n_points`` is not
        an integer ``>= 2``.
    """
    if not isinstance(c, ElasticCatenary):
        raise ValueError(f"c={c!r}: must be an ElasticCatenary (see elastic_catenary)")
    if (isinstance(n_points, (bool, np.bool_)) or not isinstance(n_points, numbers.Integral)
            or n_points < 2):
        raise ValueError(f"n_points={n_points!r}: must be an integer >= 2")

    h = c.horizontal_tension_N
    l0 = c.unstretched_length_m
    w = c.weight_per_length_N_per_m
    ea = c.axial_stiffness_N
    s = np.linspace(0.0, l0, int(n_points))
    v = 0.5 * w * l0  # vertical reaction at each support, N
    a = v / h
    b = (v - w * s) / h  # tan of the cable angle below the horizontal
    x = h * s / ea + h / w * (np.arcsinh(a) - np.arcsinh(b))
    # the catenary term's difference of square roots, rationalised so that
    # shallow cables keep full relative accuracy
    depth = (w * s * (l0 - s) / (2.0 * ea)
             + w * s * (l0 - s) / (h * (np.sqrt(1.0 + a * a) + np.sqrt(1.0 + b * b))))
    return x, 0.0 - depth  # 0.0 - ... avoids -0.0 at the supports
