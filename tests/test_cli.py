"""`symcat run` from the command line: summaries, outputs, help, and bad input."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from symcat.model import run_model

ROOT = Path(__file__).resolve().parents[1]


def _symcat(*args):
    return subprocess.run([sys.executable, "-m", "symcat.cli", *args], capture_output=True, text=True, cwd=ROOT)


def test_run_writes_summary_plots_and_paraview_files(tmp_path):
    out = tmp_path / "out"
    res = _symcat("run", "cantilever", "--set", "alpha=2", "--set", "element=cable3d", "--out", str(out),
                  "--summary", str(tmp_path / "s.json"), "--quiet")
    assert res.returncode == 0, res.stderr
    summary = json.loads((tmp_path / "s.json").read_text())
    assert {"tip_ux_m", "tip_uy_m", "wall_s", "stats"} <= summary.keys()
    assert summary["stats"]["newton_iterations"] > 0
    assert (out / "cantilever.png").stat().st_size > 1000
    import meshio

    mesh = meshio.read(out / "cantilever.vtu")
    assert "displacement_m" in mesh.point_data and len(mesh.points) > 10
    assert json.loads((out / "summary.json").read_text())["parameters"]["alpha"] == 2.0


def test_model_by_path_and_python_api(tmp_path):
    res = _symcat("run", str(ROOT / "models" / "rollup.py"), "--set", "n_elements=4", "--set", "element=cable2d")
    assert res.returncode == 0, res.stderr
    assert "tip_x_m" in json.loads(res.stdout)
    api = run_model("rollup", {"n_elements": 4, "element": "cable2d"})
    assert api.summary["tip_x_m"] == pytest.approx(json.loads(res.stdout)["tip_x_m"], rel=1e-12)


def test_help_lists_parameters_with_units_and_ranges():
    res = _symcat("run", "taut_wire", "--help")
    assert res.returncode == 0
    assert "tension [N] = 20000.0" in res.stdout and "> 0" in res.stdout
    assert "one of cable2d, cable3d, beam3d" in res.stdout


@pytest.mark.parametrize(
    "args, message",
    [
        (["run", "no_such_model"], "model='no_such_model': no such model"),
        (["run", "cantilever", "--set", "colour=red"], "colour: not a parameter of model 'cantilever'"),
        (["run", "cantilever", "--set", "n_elements=0"], "n_elements=0: must be an integer >= 1"),
        (["run", "cantilever", "--set", "length=-2"], "length=-2 m: must be a number > 0"),
        (["run", "cantilever", "--set", "E=0"], "E=0 Pa: must be a number > 0"),
        (["run", "taut_wire", "--set", "mass_per_length=-1"], "mass_per_length=-1 kg/m: must be a number > 0"),
        (["run", "cantilever", "--set", "element=truss"], "element=truss: must be one of beam3d, cable3d, cable2d"),
        (["run", "cantilever", "--set", "alpha=abc"], "alpha=abc: must be a number >= 0"),
        (["run", "cantilever", "--set", "alpha"], "expected name=value"),
    ],
)
def test_bad_input_is_one_clear_line(args, message):
    res = _symcat(*args)
    assert res.returncode == 2
    assert "Traceback" not in res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], res.stderr
