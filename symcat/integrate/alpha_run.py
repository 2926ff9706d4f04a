"""What a generalized-alpha run hands back (:mod:`.generalized_alpha`): the outputs of a run
(:class:`AlphaRun`, turned into the :class:`~.results.SimulationResult` every integrator gives)
and the states a per-step ``monitor`` sees (:class:`StepStates`)."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..dae.formulation import Formulation
from ..run_control import ended_early
from .results import SimulationResult, collect_result


@dataclass
class AlphaRun:
    """What :func:`integrate_alpha` computed: outputs in the augmented index-1 layout of
    ``form`` (``xs``, ``zs``, see :meth:`Formulation.blocks`), the integrator's own multipliers
    ``lambda_{n+1}`` (n_t, n_c) and statistics (``steps`` taken, halved ones included,
    ``newton_iterations``, ``factorizations``, ``rebuilds`` after element-window moves,
    ``halvings`` of failed steps, ``build_s`` the wall time spent building the step's functions,
    ``dt``, ``rho_inf``, ``variant``) and, where the run records them, the penalty contacts'
    gaps and normal forces at each output (``contacts``)."""

    form: Formulation
    t_s: np.ndarray
    xs: list
    zs: list
    multipliers: np.ndarray
    stats: dict = field(default_factory=dict)
    walls: list = field(default_factory=list)
    monitored: dict = field(default_factory=dict)
    modes: list | None = None  # an event handler's open flags at each output
    events: list = field(default_factory=list)
    contacts: list = field(default_factory=list)  # (gaps, forces) of the penalty contacts at each output

    def stopped(self, err, wall0: float, t_end: float) -> bool:
        """Close the run at its last output after the :class:`~symcat.errors.SolverError`
        ``err``, which then carries it as ``partial``; True if the user ended the run early
        (the caller returns the run), False if ``err`` is a failure (the caller raises it)."""
        self.stats["wall_s"] = time.perf_counter() - wall0
        self.multipliers = self.multipliers[: len(self.xs)]
        err.partial = self
        return ended_early(err, self.t_s[len(self.xs) - 1], t_end)

    def result(self, wall0: float | None = None, multipliers: str = "kkt") -> SimulationResult:
        """The :class:`SimulationResult` of these outputs (as :func:`simulate` returns it);
        ``multipliers`` as for :func:`generalized_alpha`."""
        n = len(self.xs)
        wall0 = time.perf_counter() - self.stats.get("wall_s", 0.0) if wall0 is None else wall0
        given = None
        if multipliers == "integrator":
            zb = self.form.blocks()[1]
            given = (np.asarray(self.zs, float).reshape(n, -1)[:, zb["a"].slice], self.multipliers[:n])
            if self.form.n_sc and len(self.contacts) >= n:  # no contacts evaluated over whole wires
                given += (tuple(np.array([c[k] for c in self.contacts[:n]], float) for k in range(2)),)
        modes = self.modes[:n] if self.modes is not None else [()] * n
        # a run whose steps were compiled has its terms compiled too (seconds once per model)
        res = collect_result(self.form, self.t_s[:n], self.xs, self.zs, self.stats, wall0, modes, self.events,
                             self.walls, given, compiled=self.stats.get("compiled_steps", 0) > 0)
        res.monitored = {key: np.concatenate(values) for key, values in self.monitored.items()}
        return res


@dataclass
class StepStates:
    """What a ``monitor`` of :func:`generalized_alpha` sees: the states after consecutive steps
    (SI units), each array's first axis the steps: times ``t_s`` (k,), all coordinates ``q``,
    velocities ``v`` and accelerations ``a`` (k, n_q: fixed ones included,
    ``model.coordinate_names()``), the sliding-joint arc lengths ``s_m``, the integrator's
    multipliers, and per penalty contact (``model.contacts``) the arc length ``sc_m``, normal
    gap ``gap_m`` (> 0 separated) and normal force ``force_N``. A batch, not one state: the
    compiled steps hand over the states of all the steps of a call at once, and a monitor
    evaluated over them as arrays costs a fraction of one called per step."""

    t_s: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    s_m: np.ndarray
    multipliers: np.ndarray
    sc_m: np.ndarray
    gap_m: np.ndarray
    force_N: np.ndarray

    def __len__(self) -> int:
        return len(self.t_s)

    @classmethod
    def stacked(cls, parts: list["StepStates"]) -> "StepStates":
        """The states of ``parts`` (consecutive batches) as one batch."""
        if len(parts) == 1:
            return parts[0]
        return cls(*(np.concatenate([getattr(p, name) for p in parts]) for name in cls.__dataclass_fields__))
