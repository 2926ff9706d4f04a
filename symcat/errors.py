"""Exceptions with messages meant for the user."""


class SymcatError(Exception):
    """Base class: the message alone tells the user what went wrong."""


class ParameterError(SymcatError, ValueError):
    """A parameter value outside what is allowed (the message names it)."""


class CompilerError(SymcatError):
    """The C compiler is missing or failed."""


class SolverError(SymcatError):
    """A solver did not converge; ``partial`` keeps what was computed (the message says so
    while it is set)."""

    #: Appended to the message while ``partial`` holds a result.
    partial_hint = "; the results so far are in .partial"

    def __init__(self, message: str, partial=None):
        super().__init__(message)
        self.partial = partial

    @property
    def reason(self) -> str:
        """The message without the pointer to ``partial``."""
        return str(self.args[0]) if self.args else ""

    def __str__(self) -> str:
        return self.reason + (self.partial_hint if self.partial is not None else "")


class RunStopped(SolverError):
    """A model run ended before its end (a solver failure, or the user's Ctrl-C).

    ``partial`` is the :class:`symcat.model.RunResult` of what was computed (summarized and
    written like a complete run, its summary marked ``"complete": false``); ``interrupted``
    tells a Ctrl-C from a failure.
    """

    partial_hint = ""  # the message says where the results are

    def __init__(self, message: str, partial=None, interrupted: bool = False):
        super().__init__(message, partial)
        self.interrupted = interrupted
