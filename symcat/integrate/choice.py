"""The integrator a dynamic model runs on, chosen by its parameters: CasADi's IDAS (variable
step and order, error-controlled) or the generalized-alpha method (fixed step, numerical
dissipation of what the step does not resolve: the undamped axial waves of ANCF wires, on
which IDAS takes tens of thousands of steps per simulated second).

Models declare :func:`integrator_parameters` and call :func:`symcat.simulation.integrate_model`
(above this layer: it attaches the event handlers a model needs): one place that knows which
integrator, formulation and index combinations run.
"""
from __future__ import annotations

from ..model import Parameter

INTEGRATORS = ("idas", "generalized_alpha")
#: The model's ``index`` under generalized-alpha: the constraint levels enforced.
ALPHA_VARIANTS = {"ggl": "stabilized", "1": "index3"}


def integrator_parameters(dt_s: float = 1e-3, rho_inf: float = 0.9, default: str = "idas",
                          tol_m: float = 1e-10) -> list[Parameter]:
    """The parameters that choose and tune the integrator (``integrator``, ``dt``, ``rho_inf``,
    ``tol``); ``default``: the model's integrator (IDAS for the multibody scenes,
    generalized-alpha for line passages, whose wires IDAS resolves with thousands of steps per
    simulated second); ``tol_m``: generalized-alpha's Newton tolerance (m), as tight as the
    model's checks need (the default keeps the iteration's error far below the step's)."""
    return [
        Parameter("integrator", default, "", "idas: variable step and order (rtol); generalized_alpha: fixed step "
                  "dt with numerical dissipation rho_inf (augmented form; index ggl: position and velocity "
                  "constraints, stabilized index 2; index 1: position constraints, index 3)", choices=INTEGRATORS),
        Parameter("dt", dt_s, "s", "time step of generalized_alpha", minimum=0.0, exclusive_minimum=True, maximum=1.0),
        Parameter("rho_inf", rho_inf, "-", "spectral radius at infinite frequency of generalized_alpha (1: no "
                  "numerical dissipation)", minimum=0.0, maximum=1.0),
        Parameter("tol", tol_m, "m", "Newton tolerance of generalized_alpha on the coordinates (absolute; "
                  "multipliers counted as the position change they cause)", minimum=1e-13, maximum=1e-3),
    ]
