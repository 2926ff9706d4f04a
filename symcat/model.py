"""Runnable models: declared parameters (defaults, units, ranges), a run function, a summary.

A model file under ``models/`` defines ``MODEL = Model(...)``. :func:`run_model` (and the
``symcat run`` command) finds it by name or path, validates the parameters, runs it and
returns a :class:`RunResult` whose ``summary`` holds the model's named outputs plus
``wall_s`` and the solver statistics.
"""
from __future__ import annotations

import importlib.util
import logging
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from .errors import ParameterError, RunStopped, SolverError, SymcatError

PACKAGE_DIR = Path(__file__).resolve().parent

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Parameter:
    """A model parameter.

    Parameters
    ----------
    name : str
        Name used with ``--set name=value``.
    default : float, int, str or bool
        Default value; its type is the parameter's type.
    unit : str
        SI unit ("-" for dimensionless, "" for choices).
    doc : str
        What it means.
    minimum, maximum : float, optional
        Allowed range; ``exclusive_minimum`` makes the lower bound strict (e.g. a length > 0).
    choices : tuple of str, optional
        Allowed values of a string parameter.
    text : str, optional
        What a free-text parameter (a list, a file name) must be, for the help and errors,
        e.g. "three comma-separated numbers >= 0".
    check : callable, optional
        ``check(name, value)`` raises :class:`ParameterError` for a value of the right type that is
        not allowed (e.g. a file that does not exist): run with the other checks, before any
        work.
    """

    name: str
    default: Any
    unit: str
    doc: str
    minimum: float | None = None
    maximum: float | None = None
    exclusive_minimum: bool = False
    choices: tuple[str, ...] | None = None
    text: str | None = None
    check: Callable[[Any], None] | None = field(default=None, compare=False, repr=False)

    @property
    def kind(self) -> type:
        return type(self.default)

    def allowed(self) -> str:
        if self.choices:
            return "one of " + ", ".join(self.choices)
        if self.kind is bool:
            return "true or false"
        if self.kind is str:
            return self.text or "text"
        lo = "" if self.minimum is None else (f"> {self.minimum:g}" if self.exclusive_minimum else f">= {self.minimum:g}")
        hi = "" if self.maximum is None else f"<= {self.maximum:g}"
        rng = " and ".join(x for x in (lo, hi) if x)
        what = "an integer" if self.kind is int else "a number"
        return f"{what} {rng}".strip()

    def _reject(self, value) -> ParameterError:
        unit = f" {self.unit}" if self.unit not in ("", "-") else ""
        shown = f"{value:g}" if isinstance(value, float) else value
        return ParameterError(f"{self.name}={shown}{unit}: must be {self.allowed()}")

    def parse(self, text: str):
        """Convert command-line text to the parameter's type and validate it."""
        if self.kind is bool:
            low = str(text).strip().lower()
            if low in ("1", "true", "yes", "on"):
                return True
            if low in ("0", "false", "no", "off"):
                return False
            raise self._reject(text)
        if self.kind in (int, float):
            try:
                value = float(text)
            except ValueError:
                raise self._reject(text) from None
            if not math.isfinite(value):
                raise self._reject(text)
            if self.kind is int:
                if value != int(value):
                    raise self._reject(text)
                value = int(value)
            return self.validate(value)
        return self.validate(str(text))

    def validate(self, value):
        """Check a Python value against type, range and choices; return it."""
        if self.choices is not None:
            if value not in self.choices:
                raise self._reject(value)
            return value
        if self.kind is str:
            if not isinstance(value, str):
                raise self._reject(value)
            if self.check is not None:
                self.check(self.name, value)
            return value
        if self.kind in (int, float):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise self._reject(value)
            if self.kind is int and value != int(value):
                raise self._reject(value)
            if self.minimum is not None and (value < self.minimum or (self.exclusive_minimum and value <= self.minimum)):
                raise self._reject(value)
            if self.maximum is not None and value > self.maximum:
                raise self._reject(value)
            return self.kind(value)
        if self.kind is bool and not isinstance(value, bool):
            raise self._reject(value)
        return value


def comma_numbers(text: str, name: str = "value", count: int | None = None, minimum: float | None = None) -> tuple:
    """The finite numbers of a comma-separated list (``count`` of them, each ``>= minimum``).

    Raises
    ------
    ParameterError
        Naming ``name``, the text and what is allowed.
    """
    need = (f"{count} " if count else "") + "comma-separated finite numbers" + (f" >= {minimum:g}" if minimum is not None else "")
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise ParameterError(f"{name}={text!r}: must be {need}") from None
    if (not all(math.isfinite(v) for v in values) or (count is not None and len(values) != count)
            or (minimum is not None and any(v < minimum for v in values))):
        raise ParameterError(f"{name}={text!r}: must be {need}")
    return values


def numbers_check(count: int | None = None, minimum: float | None = None, empty: bool = False):
    """A :attr:`Parameter.check` for a comma-separated list of numbers (``empty``: "" allowed)."""
    def check(name: str, text: str) -> None:
        if not (empty and not text.strip()):
            comma_numbers(text, name, count, minimum)
    return check


def existing_file(name: str, text: str) -> None:
    """A :attr:`Parameter.check` for the path of a file to read ("" for none)."""
    if text and not Path(text).is_file():
        raise ParameterError(f"{name}={text!r}: no such file (give the path of a file to read, or nothing)")


@dataclass
class ModelOutput:
    """What a model's run function returns.

    Attributes
    ----------
    summary : dict
        Named outputs (JSON-serializable), units in the names.
    stats : dict
        Solver statistics.
    arrays : dict
        Named arrays for further use (units in the names).
    writer : callable, optional
        ``writer(out_dir)`` writes plots and ParaView files.
    """

    summary: dict
    stats: dict = field(default_factory=dict)
    arrays: dict = field(default_factory=dict)
    writer: Callable[[Path], list] | None = None


@dataclass
class Model:
    """A runnable model: parameters and a run function ``run(params: dict) -> ModelOutput``."""

    name: str
    description: str
    parameters: list[Parameter]
    run: Callable[[dict], ModelOutput]

    def parameter(self, name: str) -> Parameter:
        for p in self.parameters:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in self.parameters)
        raise ParameterError(f"{name}: not a parameter of model {self.name!r} (parameters: {known})")

    def resolve(self, values: dict | None) -> dict:
        """Defaults overridden by ``values`` (validated; strings are parsed as on the command
        line)."""
        params = {p.name: p.default for p in self.parameters}
        for name, value in (values or {}).items():
            p = self.parameter(name)
            params[name] = p.parse(value) if isinstance(value, str) and p.kind is not str else p.validate(value)
        return params

    def help(self) -> str:
        lines = [f"{self.name}: {self.description}", "", "parameters (--set name=value):"]
        for p in self.parameters:
            unit = f" [{p.unit}]" if p.unit else ""
            lines.append(f"  {p.name}{unit} = {p.default!r}  ({p.allowed()})")
            lines.append(f"      {p.doc}")
        return "\n".join(lines)


@dataclass
class RunResult:
    """Result of :func:`run_model`: ``summary`` (outputs + ``wall_s`` + ``stats``), arrays, files."""

    model: str
    params: dict
    summary: dict
    arrays: dict
    files: list


def shipped_models_dir() -> Path:
    """The models that ship with symcat: ``symcat/_models`` of an installed package (see
    ``pyproject.toml``), else ``models/`` of the source tree."""
    installed = PACKAGE_DIR / "_models"
    return installed if installed.is_dir() else PACKAGE_DIR.parent / "models"


def models_dirs() -> list[Path]:
    """Where models are found by name: the folders of ``$SYMCAT_MODELS`` (separated by
    ``os.pathsep``), then the shipped models. The working directory is not searched (a file
    there must not silently replace a shipped model): run a model of your own by its path."""
    user = [Path(d) for d in os.environ.get("SYMCAT_MODELS", "").split(os.pathsep) if d]
    return user + [shipped_models_dir()]


def available_models() -> list[str]:
    names = set()
    for d in models_dirs():
        if d.is_dir():
            names.update(p.stem for p in d.glob("*.py") if not p.name.startswith("_"))
    return sorted(names)


def describe_models() -> dict[str, str]:
    """One line of description per model by name, read from each file's ``MODEL = Model(name,
    description, ...)`` without running it (listing the models imports none of them)."""
    import ast

    out = {}
    for name in available_models():
        path = model_path(name, warn=False)
        text = ""
        try:
            tree = ast.parse(path.read_text())
            for node in tree.body:
                if (isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "MODEL" for t in node.targets)
                        and isinstance(node.value, ast.Call) and len(node.value.args) >= 2):
                    text = ast.literal_eval(node.value.args[1])
            text = text or (ast.get_docstring(tree) or "").strip().splitlines()[0]
        except (OSError, SyntaxError, ValueError, IndexError):
            text = "(its file could not be read)"
        out[name] = " ".join(str(text).split())
    return out


def model_path(name_or_path: str, warn: bool = True) -> Path:
    """The file of a model given by name or path.

    A name found both in ``$SYMCAT_MODELS`` and among the shipped models resolves to the
    user's file, with a warning naming both.
    """
    path = Path(name_or_path)
    if path.suffix == ".py" or os.sep in name_or_path:
        if not path.is_file():
            raise ParameterError(f"model={name_or_path!r}: no such file")
        return path
    found = [d / f"{name_or_path}.py" for d in models_dirs() if (d / f"{name_or_path}.py").is_file()]
    if not found:
        known = ", ".join(available_models()) or "none found"
        raise ParameterError(f"model={name_or_path!r}: no such model (available: {known})")
    shipped = shipped_models_dir() / f"{name_or_path}.py"
    if warn and found[0] != shipped and shipped.is_file():
        log.warning("model %s: running %s, which shadows the shipped model %s (SYMCAT_MODELS)",
                    name_or_path, found[0], shipped)
    return found[0]


def load_model(name_or_path: str) -> Model:
    """Find a model by name (``models/<name>.py``, see :func:`models_dirs`) or by file path."""
    path = model_path(name_or_path)
    spec = importlib.util.spec_from_file_location(f"symcat_model_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    model = getattr(module, "MODEL", None)
    if not isinstance(model, Model):
        raise SymcatError(f"{path}: defines no MODEL = symcat.model.Model(...)")
    return model


def run_model(model: str | Model, params: dict | None = None, out: str | Path | None = None,
              summary_path: str | Path | None = None, labels: tuple[str, str] = ("out", "summary_path")) -> RunResult:
    """Run a model.

    Parameters, then ``out`` and ``summary_path``, are checked before any work. If the run's
    time integration fails or is interrupted (Ctrl-C, see :mod:`symcat.run_control`), what was
    computed up to then is summarized and written like a complete run, with
    ``summary["complete"] = False`` and ``summary["stopped"]`` (time, end time, reason), and
    :class:`~symcat.errors.RunStopped` is raised carrying that :class:`RunResult`.

    Parameters
    ----------
    model : str or Model
        Model name (file under ``models/``), path, or object.
    params : dict, optional
        Parameter values (strings are parsed as on the command line).
    out : path, optional
        Folder for plots, ParaView files and ``summary.json`` (created if missing). The files
        an earlier run wrote there are removed first; other files are kept.
    summary_path : path, optional
        Where to write the summary JSON.
    labels : tuple of str
        How ``out`` and ``summary_path`` are named in error messages.

    Raises
    ------
    ParameterError
        A parameter or path that is not allowed (nothing is written).
    RunStopped
        The run ended early; ``.partial`` is the result so far.
    """
    from .run_control import EarlyStop, interrupted_outside_integration, keeping_partial_results, record_stop
    from .run_output import SUMMARY_NAME, OutputPaths, write_json

    m = load_model(model) if isinstance(model, str) else model
    values = m.resolve(params)
    paths = OutputPaths(out, summary_path, labels)
    t0 = time.perf_counter()
    output = None
    with keeping_partial_results() as recorded_stop:
        try:
            output = m.run(values)
        except ParameterError:
            paths.discard()
            raise
        except KeyboardInterrupt:
            record_stop(interrupted_outside_integration())
        except SolverError as err:  # before the time integration (statics, form finding)
            record_stop(EarlyStop(None, None, (err.reason.strip().splitlines() or [type(err).__name__])[0], False))
        except SymcatError:
            paths.discard()
            raise
        stop = recorded_stop()
    wall = time.perf_counter() - t0
    summary = dict(output.summary) if output is not None else {}
    summary["wall_s"] = wall
    summary["stats"] = output.stats if output is not None else {}
    summary["complete"] = stop is None
    if stop is not None:
        summary["stopped"] = {"t_s": stop.t_s, "t_end_s": stop.t_end_s, "reason": stop.line(),
                              "interrupted": stop.interrupted}
    files = []
    if paths.out is not None:
        paths.clear_previous_run()
        if output is not None and output.writer is not None:
            try:
                files += [str(f) for f in output.writer(paths.out)]
            except KeyboardInterrupt:
                stop = stop or EarlyStop(None, None, "interrupted while writing the outputs", True)
                summary["complete"] = False
                summary["stopped"] = {"t_s": stop.t_s, "t_end_s": stop.t_end_s, "reason": stop.line(),
                                      "interrupted": True}
        listed = [os.path.relpath(f, paths.out) for f in files]
        write_json(paths.out / SUMMARY_NAME, {"model": m.name, "parameters": values, **summary, "files": listed},
                   _jsonable)
        files.append(str(paths.out / SUMMARY_NAME))
    if paths.summary is not None:
        write_json(paths.summary, summary, _jsonable)
    result = RunResult(m.name, values, summary, output.arrays if output is not None else {}, files)
    if stop is not None:
        where = paths.out or paths.summary
        kept = f"; the results so far are in {where}" if where is not None else "; the results so far are in .partial"
        raise RunStopped(stop.line() + kept, result, stop.interrupted)
    return result


def _jsonable(x):
    try:
        import numpy as np

        if isinstance(x, np.ndarray):
            return x.tolist()
        if isinstance(x, np.generic):
            return x.item()
    except ImportError:  # pragma: no cover
        pass
    raise TypeError(f"not JSON serializable: {type(x).__name__}")
