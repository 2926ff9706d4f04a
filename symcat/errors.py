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
