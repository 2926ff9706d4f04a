"""Studies: parameter sweeps and Monte Carlo samples of any model, run on Dask.

``symcat.study("taut_wire", grid={"tension": "18000:22000:2000"}, out="study")`` (or the
command ``symcat study``) runs a model over the full factorial of its grids times ``samples``
random samples, on a local cluster of single-threaded worker processes or on an existing Dask
cluster, and returns (and writes to ``out``) one row per run. The modules: :mod:`.spec` (the
inputs, checked), :mod:`.sampling` (the runs), :mod:`.task` (one run on a worker),
:mod:`.runner` (the cluster, retries, progress), :mod:`.table` (the folder, resume, Parquet),
:mod:`.plots`.

The package is callable: ``symcat.study(...)`` is :func:`run_study`.
"""
from __future__ import annotations

import sys
import types
from dataclasses import dataclass
from pathlib import Path

from .spec import StudySpec, make_spec

__all__ = ["run_study", "StudyResult", "StudySpec", "make_spec"]


@dataclass
class StudyResult:
    """The outcome of :func:`run_study`.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per run, in the study's order: ``run_id``, ``index``, ``grid_point``,
        ``sample``, ``status`` (``ok``, ``failed``, ``lost``), ``error``, ``run_wall_s`` and
        ``run_cpu_s`` (s), ``attempts``, ``worker``, the parameters, then every scalar summary entry.
    out : Path or None
        The study folder.
    files : list of Path
        What was written (table, plots).
    ran, skipped : int
        Runs computed now, and finished runs found in ``out`` and not run again.
    dashboard : str or None
        The Dask dashboard's address, if one was served.
    """

    table: object
    out: Path | None
    files: list
    ran: int
    skipped: int
    dashboard: str | None = None

    @property
    def failed(self) -> int:
        return int((self.table["status"] != "ok").sum()) if len(self.table) else 0


def prepare(model, set=None, grid=None, random=None, samples: int = 1, seed: int = 0, out=None):
    """Check a study's inputs and its folder without running anything: ``(spec, folder)``.

    Raises
    ------
    ParameterError
        Bad input (one line naming the option, the value and what is allowed); nothing is
        written.
    """
    from ..errors import ParameterError
    from ..model import load_model
    from .table import StudyFolder

    if not isinstance(model, str):
        raise ParameterError(f"model={getattr(model, 'name', model)!r}: give the model by name or file path "
                             "(the workers load it themselves)")
    spec = make_spec(load_model(model), model, set, grid, random, samples, seed)
    folder = StudyFolder(out, spec.signature()) if out is not None else None
    return spec, folder


def run_study(model: str, set: dict | None = None, grid=None, random=None, samples: int = 1, seed: int = 0,
              scheduler: str = "local", workers: int | None = None, out=None, keep_outputs: bool = False,
              progress: bool = True, plots: bool = True, client=None) -> StudyResult:
    """Run ``model`` over a grid of parameters and random samples, on Dask.

    Parameters
    ----------
    model : str
        A model's name (``symcat list``) or the path of a model file.
    set : dict, optional
        Parameter values of every run (text is parsed as on the command line).
    grid : dict or list of str, optional
        ``{name: "START:STOP:STEP"}`` (both ends included), ``{name: [v1, v2]}`` or
        ``["name=1,2", ...]``: the runs are the full factorial of the grids.
    random : dict or list of str, optional
        ``{name: "normal:MEAN:SD"}`` or ``{name: "uniform:LOW:HIGH"}`` (a real-valued
        parameter, in its unit), drawn for each sample.
    samples : int
        Random samples at every grid point. A catenary model with ``deviation_seed`` (not given
        here) gets one seed per sample, derived from ``seed``: the Monte Carlo of its as-built
        errors.
    seed : int
        Seed of the samples: the same seed gives the same runs.
    scheduler : str
        ``"local"`` (a ``LocalCluster`` of single-threaded worker processes) or
        ``"tcp://HOST:PORT"`` (an existing Dask scheduler; models, kernels cache and ``out``
        must be reachable from its workers).
    workers : int, optional
        Local workers (default: one per core); with an existing scheduler, wait for that many.
    out : path, optional
        The study folder: ``results.parquet``, ``study.json``, ``rows/`` (one file per finished
        run: rerunning the same study there runs only the others), ``plots/`` and, with
        ``keep_outputs``, ``runs/<run_id>/`` (each run's ``--out``).
    keep_outputs : bool
        Keep each run's plots and files (needs ``out``).
    progress : bool
        Show the progress of the runs on stderr.
    plots : bool
        Write the plots (with ``out``).
    client : distributed.Client, optional
        Run on this client instead of connecting (``scheduler`` and ``workers`` unused).

    Returns
    -------
    StudyResult

    Raises
    ------
    ParameterError
        Bad input, an unreachable scheduler, or an ``out`` holding another study: nothing is
        written.
    """
    from ..errors import ParameterError
    from .runner import connect, dashboard, execute
    from .sampling import study_runs
    from .table import table_frame

    if keep_outputs and out is None:
        raise ParameterError("--keep-outputs: needs --out DIR (where the runs' outputs go)")
    spec, folder = prepare(model, set, grid, random, samples, seed, out)
    runs = study_runs(spec)
    if "progress" in {p.name for p in spec.model.parameters} and "progress" not in spec.fixed:
        runs = [type(r)(r.index, r.grid_point, r.sample, {**r.params, "progress": False}, r.run_id) for r in runs]
    rows: dict[str, dict] = {}
    finished = folder.finished() if folder is not None else {}
    todo = [r for r in runs if r.run_id not in finished]
    context = connect(scheduler, workers) if client is None else _given(client)
    files = []
    with context as c:  # connected (or refused) before anything is written
        board = dashboard(c)
        if board and progress:
            print(f"symcat: Dask dashboard at {board}", file=sys.stderr)
        if folder is not None:
            folder.create()
        for r in runs:
            if r.run_id in finished:
                rows[r.run_id] = finished[r.run_id]

        def on_row(run, row):
            row.update(run_id=run.run_id, index=run.index, grid_point=run.grid_point, sample=run.sample,
                       params=_shown_params(run.params, spec))
            rows[run.run_id] = row
            if folder is not None:
                folder.add(row)

        try:
            execute(c, spec.model_ref, todo, on_row, folder.run_folder if keep_outputs else None, progress,
                    done_before=len(runs) - len(todo),
                    failed_before=sum(finished[r.run_id]["status"] != "ok" for r in runs if r.run_id in finished),
                    total=len(runs))
        finally:
            ordered = [rows[r.run_id] for r in runs if r.run_id in rows]
            if folder is not None and ordered:
                files.append(folder.write_table(ordered))
    frame = table_frame(ordered)
    if folder is not None and plots and len(frame):
        from .plots import plot_study

        params = sorted({k for row in ordered for k in row.get("params", {})})
        files += plot_study(frame, list(spec.grids), [r.name for r in spec.randoms], folder.path / "plots", params)
    return StudyResult(frame, None if folder is None else folder.path, files, len(todo), len(runs) - len(todo), board)


def _shown_params(params: dict, spec: StudySpec) -> dict:
    """The parameters of a row: those the study sets (not the workers' ``progress``)."""
    return {k: v for k, v in params.items() if k != "progress" or "progress" in spec.fixed}


class _given:
    """A client given by the caller, used as is and left open."""

    def __init__(self, client):
        self.client = client

    def __enter__(self):
        return self.client

    def __exit__(self, *exc):
        return False


class _CallableModule(types.ModuleType):
    def __call__(self, *args, **kwargs) -> StudyResult:
        return run_study(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
