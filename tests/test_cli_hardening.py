"""The command line as a user meets it when things go wrong: every bad value is one line (exit
2, nothing written), output paths are checked before any work, a failure or a Ctrl-C keeps
what was computed (exit 1 / 130, summary marked incomplete), and reused folders never mix runs.
"""
from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from symcat import cli
from symcat.model import available_models, load_model

ROOT = Path(__file__).resolve().parents[1]

#: A rod hinged at the origin whose tip is driven sideways at 1 m/s: the mechanism locks at
#: t = 1 s and IDAS fails there (tests/dynamics/test_joints_forces.py).
LOCKING_MODEL = '''
import numpy as np
from symcat.assembly.multibody import MultibodyModel
from symcat.integrate import simulate
from symcat.model import Model, ModelOutput, Parameter
from symcat.scene import Driving, Revolute, RigidBody, Scene

def run(p):
    scene = Scene()
    scene.add(RigidBody("rod", 1.0, (0.1, 0.1, 0.1), (0, 0, -0.5), rotation=np.eye(3)))
    scene.add(Revolute("hinge", "rod", "ground", at=(0, 0, 0), axis=(0, 1, 0)))
    scene.add(Driving("push", "rod", direction=(1, 0, 0), at=(0, 0, -1.0), velocity=1.0))
    res = simulate(MultibodyModel(scene), p["t_end"], rtol=1e-8, atol=1e-10, n_out=40, chunks=20, progress=False)
    def write(out):
        res.save(out / "locking.npz")
        return [out / "locking.npz"]
    return ModelOutput({"t_last_s": float(res.t_s[-1])}, res.stats, {"result": res}, write)

MODEL = Model("locking", "a mechanism that locks at t = 1 s", [Parameter("t_end", 2.0, "s", "simulated time", minimum=0.0)], run)
'''


def _symcat(*args, cwd=ROOT, **kw):
    return subprocess.run([sys.executable, "-m", "symcat.cli", *args], capture_output=True, text=True, cwd=cwd, **kw)


def _one_line(stderr: str) -> str:
    assert "Traceback" not in stderr, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    return lines[0]


# --- 2. every bad value is one line ------------------------------------------------------------

BAD_VALUES = ("nan", "inf", "-inf", "-1", "0", "abc", "")


def _rejected(p, text: str) -> bool:
    """Whether the declaration of ``p`` forbids ``text``, judged here without the parser."""
    if p.choices:
        return text not in p.choices
    if p.kind is bool:
        return text.lower() not in ("1", "true", "yes", "on", "0", "false", "no", "off")
    if p.kind is str:
        # lists of numbers and files: non-finite numbers, words and missing files are refused;
        # an empty text means "none" where that is the default.
        return not (text == "" and p.default == "")
    try:
        value = float(text)
    except ValueError:
        return True
    if not math.isfinite(value) or (p.kind is int and value != int(value)):
        return True
    if p.minimum is not None and (value < p.minimum or (p.exclusive_minimum and value <= p.minimum)):
        return True
    return p.maximum is not None and value > p.maximum


def _cases():
    for name in available_models():
        for p in load_model(name).parameters:
            for text in BAD_VALUES:
                if _rejected(p, text):
                    yield name, p.name, text


CASES = list(_cases())


def test_the_table_of_bad_values_covers_every_model_and_parameter():
    models = {m for m, _, _ in CASES}
    assert models == set(available_models()) and len(models) == 14
    params = {(m, p) for m, p, _ in CASES}
    assert params == {(m, p.name) for m in models for p in load_model(m).parameters}
    assert len(CASES) > 500


@pytest.mark.parametrize("model", sorted(available_models()))
def test_every_bad_value_of_every_parameter_is_one_clear_line_and_writes_nothing(model, tmp_path, capsys):
    """In-process (the same code path as the command, a thousand values in seconds); one of
    each model's cases also runs as a real subprocess below."""
    out, summary = tmp_path / "out", tmp_path / "s.json"
    tried = 0
    for _, name, text in [c for c in CASES if c[0] == model]:
        code = cli.main(["run", model, "--set", f"{name}={text}", "--out", str(out), "--summary", str(summary)])
        captured = capsys.readouterr()
        assert code == 2, (name, text, captured.err)
        line = _one_line(captured.err)
        assert line.startswith("symcat: error: ") and name in line, (name, text, line)
        assert not out.exists() and not summary.exists(), (name, text)
        tried += 1
    assert tried >= 10


def test_a_bad_value_is_one_line_from_a_real_process(tmp_path):
    res = _symcat("run", "benchmark2015", "--set", "elements_per_span=nan", "--out", str(tmp_path / "o"))
    assert res.returncode == 2
    assert _one_line(res.stderr) == "symcat: error: elements_per_span=nan: must be an integer >= 4 and <= 400" \
        or "elements_per_span=nan" in res.stderr
    assert not (tmp_path / "o").exists()


def test_a_parameter_given_twice_is_an_error_naming_it():
    res = _symcat("run", "cantilever", "--set", "alpha=1", "--set", "alpha=2")
    assert res.returncode == 2
    assert "--set alpha: given twice" in _one_line(res.stderr)


def test_run_help_without_a_model_lists_the_models_and_list_describes_them():
    res = _symcat("run", "--help")
    assert res.returncode == 0, res.stderr
    for name in available_models():
        assert f"  {name}  " in res.stdout.replace(" " * 3, "  ") or f"  {name} " in res.stdout
    assert "removed first" in res.stdout  # what a reused --out folder does
    listed = _symcat("list")
    assert listed.returncode == 0
    lines = listed.stdout.strip().splitlines()
    assert len(lines) == len(available_models())
    assert all(len(line.split(None, 1)) == 2 for line in lines)  # a name and its description
    assert any(line.split()[0] == "vehicle" and "bogies" in line for line in lines)
    none = _symcat("run")
    assert none.returncode == 2 and "give a model" in _one_line(none.stderr)


def test_text_list_and_file_parameters_are_not_labelled_a_number():
    for name in available_models():
        for p in load_model(name).parameters:
            if p.kind is str:
                assert "number" not in p.allowed() or "numbers" in p.allowed(), (name, p.name, p.allowed())
                assert p.allowed() != "a number"
    help_text = load_model("wheelset").help()
    assert "irregularity_file = ''  (the path of a CSV file, or nothing)" in help_text


# --- 1. a run never loses its work ------------------------------------------------------------

@pytest.mark.parametrize("option, path, why", [
    ("--out", "/proc/symcat-x", "cannot create the folder"),
    ("--summary", "/proc/symcat-x/s.json", "cannot create the folder"),
    ("--out", "FILE", "is an existing file"),
    ("--summary", "DIR", "is a folder"),
])
def test_output_paths_are_checked_before_any_work(option, path, why, tmp_path):
    (tmp_path / "a_file").write_text("x")
    path = {"FILE": str(tmp_path / "a_file"), "DIR": str(tmp_path)}.get(path, path)
    t0 = time.perf_counter()
    res = _symcat("run", "benchmark2015", option, path)
    elapsed = time.perf_counter() - t0
    assert res.returncode == 2
    line = _one_line(res.stderr)
    assert line.startswith(f"symcat: error: {option} {path}: {why}"), line
    assert elapsed < 5.0  # refused before the model is loaded (a passage takes minutes)


def test_a_solver_failure_writes_the_partial_result_and_a_summary_marked_incomplete(tmp_path):
    model = tmp_path / "locking.py"
    model.write_text(LOCKING_MODEL)
    out = tmp_path / "out"
    res = _symcat("run", str(model), "--out", str(out), "--summary", str(tmp_path / "s.json"), "--quiet")
    assert res.returncode == 1
    line = _one_line(res.stderr)
    assert "IDAS failed in the step after t = 0.9 s" in line and f"the results so far are in {out}" in line
    assert "Python API" not in line
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["complete"] is False
    assert 0.8 <= summary["stopped"]["t_s"] <= 1.0 and summary["stopped"]["t_end_s"] == 2.0
    assert "IDA_CONV_FAIL" in summary["stopped"]["reason"]
    assert summary["t_last_s"] == summary["stopped"]["t_s"]  # the model summarized what was computed
    saved = np.load(out / "locking.npz")
    assert saved["t_s"][-1] == pytest.approx(summary["t_last_s"]) and len(saved["t_s"]) == 19  # every 0.05 s
    assert json.loads((out / "summary.json").read_text())["files"] == ["locking.npz"]


def test_the_python_api_raises_with_the_result_so_far():
    from symcat.errors import RunStopped, SolverError
    from symcat.model import Model, run_model

    namespace = {}
    exec(compile(LOCKING_MODEL, "locking", "exec"), namespace)
    model: Model = namespace["MODEL"]
    with pytest.raises(RunStopped) as info:
        run_model(model, {"t_end": 2.0})
    assert isinstance(info.value, SolverError) and not info.value.interrupted
    assert info.value.partial.summary["complete"] is False
    assert 0.8 <= info.value.partial.summary["t_last_s"] <= 1.0


def _start_and_wait_for(args, marker: str, cwd=ROOT, timeout_s: float = 240.0):
    """Start ``symcat`` and return the process once ``marker`` has appeared on its stderr
    (with what it printed so far)."""
    proc = subprocess.Popen([sys.executable, "-u", "-m", "symcat.cli", *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    os.set_blocking(proc.stderr.fileno(), False)
    seen, end = b"", time.monotonic() + timeout_s
    while marker.encode() not in seen:
        assert proc.poll() is None, seen.decode(errors="replace")
        assert time.monotonic() < end, seen.decode(errors="replace")
        time.sleep(0.05)
        seen += proc.stderr.read() or b""
    return proc, seen


@pytest.mark.slow
def test_ctrl_c_during_a_passage_keeps_the_histories_so_far(tmp_path):
    out, summary = tmp_path / "out", tmp_path / "s.json"
    proc, seen = _start_and_wait_for(["run", "benchmark2015", "--set", "speed_kmh=60", "--set", "elements_per_span=30",
                                      "--out", str(out), "--summary", str(summary), "--quiet"], "generalized-alpha [")
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130
    text = (seen + err).decode()
    assert "Traceback" not in text and "KeyboardInterrupt" not in text and "SystemError" not in text
    last = text.replace("\r", "\n").strip().splitlines()[-1]
    assert last.startswith("symcat: interrupted at t = ") and f"the results so far are in {out}" in last
    data = json.loads(summary.read_text())
    assert data["complete"] is False and data["stopped"]["interrupted"] is True
    assert 0 < data["stopped"]["t_s"] < data["stopped"]["t_end_s"]
    from symcat.interaction import load_passage

    saved = load_passage(out / "benchmark2015.npz")
    assert saved["t_s"][-1] == pytest.approx(data["stopped"]["t_s"], abs=2e-3)
    assert json.loads((out / "summary.json").read_text())["complete"] is False


#: A model whose set-up takes long (a stand-in for form finding or a compile), saying when it starts.
SLOW_SETUP_MODEL = '''
import sys, time
from symcat.model import Model, Parameter

def run(p):
    print("setting up", file=sys.stderr, flush=True)
    time.sleep(60)

MODEL = Model("slow_setup", "a long set-up", [Parameter("t_end", 1.0, "s", "simulated time", minimum=0.0)], run)
'''


def test_ctrl_c_before_the_time_integration_writes_an_incomplete_summary(tmp_path):
    model = tmp_path / "slow_setup.py"
    model.write_text(SLOW_SETUP_MODEL)
    summary = tmp_path / "s.json"
    proc, _ = _start_and_wait_for(["run", str(model), "--summary", str(summary), "--quiet"], "setting up")
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert "Traceback" not in err.decode()
    assert err.decode().strip().splitlines()[-1].startswith("symcat: interrupted before the time integration started")
    data = json.loads(summary.read_text())
    assert data["complete"] is False and data["stopped"]["t_s"] is None


def test_a_reused_out_folder_holds_only_the_latest_run(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "mode_7.vtu").write_text("stale")
    (out / "paraview").mkdir()
    (out / "paraview" / "old_0001.vtu").write_text("stale")
    (out / "notes.txt").write_text("the user's own file")
    (out / "summary.json").write_text(json.dumps({"files": ["mode_7.vtu", "paraview/old_0001.vtu"]}))
    res = _symcat("run", "taut_wire", "--set", "n_modes=2", "--out", str(out), "--quiet")
    assert res.returncode == 0, res.stderr
    assert not (out / "mode_7.vtu").exists() and not (out / "paraview").exists()
    assert (out / "notes.txt").read_text() == "the user's own file"
    listed = json.loads((out / "summary.json").read_text())["files"]
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()) == sorted(
        listed + ["notes.txt", "summary.json"])
    # A second run into the same folder leaves the same set of files.
    again = _symcat("run", "taut_wire", "--set", "n_modes=1", "--out", str(out), "--quiet")
    assert again.returncode == 0
    assert len(list(out.glob("mode_*.vtu"))) == 1  # the first run wrote two
