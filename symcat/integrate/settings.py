"""The tuning of an IDAS run (:func:`symcat.integrate.simulate`) as one checked object.

:func:`~symcat.integrate.simulate` took these as seventeen keywords, passed on through the
models and :func:`symcat.simulation.integrate_model`; as :class:`IdasSettings` they are checked
once, where they are made (one line naming the field, the value and what is allowed), and a
model builds one from its parameters. The old keywords still work: :func:`settings_from`
builds the object from them and refuses a name that is not a field, listing the fields.
"""
from __future__ import annotations

import dataclasses
import numbers
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..errors import ParameterError

#: The models' default velocity tolerance (m/s, rad/s) as a multiple of their position tolerance
#: (m, rad): positions accurate to atol over motions up to 10 rad/s (``simulate``'s own default
#: is ``atol`` itself).
VELOCITY_ATOL_FACTOR = 10.0


@dataclass(frozen=True)
class IdasSettings:
    """How :func:`~symcat.integrate.simulate` integrates: tolerances, the equations' form,
    IDAS's solver and the output.

    Parameters
    ----------
    rtol : float
        IDAS's relative tolerance (differential states only), in (0, 1).
    atol : float or ndarray
        IDAS's absolute tolerance of the positions (m, rad), > 0; or an array over all
        generalized coordinates (``model.coordinate_names()``), used for the coordinates and
        their velocities (e.g. looser on the stiff cross-section gradients of a thin beam).
    velocity_atol : float or ndarray, optional
        Absolute tolerance of the velocities (m/s, rad/s), a number or an array like ``atol``;
        default ``atol``. Positions accurate to ``atol`` over a motion of angular frequency
        ``omega`` need velocities accurate only to ``omega * atol``: on the seed vehicle,
        ``10 * atol`` (:data:`VELOCITY_ATOL_FACTOR`) takes a quarter to a half fewer steps and
        removes the error-test failures of its stiff creep modes at rtol 1e-5.
    algebraic_atol : float
        Absolute tolerance of the algebraic variables (accelerations m/s^2, multipliers N) in
        IDAS's Newton test (they are not error-controlled), > 0.
    baumgarte : float
        Stabilization (1/s) of the index-1 forms, >= 0.
    cholesky : bool
        Cholesky coordinates for the ANCF bodies (see :class:`symcat.dae.Formulation`).
    linear_solver : str, optional
        CasADi linear solver plugin for IDAS's Newton systems: ``csparse`` (sparse LU, 1.6x
        faster than CasADi's default ``qr`` on a 32-element wire), ``qr`` (sparse QR) or
        ``lapacklu`` (dense LU). Default: ``csparse`` at index 1, ``qr`` for GGL, whose
        ill-conditioned index-2 matrices make the LU's pivoting fail (IDA_LSETUP_FAIL); a run
        whose QR call fails goes on with ``csparse`` (QR has failed to start at tight
        tolerances where LU integrates; ``stats["linear_solver_fallbacks"]``).
    compiled : bool, optional
        Compile the whole DAE residual and its Jacobian to C for this model
        (:mod:`symcat.codegen.model_dae`; about 10 s for the seed vehicle the first time, then
        cached), instead of evaluating CasADi's graph over the kernels. Default: for wheel/rail
        models in the augmented form without element windows (those rebuild their DAE as the
        windows move; the embedded form's linear solve does not expand, and a request for it
        falls back to the graph with a warning).
    max_step : float, optional
        Largest IDAS step (s), > 0; ``None`` (or 0): IDAS's own.
    max_steps : int
        IDAS steps allowed per integrator call, >= 1 (event handlers may cap their calls lower,
        e.g. the wheel/rail contact driver at
        :data:`~symcat.integrate.event_stepping.MAX_CALL_STEPS`).
    n_out : int
        Output intervals, >= 1.
    chunks : int, optional
        Integrator calls the run is split into, >= 1 (default, ``None`` or 0: adaptive, about
        10, shorter while a sliding point would otherwise leave its element window).
    progress : bool
        Show a progress bar on stderr.
    """

    # Tolerances
    rtol: float = 1e-6
    atol: float | np.ndarray = 1e-8
    velocity_atol: float | np.ndarray | None = None
    algebraic_atol: float = 1e-3
    # The equations' form
    baumgarte: float = 10.0
    cholesky: bool = False
    # IDAS's solver
    linear_solver: str | None = None
    compiled: bool | None = None
    max_step: float | None = None
    max_steps: int = 500000
    # Output and progress
    n_out: int = 200
    chunks: int | None = None
    progress: bool = True

    def __post_init__(self):
        if not (_real(self.rtol) and 0 < self.rtol < 1):
            raise ParameterError(f"rtol={self.rtol!r}: must be in (0, 1)")
        for name in ("atol", "velocity_atol"):
            value = getattr(self, name)
            if value is None and name == "velocity_atol":
                continue
            per = np.atleast_1d(np.asarray(value, dtype=float)) if _numeric(value) else None
            if per is None or per.size == 0 or not np.all(np.isfinite(per) & (per > 0)):
                raise ParameterError(f"{name}={value!r}: must be > 0 (m, rad; m/s, rad/s for the velocities), "
                                     "a number or one per coordinate")
        if not (_real(self.algebraic_atol) and self.algebraic_atol > 0):
            raise ParameterError(f"algebraic_atol={self.algebraic_atol!r}: must be a number > 0")
        if not (_real(self.baumgarte) and self.baumgarte >= 0):
            raise ParameterError(f"baumgarte={self.baumgarte!r}: must be a number >= 0 (1/s)")
        for name in ("cholesky", "progress"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise ParameterError(f"{name}={getattr(self, name)!r}: must be True or False")
        if self.compiled is not None and not isinstance(self.compiled, (bool, np.bool_)):
            raise ParameterError(f"compiled={self.compiled!r}: must be True, False or None (automatic)")
        if self.linear_solver is not None and not (isinstance(self.linear_solver, str)
                                                   and ca.has_linsol(self.linear_solver)):
            raise ParameterError(f"linear_solver={self.linear_solver!r}: must be a CasADi linear solver plugin "
                                 "(csparse, qr, lapacklu, ...) or None (automatic)")
        if self.max_step is not None and not (_real(self.max_step) and self.max_step >= 0):
            raise ParameterError(f"max_step={self.max_step!r}: must be a number > 0 (s), or None (IDAS's own)")
        for name, least in (("max_steps", 1), ("n_out", 1)):
            value = getattr(self, name)
            if not (_integral(value) and value >= least):
                raise ParameterError(f"{name}={value!r}: must be an integer >= {least}")
        if self.chunks is not None and not (_integral(self.chunks) and self.chunks >= 0):
            raise ParameterError(f"chunks={self.chunks!r}: must be an integer >= 1, or None (adaptive)")


def _real(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool) and bool(np.isfinite(value))


def _integral(value) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _numeric(value) -> bool:
    try:
        np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return not isinstance(value, (bool, str))


#: The names :func:`settings_from` accepts (the fields of :class:`IdasSettings`).
FIELDS = tuple(f.name for f in dataclasses.fields(IdasSettings))


def settings_from(settings: IdasSettings | None = None, **keywords) -> IdasSettings:
    """``settings`` (default :class:`IdasSettings`) with the fields given as ``keywords``
    replaced: the compatibility path of the old keyword arguments of
    :func:`~symcat.integrate.simulate`.

    Raises
    ------
    ParameterError
        A keyword that is not a field (naming it and listing the fields), or a value a field
        does not allow.
    """
    unknown = [k for k in keywords if k not in FIELDS]
    if unknown:
        raise ParameterError(f"{', '.join(unknown)}: not an IDAS setting (allowed: {', '.join(FIELDS)})")
    if settings is None:
        return IdasSettings(**keywords)
    if not isinstance(settings, IdasSettings):
        raise ParameterError(f"settings={settings!r}: must be an IdasSettings or None")
    return dataclasses.replace(settings, **keywords) if keywords else settings
