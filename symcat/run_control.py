"""How a run ends when it cannot finish: a solver failure or an interrupt (Ctrl-C).

Inside :func:`keeping_partial_results` (what :func:`symcat.model.run_model` runs a model in),
an integrator that fails or is interrupted records an :class:`EarlyStop` and *returns* the
result computed so far instead of raising, so the model summarizes and writes it as it would a
complete one, and the run is then reported as incomplete. Outside it (a direct call of an
integrator) a failure raises :class:`~symcat.errors.SolverError` with ``.partial`` as before.

Ctrl-C: the command line installs :func:`install_interrupt_handler`. While a time integration
runs (:func:`integrating`), the first Ctrl-C only asks it to stop at its next output or step
(:func:`check_interrupt`), so that what it computed is kept; outside an integration, and at a
second Ctrl-C, it raises :class:`KeyboardInterrupt` at once.
"""
from __future__ import annotations

import signal
from contextlib import contextmanager
from dataclasses import dataclass

from .errors import SolverError


@dataclass
class EarlyStop:
    """Why and when a time integration ended before its end time.

    Attributes
    ----------
    t_s : float or None
        Time reached (s); None if the run stopped before any time integration.
    t_end_s : float or None
        The end time asked for (s).
    reason : str
        One line.
    interrupted : bool
        By the user (Ctrl-C) rather than by a solver failure.
    """

    t_s: float | None
    t_end_s: float | None
    reason: str
    interrupted: bool

    def line(self) -> str:
        """The one line a user reads."""
        if self.interrupted and self.t_s is not None:
            return f"interrupted at t = {self.t_s:.6g} s of {self.t_end_s:.6g} s"
        return self.reason


class Interrupted(SolverError):
    """The user asked a time integration to stop (Ctrl-C); ``partial`` as for a failure."""

    def __init__(self, t_s: float, t_end_s: float):
        super().__init__(f"interrupted at t = {t_s:.6g} s of {t_end_s:.6g} s")
        self.t_s, self.t_end_s = t_s, t_end_s


class _State:
    keep_partial = 0    # depth of keeping_partial_results()
    integrating = 0     # depth of integrating()
    integrated = 0      # integrations finished in this run
    requested = False   # Ctrl-C seen during an integration
    stop: EarlyStop | None = None


_STATE = _State()


@contextmanager
def keeping_partial_results():
    """Run a model so that its integrators return partial results; yields a function that
    gives the :class:`EarlyStop` recorded (or None)."""
    _STATE.keep_partial += 1
    outer = _STATE.stop, _STATE.requested, _STATE.integrated
    _STATE.stop, _STATE.requested, _STATE.integrated = None, False, 0
    try:
        yield lambda: _STATE.stop
    finally:
        _STATE.keep_partial -= 1
        _STATE.stop, _STATE.requested, _STATE.integrated = outer


@contextmanager
def integrating():
    """Mark a time integration: a Ctrl-C meanwhile asks it to stop at its next
    :func:`check_interrupt` instead of raising where the program happens to be."""
    _STATE.integrating += 1
    try:
        yield
    finally:
        _STATE.integrating -= 1
        _STATE.integrated += 1


def check_interrupt(t_s: float, t_end_s: float) -> None:
    """Called by integrators after each output or step.

    Raises
    ------
    Interrupted
        If the user asked to stop, or an earlier integration of this run already stopped.
    """
    if _STATE.requested or (_STATE.keep_partial and _STATE.stop is not None):
        raise Interrupted(t_s, t_end_s)


def ended_early(error: SolverError, t_s: float, t_end_s: float) -> bool:
    """Record that an integration ended at ``t_s`` with ``error`` (its partial result in
    ``error.partial``). True if the caller should return that partial result (inside
    :func:`keeping_partial_results`), False if it should raise ``error``."""
    if not _STATE.keep_partial:
        return False
    if _STATE.stop is None:
        interrupted = isinstance(error, Interrupted)
        reason = error.reason.strip().splitlines()[0] if error.reason.strip() else type(error).__name__
        _STATE.stop = EarlyStop(t_s, t_end_s, reason, interrupted)
    return True


def record_stop(stop: EarlyStop) -> None:
    """Record a stop outside an integrator (an interrupt or a failure during set-up)."""
    if _STATE.stop is None:
        _STATE.stop = stop


def interrupted_outside_integration() -> EarlyStop:
    """The stop of a Ctrl-C that came outside any time integration (set-up or summary)."""
    if _STATE.integrated:
        return EarlyStop(None, None, "interrupted after the time integration, while its results were summarized "
                         "(they are lost; only this summary is written)", True)
    return EarlyStop(None, None, "interrupted before the time integration started", True)


def _on_sigint(signum, frame):
    if _STATE.integrating and not _STATE.requested:
        _STATE.requested = True
        return
    raise KeyboardInterrupt


def install_interrupt_handler() -> None:
    """Ctrl-C as described in the module docstring (the command line calls this)."""
    signal.signal(signal.SIGINT, _on_sigint)
