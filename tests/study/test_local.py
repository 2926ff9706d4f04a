"""Studies on a local cluster of two workers: the same answers as `symcat run`, reproducible
samples, failed runs, resume, and a killed worker."""
from __future__ import annotations

import json
import os
import signal
import threading
import time

import pandas as pd
import pytest

from symcat.cli import main
from symcat.study import run_study
from symcat.study.task import flatten

from .conftest import TOY

TAUT = {"n_elements": 8, "n_modes": 3}


def test_grid_rows_are_the_summaries_of_symcat_run(client, tmp_path):
    result = run_study("taut_wire", TAUT, {"tension": "18000:20000:2000", "element": ["cable2d", "cable3d"]},
                       client=client, out=tmp_path / "study", progress=False)
    table = pd.read_parquet(tmp_path / "study" / "results.parquet")
    assert len(table) == 4 and set(table["status"]) == {"ok"}
    assert table["worker"].nunique() == 2  # both workers ran
    assert list(table["tension"]) == [18000.0, 18000.0, 20000.0, 20000.0]
    assert (tmp_path / "study" / "plots" / "tension.png").is_file()
    for _, row in table.iterrows():
        summary_file = tmp_path / f"{row['run_id']}.json"
        sets = [f"{k}={v!r}" if isinstance(v, float) else f"{k}={v}" for k, v in
                {**TAUT, "tension": row["tension"], "element": row["element"]}.items()]
        assert main(["run", "taut_wire", *sum([["--set", s] for s in sets], []), "--summary", str(summary_file),
                     "--quiet"]) == 0
        expected = flatten(json.loads(summary_file.read_text()))
        compared = [k for k in expected if "wall" not in k]
        assert len(compared) >= 4
        for key in compared:  # bit-identical, through the Parquet table
            assert row[key] == expected[key], key
    assert result.ran == 4 and result.skipped == 0


def test_the_same_seed_gives_the_same_table_and_another_seed_another(client):
    spec = dict(grid={"shape": "square,cube"}, random={"x": "normal:1:0.5", "fail_above": "uniform:10:20"},
                samples=3, client=client, progress=False)
    a = run_study(TOY, seed=5, **spec).table
    b = run_study(TOY, seed=5, **spec).table
    c = run_study(TOY, seed=6, **spec).table
    columns = ["run_id", "shape", "x", "fail_above", "y_m2", "sin_x", "nested.twice_y"]
    pd.testing.assert_frame_equal(a[columns], b[columns])
    assert not a["x"].equals(c["x"]) and not a["y_m2"].equals(c["y_m2"])
    assert "list" not in a.columns  # lists are not scalars


def test_a_failing_run_is_a_row_with_its_error(client, tmp_path):
    import symcat

    result = symcat.study(TOY, {"fail_above": 2.5}, {"x": "1:4:1"}, client=client, out=tmp_path, progress=False,
                          keep_outputs=True)
    table = result.table
    for run_id, status in zip(table["run_id"], table["status"]):  # each run's own --out, failed ones too
        kept = json.loads((tmp_path / "runs" / run_id / "summary.json").read_text())
        assert kept["complete"] is (status == "ok")
    assert list(table["status"]) == ["ok", "ok", "failed", "failed"]
    assert table["error"].iloc[2] == "toy solver: x=3 m is above fail_above=2.5 m"
    assert table["error"].iloc[0] == "" and table["y_m2"].iloc[1] == 4.0
    assert result.failed == 2
    # a resumed study does not run its failed runs again
    assert run_study(TOY, {"fail_above": 2.5}, {"x": "1:4:1"}, client=client, out=tmp_path, progress=False).ran == 0


def test_an_interrupted_study_resumes_with_the_runs_it_has_not_finished(client, tmp_path):
    args = (TOY, {"n": 1}, {"x": "1:6:1"})
    first = run_study(*args, client=client, out=tmp_path, progress=False)
    rows = sorted((tmp_path / "rows").glob("*.json"))
    assert len(rows) == 6
    for f in rows[:4]:  # as if the study had been stopped after two runs
        f.unlink()
    (tmp_path / "results.parquet").unlink()
    again = run_study(*args, client=client, out=tmp_path, progress=False)
    assert (again.ran, again.skipped) == (4, 2)
    columns = ["run_id", "x", "y_m2", "status"]
    pd.testing.assert_frame_equal(first.table[columns], pd.read_parquet(tmp_path / "results.parquet")[columns])


def test_a_killed_worker_loses_only_its_run_which_is_run_again(client, tmp_path):
    hang = tmp_path / "hang"
    hang.mkdir()

    def kill_when_hanging():
        deadline = time.monotonic() + 60
        while not (hang / "pid").exists() and time.monotonic() < deadline:
            time.sleep(0.02)
        (hang / "marker").write_text("")
        os.kill(int((hang / "pid").read_text()), signal.SIGKILL)  # the worker process running x=3

    killer = threading.Thread(target=kill_when_hanging)
    killer.start()
    result = run_study(TOY, {"hang_at": 3.0, "hang_dir": str(hang)}, {"x": "1:5:1"}, client=client, out=tmp_path / "s",
                       progress=False)
    killer.join()
    table = result.table
    assert list(table["status"]) == ["ok"] * 5
    assert list(table["attempts"]) == [1, 1, 2, 1, 1]
    assert list(table["y_m2"]) == [1.0, 4.0, 9.0, 16.0, 25.0]
    client.wait_for_workers(2, timeout=30)  # the nanny has restarted it: the cluster is whole for the next test


@pytest.mark.parametrize("extra", [["--grid", "nope=1,2"], ["--grid", "x=2:1:1"], ["--random", "x=beta:1:2"],
                                   ["--scheduler", "tcp://127.0.0.1:9"], ["--keep-outputs"]])
def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path, capsys, extra):
    out = tmp_path / "study"
    args = ["study", TOY, "--grid", "n=1,2", *extra] + ([] if extra == ["--keep-outputs"] else ["--out", str(out)])
    t0 = time.perf_counter()
    assert main(args) == 2
    assert time.perf_counter() - t0 < 10
    err = capsys.readouterr().err
    assert err.startswith("symcat: error: ") and err.count("\n") == 1, err
    assert not out.exists()


def test_an_out_folder_of_another_study_is_refused(client, tmp_path, capsys):
    run_study(TOY, grid={"x": "1,2"}, client=client, out=tmp_path, progress=False)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    assert main(["study", TOY, "--grid", "x=1,2,3", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"--out {tmp_path}: holds a study of different parameters (grid: " in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before


def test_progress_shows_done_failed_running_and_time_left(capsys):
    from symcat.study.runner import StudyProgress

    bar = StudyProgress(10, 2, slots=2, delay=0.0)
    bar.update(3, 0)
    time.sleep(0.25)
    bar.update(5, 1)
    bar.close()
    line = capsys.readouterr().err.strip().split("\r")[-1]
    assert "5/10 runs, 1 failed, 2 running" in line and "eta" in line and "eta --" not in line


def test_a_study_stopped_by_ctrl_c_resumes_where_it_stopped(client, tmp_path):
    """A real interruption: `symcat study` on one worker gets SIGINT while the run x=4 is under way."""
    import subprocess
    import sys

    hang, out = tmp_path / "hang", tmp_path / "study"
    hang.mkdir()
    cmd = [sys.executable, "-m", "symcat.cli", "study", TOY, "--grid", "x=1:6:1", "--set", "hang_at=4",
           "--set", f"hang_dir={hang}", "--workers", "1", "--out", str(out), "--quiet"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (hang / "pid").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.strip().splitlines()[-1] == (f"symcat: interrupted; the finished runs are in {out}: rerun the same "
                                            "command to resume")
    assert len(list((out / "rows").glob("*.json"))) == 3  # x = 1, 2, 3
    assert list(pd.read_parquet(out / "results.parquet")["x"]) == [1.0, 2.0, 3.0]
    (hang / "marker").write_text("")  # x=4 runs through this time
    # the same study again (from Python, on the shared cluster: the same runs)
    again = run_study(TOY, {"hang_at": "4", "hang_dir": str(hang)}, ["x=1:6:1"], client=client, out=out, progress=False)
    assert (again.ran, again.skipped, again.failed) == (3, 3, 0)
    assert list(pd.read_parquet(out / "results.parquet")["y_m2"]) == [1.0, 4.0, 9.0, 16.0, 25.0, 36.0]
