"""Exceptions with messages meant for the user."""


class SymcatError(Exception):
    """Base class: the message alone tells the user what went wrong."""


class ParameterError(SymcatError, ValueError):
    """A parameter value outside what is allowed (the message names it)."""


class CompilerError(SymcatError):
    """The C compiler is missing or failed."""


class SolverError(SymcatError):
    """A solver did not converge; ``partial`` keeps what was computed."""

    def __init__(self, message: str, partial=None):
        super().__init__(message)
        self.partial = partial


class RunStopped(SolverError):
    """A model run ended before its end (a solver failure, or the user's Ctrl-C).

    ``partial`` is the :class:`symcat.model.RunResult` of what was computed (summarized and
    written like a complete run, its summary marked ``"complete": false``); ``interrupted``
    tells a Ctrl-C from a failure.
    """

    def __init__(self, message: str, partial=None, interrupted: bool = False):
        super().__init__(message, partial)
        self.interrupted = interrupted
