"""A plain (non-editable) ``pip install`` of the project into a fresh virtual environment runs
a shipped model from any directory: ``generated/`` and ``models/`` are package data, a file
named like a model in the working directory does not replace it, and the run writes nothing
into the installed package."""
from __future__ import annotations

import json
import subprocess
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_non_editable_install_runs_a_shipped_model_from_any_directory(tmp_path):
    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    pip = subprocess.run([env_dir / "bin" / "python", "-m", "pip", "install", "-q", str(ROOT)],
                         capture_output=True, text=True)
    assert pip.returncode == 0, pip.stderr[-3000:]
    work = tmp_path / "elsewhere"
    (work / "models").mkdir(parents=True)
    for decoy in (work / "taut_wire.py", work / "models" / "taut_wire.py"):
        decoy.write_text("raise SystemExit('a file of the working directory was run as the model')\n")
    site = subprocess.run([env_dir / "bin" / "python", "-c", "import symcat, pathlib; print(pathlib.Path(symcat.__file__).parent)"],
                          capture_output=True, text=True, check=True, cwd=work).stdout.strip()
    package = Path(site)
    assert package != ROOT / "symcat" and (package / "_generated" / "manifest.json").is_file()
    before = {p: p.stat().st_mtime_ns for p in package.rglob("*") if "__pycache__" not in p.parts}
    run = subprocess.run([env_dir / "bin" / "symcat", "run", "taut_wire", "--set", "n_elements=10", "--quiet",
                          "--summary", "s.json"], capture_output=True, text=True, cwd=work)
    assert run.returncode == 0, run.stderr
    assert "regenerating" not in run.stderr  # the shipped code is current in the installed package
    installed = json.loads((work / "s.json").read_text())
    from symcat.model import run_model

    here = run_model("taut_wire", {"n_elements": 10}).summary
    assert installed["frequencies_hz"] == pytest.approx(here["frequencies_hz"], rel=1e-12)
    after = {p: p.stat().st_mtime_ns for p in package.rglob("*") if "__pycache__" not in p.parts}
    assert after == before
