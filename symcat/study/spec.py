"""What a study varies: fixed values, grids and random parameters, parsed and checked against
the model's declared parameters before any work.

Grids are given as ``START:STOP:STEP`` (both ends included) or as a comma-separated list; random
parameters as ``normal:MEAN:SD`` or ``uniform:LOW:HIGH``. Every message names the option, the
text given and what is allowed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import ParameterError
from ..model import Model

#: The distributions of ``--random`` and what their two numbers are.
DISTRIBUTIONS = {"normal": ("MEAN", "SD"), "uniform": ("LOW", "HIGH")}
#: The most points a grid range may give (a mistyped step must not make a million runs).
MAX_GRID_POINTS = 100_000


@dataclass(frozen=True)
class RandomParameter:
    """A scalar parameter drawn independently for every sample.

    Parameters
    ----------
    name : str
        The model parameter (real-valued).
    distribution : str
        ``"normal"`` or ``"uniform"``.
    a, b : float
        Mean and standard deviation (normal), or lower and upper bound (uniform), in the
        parameter's unit.
    """

    name: str
    distribution: str
    a: float
    b: float

    def text(self) -> str:
        return f"{self.distribution}:{self.a:g}:{self.b:g}"


@dataclass
class StudySpec:
    """A checked study: the model, its fixed values, grids and random parameters.

    Attributes
    ----------
    model : Model
    model_ref : str
        How the model was named (a name, or a file's path), for the workers to load it.
    fixed : dict
        Parameter values of every run (validated).
    grids : dict
        Parameter name -> list of values (validated); the runs are their full factorial.
    randoms : list of RandomParameter
    samples : int
        Random samples at every grid point (1 without random inputs).
    seed : int
        Seed of the samples (and of the ``deviation_seed`` of each sample).
    """

    model: Model
    model_ref: str
    fixed: dict = field(default_factory=dict)
    grids: dict = field(default_factory=dict)
    randoms: list = field(default_factory=list)
    samples: int = 1
    seed: int = 0

    @property
    def seeds_deviations(self) -> bool:
        """Whether each sample gets its own ``deviation_seed`` (a catenary model that takes one,
        not given by the user)."""
        varied = set(self.fixed) | set(self.grids) | {r.name for r in self.randoms}
        return any(p.name == "deviation_seed" for p in self.model.parameters) and "deviation_seed" not in varied

    @property
    def swept(self) -> list[str]:
        """The parameters that vary from run to run (grids, then random ones)."""
        return list(self.grids) + [r.name for r in self.randoms]

    def signature(self) -> dict:
        """What identifies the study's runs (compared when a folder is resumed)."""
        return {"model": self.model.name, "set": {k: self.fixed[k] for k in sorted(self.fixed)},
                "grid": {k: list(v) for k, v in self.grids.items()},
                "random": {r.name: r.text() for r in self.randoms}, "samples": self.samples, "seed": self.seed}


def _number(option: str, item: str, text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ParameterError(f"{option} {item}: {what} {text.strip()!r} is not a finite number")
    return value


def _split(option: str, item: str, form: str) -> tuple[str, str]:
    name, eq, value = item.partition("=")
    if not eq or not name.strip() or not value.strip():
        raise ParameterError(f"{option} {item!r}: expected {form}")
    return name.strip(), value.strip()


def _parameter(model: Model, option: str, item: str, name: str):
    try:
        return model.parameter(name)
    except ParameterError as err:
        raise ParameterError(f"{option} {item}: {err}") from None


def parse_grid(model: Model, item: str) -> tuple[str, list]:
    """``name=START:STOP:STEP`` or ``name=V1,V2,...`` -> the parameter and its checked values."""
    form = "NAME=START:STOP:STEP (both ends included) or NAME=V1,V2,..."
    name, text = _split("--grid", item, form)
    p = _parameter(model, "--grid", item, name)
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise ParameterError(f"--grid {item}: a range is START:STOP:STEP (three numbers), got {text!r}")
        if p.kind not in (int, float):
            raise ParameterError(f"--grid {item}: {name} is not numeric ({p.allowed()}); give its values as V1,V2,...")
        start, stop, step = (_number("--grid", item, t, w) for t, w in zip(parts, ("START", "STOP", "STEP")))
        if not step > 0:
            raise ParameterError(f"--grid {item}: STEP={step:g} must be > 0")
        if start > stop:
            raise ParameterError(f"--grid {item}: empty range (START={start:g} > STOP={stop:g}); "
                                 "give START <= STOP")
        count = int(math.floor((stop - start) / step * (1 + 1e-12) + 1e-9)) + 1
        if count > MAX_GRID_POINTS:
            raise ParameterError(f"--grid {item}: {count} points; at most {MAX_GRID_POINTS} (check STEP)")
        raw = [float(f"{start + k * step:.12g}") for k in range(count)]
        try:
            values = [p.validate(int(v) if p.kind is int and v == int(v) else v) for v in raw]
        except ParameterError as err:
            raise ParameterError(f"--grid {item}: {err}") from None
    else:
        texts = [t.strip() for t in text.split(",")]
        if any(not t for t in texts):
            raise ParameterError(f"--grid {item}: an empty value in the list; give {form}")
        try:
            values = [p.parse(t) for t in texts]
        except ParameterError as err:
            raise ParameterError(f"--grid {item}: {err}") from None
    if len(set(map(repr, values))) != len(values):
        raise ParameterError(f"--grid {item}: a value is given twice; give each value once")
    return name, values


def parse_random(model: Model, item: str) -> RandomParameter:
    """``name=normal:MEAN:SD`` or ``name=uniform:LOW:HIGH`` -> a checked random parameter."""
    form = "NAME=normal:MEAN:SD or NAME=uniform:LOW:HIGH"
    name, text = _split("--random", item, form)
    p = _parameter(model, "--random", item, name)
    if p.kind is not float:
        raise ParameterError(f"--random {item}: {name} must be a real-valued parameter to be drawn at random "
                             f"({name} is {p.allowed()}); use --grid for it")
    parts = text.split(":")
    if parts[0] not in DISTRIBUTIONS:
        raise ParameterError(f"--random {item}: unknown distribution {parts[0]!r}; use {form}")
    names = DISTRIBUTIONS[parts[0]]
    if len(parts) != 3:
        raise ParameterError(f"--random {item}: {parts[0]} takes two numbers, {parts[0]}:{names[0]}:{names[1]}")
    a, b = (_number("--random", item, t, w) for t, w in zip(parts[1:], names))
    if parts[0] == "normal" and not b > 0:
        raise ParameterError(f"--random {item}: SD={b:g} must be > 0")
    if parts[0] == "uniform" and not a < b:
        raise ParameterError(f"--random {item}: LOW={a:g} must be below HIGH={b:g}")
    return RandomParameter(name, parts[0], a, b)


def _as_dict(option: str, items) -> list[str]:
    """Items of an option given as ``["name=text", ...]`` or as a dict ``{name: value}``."""
    if items is None:
        return []
    if isinstance(items, dict):
        out = []
        for k, v in items.items():
            if isinstance(v, (list, tuple)):
                v = ",".join(str(x) for x in v) if option == "--grid" else ":".join(str(x) for x in v)
            out.append(f"{k}={v}")
        return out
    return list(items)


def make_spec(model: Model, model_ref: str, fixed=None, grids=None, randoms=None, samples: int = 1,
              seed: int = 0) -> StudySpec:
    """Check a study's inputs against ``model``'s parameters (see :func:`symcat.study.run_study`).

    Raises
    ------
    ParameterError
        One line naming the option, the value and what is allowed.
    """
    values = {}
    for name, value in (fixed or {}).items():
        values[name] = model.resolve({name: value})[name]
    grid_values: dict[str, list] = {}
    for item in _as_dict("--grid", grids):
        name, vals = parse_grid(model, item)
        if name in grid_values or name in values:
            raise ParameterError(f"--grid {item}: {name} is given twice; give each parameter once")
        grid_values[name] = vals
    random_params = []
    for item in _as_dict("--random", randoms):
        r = parse_random(model, item)
        if r.name in grid_values or r.name in values or any(x.name == r.name for x in random_params):
            raise ParameterError(f"--random {item}: {r.name} is given twice; give each parameter once")
        random_params.append(r)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ParameterError(f"--samples {samples}: must be an integer >= 1")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise ParameterError(f"--seed {seed}: must be an integer >= 0")
    spec = StudySpec(model, model_ref, values, grid_values, random_params, samples, seed)
    if samples > 1 and not random_params and not spec.seeds_deviations:
        raise ParameterError(f"--samples {samples}: model {model.name!r} has nothing random to sample (no --random "
                             "and no deviation_seed); every sample would be the same run")
    return spec
