"""Time integration of multibody models: CasADi's IDAS (:func:`simulate`, variable step and
order, tuned by :class:`IdasSettings`, events between calls through :class:`EventHandler`
plug-ins) and the generalized-alpha method (:func:`generalized_alpha`, fixed step).

This layer knows no wheel/rail or catenary code (``tests/test_layers.py``): the wheel/rail
contact events are handlers of :mod:`symcat.wheelrail_events`, attached by
:func:`symcat.simulation.simulate`."""
from .alpha_coefficients import AlphaCoefficients
from .events import EventHandler
from .generalized_alpha import generalized_alpha
from .settings import IdasSettings
from .simulate import SimulationResult, simulate

__all__ = ["SimulationResult", "simulate", "generalized_alpha", "AlphaCoefficients", "EventHandler", "IdasSettings"]
