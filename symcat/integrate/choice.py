"""The integrator a dynamic model runs on, chosen by its parameters: CasADi's IDAS (variable
step and order, error-controlled) or the generalized-alpha method (fixed step, numerical
dissipation of what the step does not resolve: the undamped axial waves of ANCF wires, on
which IDAS takes tens of thousands of steps per simulated second).

Models declare :func:`integrator_parameters` and call :func:`integrate_model`: one place that
knows which integrator, formulation and index combinations run.
"""
from __future__ import annotations

from ..errors import ParameterError
from ..model import Parameter
from .generalized_alpha import generalized_alpha
from .results import SimulationResult
from .simulate import simulate

INTEGRATORS = ("idas", "generalized_alpha")
#: The model's ``index`` under generalized-alpha: the constraint levels enforced.
ALPHA_VARIANTS = {"ggl": "stabilized", "1": "index3"}


def integrator_parameters(dt_s: float = 1e-3, rho_inf: float = 0.9) -> list[Parameter]:
    """The parameters that choose and tune the integrator (``integrator``, ``dt``, ``rho_inf``)."""
    return [
        Parameter("integrator", "idas", "", "idas: variable step and order (rtol); generalized_alpha: fixed step "
                  "dt with numerical dissipation rho_inf (augmented form; index ggl: position and velocity "
                  "constraints, stabilized index 2; index 1: position constraints, index 3)", choices=INTEGRATORS),
        Parameter("dt", dt_s, "s", "time step of generalized_alpha", minimum=0.0, exclusive_minimum=True, maximum=1.0),
        Parameter("rho_inf", rho_inf, "-", "spectral radius at infinite frequency of generalized_alpha (1: no "
                  "numerical dissipation)", minimum=0.0, maximum=1.0),
    ]


def integrate_model(model, p: dict, t_end: float, formulation: str, index: str, n_out: int = 200,
                    progress: bool = True, **idas_options) -> SimulationResult:
    """Integrate ``model`` with the integrator that ``p`` (the model's parameters) chooses.

    Parameters
    ----------
    model : MultibodyModel
    p : dict
        Holds ``integrator``, ``dt`` (s) and ``rho_inf`` (:func:`integrator_parameters`).
    t_end : float
        Simulated time (s).
    formulation, index : str
        As for :func:`~symcat.integrate.simulate`; under generalized-alpha the augmented form
        only, ``index`` choosing the constraint levels (:data:`ALPHA_VARIANTS`).
    n_out : int
        Output intervals.
    **idas_options
        Passed to :func:`~symcat.integrate.simulate` (``rtol``, ``atol``, ...); unused by
        generalized-alpha.

    Raises
    ------
    ParameterError
        A combination that cannot run (generalized-alpha with the embedded form, or with
        wheel/rail contacts), naming it and what is allowed.
    """
    if p["integrator"] == "idas":
        return simulate(model, t_end, formulation, index, n_out=n_out, progress=progress, **idas_options)
    if formulation != "augmented":
        raise ParameterError(f"formulation={formulation} with integrator=generalized_alpha: generalized-alpha "
                             "integrates the augmented form; use formulation=augmented, or integrator=idas")
    contacts = [e.joint.name for e in model.wheelrail]
    if contacts:
        raise ParameterError(f"integrator=generalized_alpha: not yet with wheel/rail contacts "
                             f"({', '.join(contacts)}); use integrator=idas")
    return generalized_alpha(model, t_end, p["dt"], p["rho_inf"], variant=ALPHA_VARIANTS[str(index)], n_out=n_out,
                             progress=progress)
