"""Reference solutions for the inextensible Euler-Bernoulli elastica.

Two classic large-deflection benchmarks for beam elements:

* a cantilever under a dead (non-follower) transverse tip load, solved
  in closed form with elliptic integrals (Bisshopp & Drucker 1945) and,
  independently, by shooting on the governing ODE;
* a cantilever under a pure end moment, which rolls up into a circular arc.

All results are nondimensional (divided by the beam length ``L`` in m) unless
stated otherwise; the load parameter is ``alpha = P L**2 / (E I)`` with ``P``
in N, ``L`` in m and ``E I`` in N m**2.

Notation used below: the beam is clamped at ``x = 0`` with its axis along
``+x``; ``s`` in [0, 1] is the arclength divided by ``L``; ``phi(s)`` is the
clockwise (downward) rotation of the tangent. Moment balance about the
section at ``s`` for a tip load ``P`` in ``-y`` gives ``E I phi' =
P (x_tip - x(s))``, i.e. ``phi'' = -alpha cos(phi)`` with ``phi(0) = 0`` and
``phi'(1) = 0`` (no moment at the free tip).

References
----------
K. E. Bisshopp and D. C. Drucker, "Large deflection of cantilever beams",
Quarterly of Applied Mathematics 3 (1945) 272-275.

K. Mattiasson, "Numerical results from large deflection beam and frame
problems analysed by means of elliptic integrals", International Journal for
Numerical Methods in Engineering 17 (1981) 145-153.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

# SciPy's integrators, root finders and special functions are imported in the functions using
# them: the roll-up reference needs none of them (scipy.integrate alone takes 0.3 s to import).

__all__ = [
    "cantilever_tip_load",
    "cantilever_tip_load_ode",
    "cantilever_tip_load_linear",
    "rollup_tip_position",
]

# Beyond these loads the beam hangs practically vertical; the elliptic
# parameter then gets within ~exp(-2 sqrt(alpha)) of 1 and the shooting
# problem becomes exponentially ill-conditioned, so refuse rather than
# return silently degraded numbers.
ALPHA_MAX_ELLIPTIC = 1.0e4
ALPHA_MAX_ODE = 400.0


def _real(name: str, value) -> float:
    """Convert ``value`` to a finite float or raise a ValueError naming it."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    # bool is an int subclass but never a meaningful load or length
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name}={value!r}: must be a finite real number")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name}={value!r}: must be a finite real number")
    return x


def _alpha(value, alpha_max: float) -> float:
    a = _real("alpha", value)
    if abs(a) > alpha_max:
        raise ValueError(
            f"alpha={value!r}: must satisfy |alpha| <= {alpha_max:g}"
        )
    return a


# --------------------------------------------------------------------------
# Tip load: closed form (elliptic integrals)
# --------------------------------------------------------------------------
#
# Bisshopp & Drucker substitute 1 + sin(phi) = 2 k^2 sin^2(psi), with
# k^2 = m = (1 + sin phi0)/2 and phi0 the tip rotation; then
#     sqrt(alpha) = K(m) - F(psi0, m),     sin(psi0) = 1/sqrt(2 m),
#     x_tip / L  = sqrt(2 sin(phi0) / alpha),
#     delta / L  = 1 - (2/sqrt(alpha)) [E(m) - E(psi0, m)].
# The differences of complete and incomplete integrals cancel badly for both
# small loads (psi0 -> pi/2) and large loads (m -> 1). Legendre's addition
# theorem replaces them by single integrals at the complementary amplitude
# beta, tan(beta) = 1 / (sqrt(1 - m) tan(psi0)):
#     K - F(psi0) = F(beta),  E - E(psi0) = E(beta) - m sin(psi0) sin(beta).
# Everything is then rational in t = tan(beta) = sqrt(sin(phi0) / (1 - m)):
#     sin(phi0) = t^2/(t^2+2),  m = (t^2+1)/(t^2+2),
#     cos^2(beta) = 1/(1+t^2),  1 - m sin^2(beta) = 2/(t^2+2),
# and F, E are evaluated with Carlson's symmetric integrals R_F, R_D without
# ever forming 1 - m. t runs over (0, inf): t ~ sqrt(alpha) for small loads
# and t ~ 0.6 exp(sqrt(alpha)) for large ones, so solving for log(t) keeps
# full relative precision at both ends.


def _elliptic_terms(t: float) -> tuple[float, float]:
    """Return ``(F(beta, m), (m/3) sin^3(beta) R_D)`` for ``t = tan(beta)``."""
    from scipy.special import elliprd, elliprf

    t2 = t * t
    c = 1.0 / (1.0 + t2)  # cos^2(beta)
    sin_b = t / math.sqrt(1.0 + t2)
    delta = 2.0 / (t2 + 2.0)  # 1 - m sin^2(beta)
    m = (t2 + 1.0) / (t2 + 2.0)
    f = sin_b * float(elliprf(c, delta, 1.0))
    e_corr = m / 3.0 * sin_b**3 * float(elliprd(c, delta, 1.0))
    return f, e_corr


# Small loads: perturbation series phi = alpha phi_1 + alpha^3 phi_3 + ...
# of the same BVP, integrated exactly (rational coefficients). Used below
# _SERIES_ALPHA, where the closed form's ux ~ -alpha^2/15 would lose
# relative accuracy to cancellation; the first omitted terms are below
# 1e-16 relative there.
_SERIES_ALPHA = 0.05
_UX_SERIES = (-1 / 15, 4 / 315, -2126 / 675675, 356164 / 402026625,
              -3700313 / 13749310575)  # coefficients of alpha^2, ^4, ..., ^10
_UY_SERIES = (-1 / 3, 4 / 105, -47 / 5775, 21584 / 10135125,
              -2837452 / 4583103525)  # coefficients of alpha, ^3, ..., ^9


def _tip_load_series(a: float) -> tuple[float, float]:
    a2 = a * a
    ux = a2 * np.polynomial.polynomial.polyval(a2, _UX_SERIES)
    uy = a * np.polynomial.polynomial.polyval(a2, _UY_SERIES)
    return float(ux), float(uy)


def cantilever_tip_load(alpha: float) -> tuple[float, float]:
    """Tip displacement of a cantilever elastica under a dead tip load.

    Closed-form (elliptic integral) solution of Bisshopp & Drucker (1945)
    for an inextensible, unshearable Euler-Bernoulli cantilever clamped at
    ``x = 0`` along ``+x`` and loaded at the free tip by a force of fixed
    direction perpendicular to the undeformed axis.

    Parameters
    ----------
    alpha : float
        Nondimensional load ``P L**2 / (E I)`` (``P`` in N, ``L`` in m,
        ``E I`` in N m**2). Positive: load in ``-y``. A negative value means
        a load in ``+y`` and gives the mirrored result. ``|alpha| <= 1e4``.

    Returns
    -------
    ux_over_L : float
        Axial tip displacement divided by ``L`` (dimensionless); always
        ``<= 0`` (the projected length shortens).
    uy_over_L : float
        Transverse tip displacement divided by ``L`` (dimensionless); it has
        the sign of the load, so it is negative for positive ``alpha``.

    Raises
    ------
    ValueError
        If ``alpha`` is not a finite real number or ``|alpha| > 1e4``.

    See Also
    --------
    cantilever_tip_load_ode : independent shooting solution of the same BVP.
    cantilever_tip_load_linear : small-deflection limit.

    Notes
    -----
    The tip rotation ``phi0`` is found by solving
    ``F(beta, m) = sqrt(alpha)`` with :func:`scipy.optimize.brentq` (see the
    source comments for the substitution). For ``|alpha| < 0.05``, where
    the closed form for the tiny axial displacement ``ux ~ -alpha**2/15``
    suffers from cancellation, a perturbation series in ``alpha`` (exact
    rational coefficients up to ``alpha**10``) is used instead. Checked
    against 50-digit arithmetic: relative error below 1e-12 for both
    components over ``1e-4 <= alpha <= 1e4``.

    Examples
    --------
    >>> ux, uy = cantilever_tip_load(1.0)
    >>> round(ux, 5), round(uy, 5)
    (-0.05643, -0.30172)
    """
    a = _alpha(alpha, ALPHA_MAX_ELLIPTIC)
    if a == 0.0:
        return 0.0, 0.0
    sign = 1.0 if a > 0.0 else -1.0
    a = abs(a)
    if a < _SERIES_ALPHA:
        ux, uy = _tip_load_series(a)
        return ux, sign * uy
    from scipy.optimize import brentq

    root_a = math.sqrt(a)

    def residual(log_t: float) -> float:
        return _elliptic_terms(math.exp(log_t))[0] - root_a

    # F(beta, m) <= F(beta, 1) = asinh(t) < t, so t = sqrt(alpha) is a lower
    # bracket. The upper one comes from the large-load asymptote, widened
    # until the sign changes.
    lo = math.log(root_a)
    hi = max(lo + 1.0, root_a + 1.0)
    while residual(hi) < 0.0:
        hi += 2.0
    log_t = brentq(residual, lo, hi, xtol=1e-300, rtol=4.0 * np.finfo(float).eps,
                   maxiter=500)
    t = math.exp(log_t)
    t2 = t * t

    f, e_corr = _elliptic_terms(t)
    sin_phi0 = 1.0 / (1.0 + 2.0 / t2)
    x_tip = t * math.sqrt(2.0 / (t2 + 2.0)) / root_a
    # E(beta) = F(beta) - (m/3) sin^3(beta) R_D, hence
    # delta = 1 - (2/sqrt(alpha)) (F - e_corr - sqrt(sin(phi0)/2)).
    delta = 1.0 - 2.0 / root_a * (f - e_corr - math.sqrt(0.5 * sin_phi0))
    return x_tip - 1.0, -sign * delta


# --------------------------------------------------------------------------
# Tip load: shooting on the ODE
# --------------------------------------------------------------------------
#
# Shooting runs from the free tip towards the clamp in sigma = 1 - s, which
# leaves phi'' = -alpha cos(phi) unchanged and makes both tip conditions
# exact (phi = phi0, phi' = 0). Going back from the tip, phi decreases
# monotonically until the pendulum-like motion bottoms out at -pi - phi0;
# the clamp of the physical (loop-free) solution is the FIRST point where
# phi returns to 0. Its distance from the tip, sigma_c(phi0), grows
# monotonically from 0 (phi0 -> 0) to infinity (phi0 -> pi/2, where
# phi = pi/2 is an equilibrium), so sigma_c(phi0) = 1 has exactly one root.
# Asking instead for phi(sigma=1) = 0 would also admit looped solutions.


def _hit_clamp(_sigma, y, _a):
    return y[0]


_hit_clamp.terminal = True
_hit_clamp.direction = -1.0

# Far enough that a missed crossing unambiguously means "phi0 too large".
_SIGMA_MAX = 2.0


def _shoot(phi0: float, a: float, sigma_end: float | None = None) -> np.ndarray | None:
    """Integrate the elastica from the tip (sigma = 0) towards the clamp.

    State: phi, dphi/dsigma, u, v, dphi/dphi0, d(dphi/dsigma)/dphi0, where
    u' = cos(phi) - 1 and v' = -sin(phi) accumulate the tip displacements
    u = ux/L and v = uy/L (for a load in -y).

    With ``sigma_end=None`` integration stops at the first zero of phi and
    ``[sigma_c, *state]`` there is returned (None if phi stays positive up to
    _SIGMA_MAX). Otherwise the state at ``sigma_end`` is returned; it is a
    step end point, which is more accurate than the event's interpolated one.
    """
    from scipy.integrate import solve_ivp

    def rhs(_sigma, y, a):
        phi, kappa, _u, _v, dphi, dkappa = y
        c, s = math.cos(phi), math.sin(phi)
        # cos(phi) - 1 written as -2 sin^2(phi/2): no cancellation for the
        # O(alpha^2) axial displacement under small loads
        return [kappa, -a * c, -2.0 * math.sin(0.5 * phi) ** 2, -s, dkappa,
                a * s * dphi]

    # absolute tolerances follow the size of each state (phi ~ alpha,
    # u ~ alpha^2 for small loads) so that rtol governs throughout
    scale = min(1.0, a)
    atol = 1e-16 * np.array([scale, scale, scale * scale, scale, 1.0, scale])
    y0 = [phi0, 0.0, 0.0, 0.0, 1.0, 0.0]
    if sigma_end is not None:
        sol = solve_ivp(rhs, (0.0, sigma_end), y0, method="DOP853",
                        rtol=1e-13, atol=atol, args=(a,))
    else:
        sol = solve_ivp(rhs, (0.0, _SIGMA_MAX), y0, method="DOP853",
                        rtol=1e-13, atol=atol, events=_hit_clamp, args=(a,))
    if not sol.success:  # pragma: no cover - DOP853 on a smooth RHS
        raise RuntimeError(f"elastica shooting failed: {sol.message}")
    if sigma_end is not None:
        return sol.y[:, -1]
    if sol.t_events[0].size == 0:
        return None
    return np.concatenate(([sol.t_events[0][0]], sol.y_events[0][0]))


def cantilever_tip_load_ode(alpha: float) -> tuple[float, float]:
    """Tip displacement of the tip-loaded cantilever elastica by shooting.

    Same problem and conventions as :func:`cantilever_tip_load`, solved
    without elliptic integrals: ``phi'' = -alpha cos(phi)`` is integrated
    with :func:`scipy.integrate.solve_ivp` (DOP853, ``rtol=1e-13``) from the
    free tip (``phi = phi0``, ``phi' = 0``) until ``phi`` first returns to
    zero, and the tip rotation ``phi0`` is adjusted by a bracketed Newton
    iteration (variational equations for the derivative) until that point
    lies at unit arclength. Meant as an independent cross-check of the
    closed form.

    Parameters
    ----------
    alpha : float
        Nondimensional load ``P L**2 / (E I)`` (``P`` in N, ``L`` in m,
        ``E I`` in N m**2). Positive: load in ``-y``; negative: load in
        ``+y``. ``|alpha| <= 400``.

    Returns
    -------
    ux_over_L : float
        Axial tip displacement divided by ``L`` (dimensionless, ``<= 0``).
    uy_over_L : float
        Transverse tip displacement divided by ``L`` (dimensionless), with
        the sign of the load (negative for positive ``alpha``).

    Raises
    ------
    ValueError
        If ``alpha`` is not a finite real number or ``|alpha| > 400``.

    Notes
    -----
    Agrees with :func:`cantilever_tip_load` to a relative 1e-12 for
    ``1e-4 <= alpha <= 100`` (5e-9 at ``alpha = 400``). For large loads the
    tip angle approaches ``pi/2`` within ``~8 exp(-sqrt(alpha))`` and the
    shooting loses accuracy (the vertical configuration is a saddle of the
    ODE), hence the limit. Below ``|alpha| = 1e-8`` the leading terms
    ``(-alpha**2/15, -alpha/3)`` are returned, which are exact there to
    double precision. Takes 5-50 ms per call.
    """
    a = _alpha(alpha, ALPHA_MAX_ODE)
    if a == 0.0:
        return 0.0, 0.0
    sign = 1.0 if a > 0.0 else -1.0
    a = abs(a)
    if a < 1e-8:
        # leading terms of the small-load expansion; the next ones are
        # smaller by 4 alpha^2 / 21 < 1e-16 and the shooting would only
        # fight underflow here
        return -a * a / 15.0, -sign * a / 3.0

    # Bracket [0, pi/2] on the tip rotation, start from the linear value
    # alpha/2, take Newton steps on sigma_c(phi0) - 1 and bisect whenever a
    # step leaves the bracket or the crossing is not found.
    lo, hi = 0.0, 0.5 * math.pi
    phi0 = min(0.5 * a, 0.5 * (lo + hi))
    for _ in range(200):
        hit = _shoot(phi0, a)
        if hit is None:
            hi = phi0
            candidate = 0.5 * (lo + hi)
        else:
            sigma_c, _phi, kappa, _u, _v, dphi, _dkappa = hit
            if sigma_c < 1.0:
                lo = phi0
            else:
                hi = phi0
            # phi(sigma_c(phi0); phi0) = 0  =>  dsigma_c/dphi0 = -dphi/kappa
            slope = -dphi / kappa if kappa < 0.0 else 0.0
            candidate = phi0 - (sigma_c - 1.0) / slope if slope > 0.0 else math.nan
            if abs(sigma_c - 1.0) <= 4.0 * np.finfo(float).eps:
                break
            if not lo < candidate < hi:
                candidate = 0.5 * (lo + hi)
        if hi - lo <= 4.0 * np.finfo(float).eps * hi or candidate == phi0:
            break
        phi0 = candidate
    else:  # pragma: no cover - bisection alone converges in < 60 steps
        raise RuntimeError(f"elastica shooting did not converge for alpha={alpha!r}")

    # phi0 now puts the clamp at unit arclength: integrate exactly that far
    _phi, _kappa, ux, uy, _dphi, _dkappa = _shoot(phi0, a, sigma_end=1.0)
    return float(ux), float(sign * uy)


def cantilever_tip_load_linear(alpha: float) -> tuple[float, float]:
    """Small-deflection (linear Euler-Bernoulli) tip-loaded cantilever.

    Parameters
    ----------
    alpha : float
        Nondimensional load ``P L**2 / (E I)`` (``P`` in N, ``L`` in m,
        ``E I`` in N m**2); positive for a load in ``-y``.

    Returns
    -------
    ux_over_L : float
        Always ``0.0``: linear theory has no axial shortening.
    uy_over_L : float
        ``-alpha / 3``, i.e. ``-P L**3 / (3 E I)`` divided by ``L``.

    Raises
    ------
    ValueError
        If ``alpha`` is not a finite real number.
    """
    a = _real("alpha", alpha)
    return 0.0, -a / 3.0


# --------------------------------------------------------------------------
# Pure end moment: roll-up
# --------------------------------------------------------------------------


def rollup_tip_position(moment_factor: float, length: float) -> tuple[float, float]:
    """Tip position of a cantilever rolled up by a pure end moment.

    A cantilever clamped at the origin along ``+x`` carries an end moment
    ``M = k * 2 pi E I / L`` about ``+z`` (``k = moment_factor``). The
    curvature ``M / (E I)`` is uniform, so the beam becomes a circular arc of
    radius ``R = L / (2 pi k)`` subtending ``2 pi k``; ``k = 1`` closes a
    full circle and brings the tip back to the clamp.

    Parameters
    ----------
    moment_factor : float
        ``k = M L / (2 pi E I)`` (dimensionless). Positive: counter-clockwise
        moment, tip curls toward ``+y``; negative: toward ``-y``.
    length : float
        Beam length ``L`` in m, ``> 0``.

    Returns
    -------
    x : float
        Tip x coordinate in m, ``R sin(2 pi k)``.
    y : float
        Tip y coordinate in m, ``R (1 - cos(2 pi k))``.

    Raises
    ------
    ValueError
        If ``moment_factor`` is not finite or ``length`` is not a finite
        positive number.

    Notes
    -----
    Written with ``sinc(x) = sin(pi x)/(pi x)`` as ``x = L sinc(2k)`` and
    ``y = L sin(pi k) sinc(k)``, which is exact and division-free at
    ``k = 0`` (straight beam, tip at ``(L, 0)``) and accurate for tiny k.

    Examples
    --------
    >>> rollup_tip_position(0.0, 2.0)
    (2.0, 0.0)
    """
    k = _real("moment_factor", moment_factor)
    length_m = _real("length", length)
    if length_m <= 0.0:
        raise ValueError(f"length={length!r}: must be > 0")
    x = length_m * float(np.sinc(2.0 * k))
    y = length_m * math.sin(math.pi * k) * float(np.sinc(k))
    return x, y
