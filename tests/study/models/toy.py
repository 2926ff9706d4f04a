"""A model that runs in microseconds, for the study tests: y = x^2 + n, a failure on demand, and
a run that waits to be killed (its worker's pid written to a file) until a marker file exists."""
from __future__ import annotations

import math
import os
import time
from pathlib import Path

from symcat.errors import SolverError
from symcat.model import Model, ModelOutput, Parameter

PARAMETERS = [
    Parameter("x", 1.0, "m", "a length"),
    Parameter("n", 0, "-", "an integer", minimum=0),
    Parameter("shape", "square", "", "a choice", choices=("square", "cube")),
    Parameter("fail_above", 1e9, "m", "the run fails (a solver error) when x exceeds this"),
    Parameter("hang_at", -1.0, "m", "at this x, the run writes its pid to hang_dir/pid and waits for "
              "hang_dir/marker (the test kills the worker meanwhile)"),
    Parameter("hang_dir", "", "", "folder of the hang files", text="a folder"),
]


def run(p: dict) -> ModelOutput:
    if p["x"] > p["fail_above"]:
        raise SolverError(f"toy solver: x={p['x']:g} m is above fail_above={p['fail_above']:g} m")
    if p["x"] == p["hang_at"]:
        folder = Path(p["hang_dir"])
        if not (folder / "marker").exists():
            (folder / "pid.tmp").write_text(str(os.getpid()))
            os.replace(folder / "pid.tmp", folder / "pid")
            deadline = time.monotonic() + 60
            while not (folder / "marker").exists() and time.monotonic() < deadline:
                time.sleep(0.05)
            time.sleep(60)  # still alive after the marker: the test has not killed it
    power = 2 if p["shape"] == "square" else 3
    y = p["x"] ** power + p["n"]
    return ModelOutput({"y_m2": y, "sin_x": math.sin(p["x"]), "nested": {"twice_y": 2 * y}, "list": [1, 2]},
                       {"evaluations": 1})


MODEL = Model("toy", "a study-test model (instant runs)", PARAMETERS, run)
