"""A study on an existing Dask cluster: a scheduler and two workers started here as separate
processes (`dask scheduler`, `dask worker`) on localhost, reached by its tcp:// address."""
from __future__ import annotations

import json
import subprocess
import sys
import time

import pytest

from symcat.cli import main

from .conftest import TOY


@pytest.fixture
def external_cluster(tmp_path):
    """The address of a scheduler with two single-threaded workers; the processes are stopped after."""
    file = tmp_path / "scheduler.json"
    dask = [sys.executable, "-m", "dask"]
    procs = [subprocess.Popen([*dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(file)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + 60
        while not file.exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        procs += [subprocess.Popen([*dask, "worker", "--scheduler-file", str(file), "--nthreads", "1",
                                    "--no-dashboard", "--no-nanny", "--name", f"w{k}"], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL) for k in range(2)]
        yield json.loads(file.read_text())["address"]
    finally:  # workers without nannies: no child processes to leave behind
        for p in procs[::-1]:
            p.kill()
            p.wait()


def test_a_study_runs_on_an_external_scheduler(external_cluster, tmp_path, capsys):
    assert external_cluster.startswith("tcp://127.0.0.1:")
    out = tmp_path / "study"
    code = main(["study", TOY, "--grid", "x=1:4:1", "--random", "fail_above=uniform:10:20", "--samples", "2",
                 "--seed", "3", "--scheduler", external_cluster, "--workers", "2", "--out", str(out), "--quiet"])
    assert code == 0, capsys.readouterr().err
    import pandas as pd

    table = pd.read_parquet(out / "results.parquet")
    assert len(table) == 8 and set(table["status"]) == {"ok"}
    assert list(table["y_m2"]) == [1.0, 1.0, 4.0, 4.0, 9.0, 9.0, 16.0, 16.0]
    assert table["worker"].nunique() == 2
    assert "8 runs: 8 run now, 0 finished earlier, 0 failed" in capsys.readouterr().err
