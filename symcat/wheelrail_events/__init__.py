"""The wheel/rail contacts' events between IDAS calls: contact-point jumps between minima of
the gap (:mod:`.contact_jumps`, found late: :mod:`.late_jumps`) and lift-off and touchdown
(:mod:`.contact_switching`), as the event handler :class:`.contact_events.ContactEvents` of
:func:`symcat.integrate.simulate`'s stepping driver (:mod:`symcat.integrate.event_stepping`).

This package sits above both the integrator (:mod:`symcat.integrate`, which it plugs into) and
the wheel/rail geometry (:mod:`symcat.wheelrail`, whose gap minima it searches), so that the
integrator needs neither. :func:`default_handlers` is the one place that says which handlers a
model needs; :func:`symcat.simulation.simulate` and :func:`symcat.simulation.integrate_model`
attach them.

Who attaches them: a plain :func:`symcat.integrate.simulate` on a model with wheel/rail
contacts and no handlers raises a one-line error naming :func:`symcat.simulation.simulate`.
The alternative, the model carrying a handler factory set where its wheel/rail contacts are
added, would have the assembly layer (below the integrator) reach up to this package, and a
model assembled any other way would still need the error: one explicit place and one error
are simpler, and an integrator that runs a wheel/rail model silently without its contact
jumps is ruled out either way.
"""
from __future__ import annotations

from .contact_events import ContactEvents

__all__ = ["ContactEvents", "default_handlers"]


def default_handlers(model) -> list:
    """The event handlers ``model`` needs under IDAS (fresh ones, for one run): the wheel/rail
    contacts' (:class:`ContactEvents`) if it has any, else none.

    Parameters
    ----------
    model : MultibodyModel

    Returns
    -------
    list of EventHandler
    """
    return [ContactEvents()] if model.wheelrail else []
