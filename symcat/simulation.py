"""Integrate a model with the event handlers it needs and the integrator its parameters choose.

:mod:`symcat.integrate` holds the integrators and knows no wheel/rail contact; the handlers of
the wheel/rail contacts' events live above it (:mod:`symcat.wheelrail_events`). This module,
above both, attaches a model's default handlers
(:func:`symcat.wheelrail_events.default_handlers`): :func:`simulate` for IDAS, and
:func:`integrate_model` for the models that choose their integrator by parameters
(:func:`integrator_parameters`).
"""
from __future__ import annotations

from .errors import ParameterError
from .integrate.choice import ALPHA_VARIANTS, INTEGRATORS, integrator_parameters
from .integrate.generalized_alpha import generalized_alpha
from .integrate.results import SimulationResult
from .integrate.settings import IdasSettings, settings_from
from .integrate.simulate import simulate as simulate_with
from .wheelrail_events import default_handlers

__all__ = ["ALPHA_VARIANTS", "INTEGRATORS", "IdasSettings", "integrate_model", "integrator_parameters", "simulate"]


def simulate(model, t_end: float, formulation: str = "augmented", index: str = "1",
             settings: IdasSettings | None = None, *, handlers=None, **legacy) -> SimulationResult:
    """:func:`symcat.integrate.simulate` with ``model``'s default event handlers
    (:func:`~symcat.wheelrail_events.default_handlers`: its wheel/rail contacts' jumps,
    lift-offs and touchdowns) unless ``handlers`` are given.

    Parameters
    ----------
    model : MultibodyModel
    t_end : float
        Simulated time (s).
    formulation, index : str
        As for :func:`symcat.integrate.simulate`.
    settings : IdasSettings, optional
    handlers : sequence of EventHandler, optional
    **legacy
        Fields of :class:`IdasSettings` as keywords.
    """
    if handlers is None:
        handlers = default_handlers(model)
    return simulate_with(model, t_end, formulation, index, settings, handlers=handlers, **legacy)


def integrate_model(model, p: dict, t_end: float, formulation: str, index: str, settings: IdasSettings | None = None,
                    **legacy) -> SimulationResult:
    """Integrate ``model`` with the integrator that ``p`` (the model's parameters) chooses.

    Parameters
    ----------
    model : MultibodyModel
    p : dict
        Holds ``integrator``, ``dt`` (s), ``rho_inf`` and optionally ``tol`` (m; default
        1e-10) (:func:`integrator_parameters`).
    t_end : float
        Simulated time (s).
    formulation, index : str
        As for :func:`symcat.integrate.simulate`; under generalized-alpha the augmented form
        only, ``index`` choosing the constraint levels (:data:`ALPHA_VARIANTS`).
    settings : IdasSettings, optional
        IDAS's tuning (:func:`simulate`); generalized-alpha uses its ``n_out`` and ``progress``.
    **legacy
        Fields of :class:`IdasSettings` as keywords (``n_out=``, ``rtol=``, ...).

    Raises
    ------
    ParameterError
        A combination that cannot run (generalized-alpha with the embedded form), naming it
        and what is allowed.
    """
    settings = settings_from(settings, **legacy)
    if p["integrator"] == "idas":
        return simulate(model, t_end, formulation, index, settings)
    if formulation != "augmented":
        raise ParameterError(f"formulation={formulation} with integrator=generalized_alpha: generalized-alpha "
                             "integrates the augmented form; use formulation=augmented, or integrator=idas")
    return generalized_alpha(model, t_end, p["dt"], p["rho_inf"], variant=ALPHA_VARIANTS[str(index)],
                             tol=p.get("tol", 1e-10), n_out=settings.n_out, progress=settings.progress,
                             handlers=default_handlers(model))
