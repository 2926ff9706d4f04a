"""The runs of a study: the full factorial of the grids times the random samples.

Sample ``k`` has the same random values (and ``deviation_seed``) at every grid point, so grid
points are compared on the same samples (common random numbers). The random values and the
deviation seeds come from two independent children of ``numpy.random.SeedSequence(seed)``: the
same seed gives the same runs, whatever the workers or their order.
"""
from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import dataclass

import numpy as np

from .spec import StudySpec

#: The largest ``deviation_seed`` (as :data:`symcat.catenary.deviations.MAX_SEED`, without
#: importing the catenary code for models that have none).
MAX_DEVIATION_SEED = 2**31 - 1


@dataclass(frozen=True)
class Run:
    """One run of a study.

    Attributes
    ----------
    index : int
        Position in the study (grid point major, sample minor).
    grid_point, sample : int
        Which grid point and which random sample.
    params : dict
        The parameter values given to the model (fixed, grid, random, deviation seed).
    run_id : str
        A digest of the model and ``params``: a resumed study recognizes the run by it.
    """

    index: int
    grid_point: int
    sample: int
    params: dict
    run_id: str


def run_id(model: str, params: dict) -> str:
    """A short digest identifying a run of ``model`` with ``params``."""
    text = json.dumps({"model": model, "params": {k: params[k] for k in sorted(params)}}, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def draw_samples(spec: StudySpec) -> tuple[dict, list[int] | None]:
    """The random values (name -> array of ``samples``) and the deviation seeds (or None)."""
    values_seq, deviation_seq = np.random.SeedSequence(spec.seed).spawn(2)
    rng = np.random.default_rng(values_seq)
    values = {}
    for r in spec.randoms:
        if r.distribution == "normal":
            values[r.name] = rng.normal(r.a, r.b, spec.samples)
        else:
            values[r.name] = rng.uniform(r.a, r.b, spec.samples)
    seeds = None
    if spec.seeds_deviations:
        seeds = [int(s) for s in np.random.default_rng(deviation_seq).integers(0, MAX_DEVIATION_SEED + 1, spec.samples)]
    return values, seeds


def study_runs(spec: StudySpec) -> list[Run]:
    """Every run of ``spec`` in order."""
    random_values, seeds = draw_samples(spec)
    names = list(spec.grids)
    points = list(itertools.product(*(spec.grids[n] for n in names)))
    runs = []
    for g, point in enumerate(points):
        for k in range(spec.samples):
            params = dict(spec.fixed)
            params.update(zip(names, point))
            params.update({name: float(v[k]) for name, v in random_values.items()})
            if seeds is not None:
                params["deviation_seed"] = seeds[k]
            runs.append(Run(len(runs), g, k, params, run_id(spec.model.name, params)))
    return runs
