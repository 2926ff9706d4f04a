"""Extensible elastica: the continuum model that symcat's ANCF elements discretize.

A planar Kirchhoff rod with axial strain ``eps = N / EA`` and bending strain
``kappa = d theta / dS`` per unit reference length (no shear). Its finite-element solutions
converge to these, so they serve as the exact reference for convergence orders; the
inextensible elastica (:mod:`symcat.analytic.elastica`) is the limit ``EA -> inf``.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


def extensible_cantilever_tip_load(alpha: float, axial_compliance: float) -> tuple[float, float]:
    """Tip displacement of an extensible cantilever under a dead transverse tip load.

    Parameters
    ----------
    alpha : float
        Load factor ``P L^2 / (E I)`` (-), load in -y.
    axial_compliance : float
        ``E I / (E A L^2)`` (-); for a solid rectangle ``h^2 / (12 L^2)``.

    Returns
    -------
    (ux_over_L, uy_over_L) : tuple of float
        Tip displacement over the length (negative: shortening, downward).

    Notes
    -----
    With ``s = S / L``: ``theta'' = alpha lambda cos(theta)``, ``lambda = 1 - alpha c sin(theta)``,
    ``x' = lambda cos(theta)``, ``y' = lambda sin(theta)``, ``theta(0) = 0``, ``theta'(1) = 0``,
    solved by shooting on ``theta'(0)`` with tight tolerances.
    """
    alpha = float(alpha)
    c = float(axial_compliance)
    if not alpha >= 0:
        raise ValueError(f"alpha={alpha}: must be >= 0")
    if not c >= 0:
        raise ValueError(f"axial_compliance={c}: must be >= 0")
    if alpha == 0:
        return 0.0, 0.0

    def rhs(_s, y):
        theta, dtheta, _x, _y = y
        lam = 1 - alpha * c * np.sin(theta)
        return [dtheta, alpha * lam * np.cos(theta), lam * np.cos(theta), lam * np.sin(theta)]

    def end(k0):
        sol = solve_ivp(rhs, (0, 1), [0.0, k0, 0.0, 0.0], rtol=1e-12, atol=1e-13, method="DOP853")
        return sol.y[:, -1]

    # theta'(0) = -M(0)/EI lies in [-alpha (1 + alpha c), 0].
    k0 = brentq(lambda k: end(k)[1], -alpha * (1 + alpha * c) - 1e-9, 0.0, xtol=1e-14, rtol=1e-14)
    _, _, x, y = end(k0)
    return float(x - 1.0), float(y)
