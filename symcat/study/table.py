"""A study's folder: its identity, the rows of finished runs, the Parquet table.

``DIR/study.json`` holds the study's signature (model, fixed values, grids, random inputs,
samples, seed); a folder holding another study is refused before any work. Each finished run
is written at once as ``DIR/rows/<run_id>.json`` (whole or not at all), so an interrupted study
keeps every run it finished and rerunning the same command runs only the others.
``DIR/results.parquet`` is the table of all rows, one per run, in the study's order.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from ..errors import ParameterError
from ..run_output import write_json

STUDY_NAME = "study.json"
TABLE_NAME = "results.parquet"
ROWS_DIR = "rows"
RUNS_DIR = "runs"
#: Row statuses that count as finished (a resumed study does not run them again); a run whose
#: worker died twice ("lost") is run again.
FINISHED = ("ok", "failed")
#: Columns every row has besides the parameters and the summary.
META = ("run_id", "index", "grid_point", "sample", "status", "error", "run_wall_s", "run_cpu_s", "attempts", "worker")


def _differences(old: dict, new: dict) -> str:
    keys = [k for k in new if old.get(k) != new.get(k)] + [k for k in old if k not in new]
    return "; ".join(f"{k}: {json.dumps(old.get(k))} there, {json.dumps(new.get(k))} here" for k in keys)


class StudyFolder:
    """The ``--out`` folder of a study.

    Parameters
    ----------
    path : path
        The folder (created by :meth:`create`, not before).
    signature : dict
        :meth:`symcat.study.spec.StudySpec.signature`.

    Raises
    ------
    ParameterError
        If ``path`` is a file, or holds a study of different parameters.
    """

    def __init__(self, path, signature: dict):
        self.path = Path(path)
        self.signature = json.loads(json.dumps(signature))
        if self.path.exists() and not self.path.is_dir():
            raise ParameterError(f"--out {self.path}: is an existing file; give a folder (created if missing)")
        study = self.path / STUDY_NAME
        if study.exists():
            try:
                old = json.loads(study.read_text())["signature"]
            except (OSError, ValueError, KeyError, TypeError):
                raise ParameterError(f"--out {self.path}: its {STUDY_NAME} cannot be read; give another folder") from None
            if old != self.signature:
                raise ParameterError(f"--out {self.path}: holds a study of different parameters ({_differences(old, self.signature)}); "
                                     "give another folder, or the same study to resume it")

    def create(self) -> None:
        """Make the folder and record the study (the first write of a study)."""
        try:
            (self.path / ROWS_DIR).mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise ParameterError(f"--out {self.path}: cannot create the folder ({err.strerror or err})") from None
        write_json(self.path / STUDY_NAME, {"signature": self.signature})

    def finished(self) -> dict[str, dict]:
        """The rows of the runs finished earlier, by run id."""
        rows = {}
        folder = self.path / ROWS_DIR
        if not folder.is_dir():
            return rows
        for f in folder.glob("*.json"):
            try:
                row = json.loads(f.read_text())
            except (OSError, ValueError):
                continue
            if row.get("status") in FINISHED:
                rows[row["run_id"]] = row
        return rows

    def add(self, row: dict) -> None:
        """Record a finished run."""
        write_json(self.path / ROWS_DIR / f"{row['run_id']}.json", row, default=repr)

    def run_folder(self, run_id: str) -> Path:
        """Where a run keeps its outputs (``--keep-outputs``)."""
        return self.path / RUNS_DIR / run_id

    def write_table(self, rows: list[dict]) -> Path:
        """Write ``rows`` (in order) as the Parquet table; its path."""
        path = self.path / TABLE_NAME
        tmp = path.with_name(f".{TABLE_NAME}.tmp")
        table_frame(rows).to_parquet(tmp, index=False)
        tmp.replace(path)
        return path


def row_record(row: dict, param_names: list[str]) -> dict:
    """One flat record of a row: meta columns, parameters, then summary entries (a summary key
    equal to a parameter's name is prefixed ``summary.``)."""
    rec = {k: row.get(k) for k in META}
    params = row.get("params", {})
    rec.update({k: params.get(k) for k in param_names})
    for key, value in row.get("summary", {}).items():
        rec[f"summary.{key}" if key in rec else key] = value
    return rec


def table_frame(rows: list[dict]):
    """The rows as a pandas DataFrame with one type per column (a column mixing text with
    numbers is stored as text)."""
    import pandas as pd

    names = []
    for row in rows:
        names += [k for k in row.get("params", {}) if k not in names]
    frame = pd.DataFrame([row_record(r, names) for r in rows])
    for col in frame.columns:
        kinds = {type(v) for v in frame[col] if v is not None and not (isinstance(v, float) and math.isnan(v))}
        if len(kinds) > 1 and not kinds <= {int, float, bool}:
            frame[col] = [None if v is None else str(v) for v in frame[col]]
        elif kinds == {bool} and frame[col].isna().any():
            frame[col] = frame[col].astype("boolean")
        elif kinds and kinds <= {int, float} and kinds != {int}:
            frame[col] = pd.to_numeric(frame[col], errors="coerce").astype(float)
    return frame
