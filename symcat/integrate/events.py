"""Events between IDAS calls as plug-ins of the integrator: the interface an event handler
implements for :func:`symcat.integrate.simulate`'s stepping driver
(:class:`.event_stepping.EventStepper`).

Some models change between integrator calls in ways IDAS cannot follow within one: a
constraint point that jumps to another minimum, a constraint that is released or closes again
(the wheel/rail contacts, :mod:`symcat.wheelrail_events`). Their driver integrates in short
calls, shortens them toward a predicted event, checks the state after each call and restarts
IDAS from a state it has changed. What is generic about that (the call lengths on a binary
grid, the shifted integrators, retries and fallbacks, redoing a call that passed an event)
lives in :mod:`.event_stepping`; what the events are and what they do to the state is a
handler's. The integrator layer therefore knows no wheel, rail or catenary: the handlers live
in the packages above it, and a model's default handlers are attached there
(:func:`symcat.simulation.simulate`).

A handler holds the state of one run (the DAE's mode parameters, the last checks, the events
so far): :meth:`EventHandler.attach` starts it afresh.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np


class EventHandler(ABC):
    """Decisions of the stepping driver between IDAS calls (one run at a time).

    The driver calls :meth:`attach` before the consistent initial state (which releases
    :meth:`open_rows`), :meth:`start` at that state, then for each call: :meth:`mode` (the
    DAE's parameters), and after it :meth:`overshoot`, :meth:`check`, :meth:`late`,
    :meth:`kept_output` (redo decisions), :meth:`after` (events: the state restarted from) and
    :meth:`verify`; after a failed call, :meth:`recover`, and :meth:`stall_reason` and
    :meth:`failure_hint` for the report.

    Attributes
    ----------
    stat_keys : tuple of str
        The handler's counts in the run's statistics, in their order (set to 0 by the driver).
    counter_names : dict
        The names under which the driver counts in those statistics: ``calls`` (integrator
        calls), ``retries`` (failed calls), ``fallbacks`` (other solvers tried),
        ``overshoot_redos`` (calls redone up to an event they passed, :meth:`overshoot`),
        ``late_redos`` (calls redone up to a late event, :meth:`late`) and ``late_redos_kept``
        (those kept up to an output before it, :meth:`kept_output`).
    events : list
        Records of the events so far that the result lists (e.g. lift-offs and touchdowns).
    """

    stat_keys: ClassVar[tuple] = ()
    counter_names: ClassVar[dict] = {}
    events: list

    @abstractmethod
    def attach(self, form, stats: dict) -> None:
        """Start afresh for a run of the formulation ``form``, counting in ``stats``."""

    @abstractmethod
    def mode(self) -> np.ndarray:
        """The DAE's parameters after the time offset (e.g. the open flags of releasable
        constraints): the parameter vector of a call is ``[t_a, *mode()]``."""

    @abstractmethod
    def open_rows(self) -> list:
        """The constraint rows released now (:meth:`symcat.dae.Formulation.open_rows`)."""

    @abstractmethod
    def start(self, x, z, atol) -> tuple[float, float]:
        """``(span, event)`` at the consistent initial state ``(x, z)``: the longest first call
        (s) and the predicted time (s) of the first event (``inf``: none); ``atol``: the
        absolute tolerances of the differential states."""

    @abstractmethod
    def check(self, x, z):
        """The handler's checks of the state ``(x, z)`` (opaque to the driver; passed back to
        :meth:`late`, :meth:`after`)."""

    @abstractmethod
    def after(self, x, z, t: float, checks=None) -> tuple:
        """``(x, z, changed, span, event)``: the state after the events due at ``(t, x, z)``
        (unchanged if none), the events' names (``changed``; the driver restarts IDAS without
        the last call's history when any), and the next call's limits (s) as for
        :meth:`start`. ``checks``: :meth:`check`'s at this state, if at hand."""

    @abstractmethod
    def recover(self, x, z, t: float, failures: int) -> tuple:
        """``(x, z, retry, span, event)`` after the call from ``(t, x, z)`` failed (the
        ``failures``-th in a row): ``retry`` if the handler changed the state (e.g. an event
        tried early), so that the call is retried from it at once; else the driver retries
        shorter."""

    @abstractmethod
    def overshoot(self, z0, offsets, xs, zs) -> float | None:
        """Time (s after the call's start) of the first event the call from the checked state
        (algebraic part ``z0``) passed unpredicted, from its states ``xs``, ``zs`` (columns)
        at ``offsets`` (s), or ``None``: the call is redone up to just before it."""

    @abstractmethod
    def late(self, checks_end, h: float, t: float) -> float | None:
        """Time (s after the call's start) of an event found late at the end of a call of
        ``h`` seconds from ``t`` (``checks_end``: :meth:`check`'s there), or ``None``."""

    @abstractmethod
    def kept_output(self, t: float, offsets, xs, zs, before: float):
        """``(column, checks)`` of the last output inside a call from ``t`` (at ``offsets``, s)
        up to which it may be kept instead of redone after :meth:`late` (at most ``before``
        seconds after its start), else ``None``."""

    @abstractmethod
    def verify(self, x, z) -> str | None:
        """Why the run cannot go on from the state ``(x, z)`` after :meth:`after`, if so (the
        driver raises it as a :class:`~symcat.errors.SolverError` with the time)."""

    @abstractmethod
    def stall_reason(self, exc, failures: int, span_s: float) -> str:
        """Why the driver stalled: ``failures`` calls failed within ``span_s`` seconds, the last
        with ``exc``."""

    @abstractmethod
    def failure_hint(self) -> str:
        """Text appended to the report of a call that failed at the shortest length (``""``)."""
