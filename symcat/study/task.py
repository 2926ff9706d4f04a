"""One run of a study, as a worker executes it: never raises, returns the run's row.

The worker loads the model once per process (by name or path, as ``symcat run`` does) and runs
it with :func:`symcat.model.run_model`, so a study's run computes exactly what ``symcat run``
with the same parameters computes. Compiled kernels come from the shared on-disk cache.
"""
from __future__ import annotations

import os
import socket
import time

#: Models loaded by this worker process, by how they were named.
_MODELS: dict = {}
#: Longest error message kept in a row (characters).
MAX_ERROR = 500


def flatten(summary: dict, prefix: str = "") -> dict:
    """The scalar entries of a summary (numbers, booleans, text, None), nested dicts joined by
    ``"."`` (``"pantograph_1.contact_force_mean_N"``); lists and arrays are left out."""
    out = {}
    for key, value in summary.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten(value, name + "."))
        elif value is None or isinstance(value, (bool, int, float, str)):
            out[name] = value
        elif hasattr(value, "item") and getattr(value, "ndim", 1) == 0:  # a NumPy scalar
            out[name] = value.item()
    return out


def _line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    line = text[0] if text else ""
    line = f"{type(err).__name__}: {line}" if not line or not _is_symcat(err) else line
    return line[:MAX_ERROR]


def _is_symcat(err: BaseException) -> bool:
    from ..errors import SymcatError

    return isinstance(err, SymcatError)


def run_one(model_ref: str, params: dict, out: str | None = None) -> dict:
    """Run ``model_ref`` with ``params``; the row of the run.

    Returns
    -------
    dict
        ``status`` (``"ok"`` or ``"failed"``), ``error`` (one line, ``""`` if none),
        ``summary`` (the flattened scalar summary; what was computed for a run stopped by its
        solver), ``run_wall_s`` (s, the whole run on the worker, model loading included),
        ``run_cpu_s`` (s, the CPU time of the worker's process meanwhile: on a machine shared
        with other work it tells the run's cost apart from its waiting) and ``worker`` (host:pid).
    """
    from ..errors import RunStopped
    from ..model import load_model, run_model

    t0, cpu0 = time.perf_counter(), time.process_time()
    row = {"status": "ok", "error": "", "summary": {}}
    try:
        model = _MODELS.get(model_ref)
        if model is None:
            model = _MODELS[model_ref] = load_model(model_ref)
        result = run_model(model, params, out=out)
        row["summary"] = flatten(result.summary)
    except RunStopped as stop:  # the reason, without run_model's pointer to where the partial results are
        row.update(status="failed", error=_line(stop))
        if stop.partial is not None:
            row["summary"] = flatten(stop.partial.summary)
            reason = (stop.partial.summary.get("stopped") or {}).get("reason")
            if reason:
                row["error"] = str(reason).strip().splitlines()[0][:MAX_ERROR]
    except Exception as err:  # a failed run is a row with its error; the study goes on
        row.update(status="failed", error=_line(err))
    row["run_wall_s"] = time.perf_counter() - t0
    row["run_cpu_s"] = time.process_time() - cpu0
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return row
