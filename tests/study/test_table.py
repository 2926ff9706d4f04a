"""The study table: one type per column, the statistics plotted, the folder's identity."""
from __future__ import annotations

import pytest

from symcat.errors import ParameterError
from symcat.study.plots import plot_study, statistics_columns
from symcat.study.table import StudyFolder, table_frame


def _row(k, status="ok", **summary):
    return {"run_id": f"r{k}", "index": k, "grid_point": k, "sample": 0, "status": status, "error": "",
            "run_wall_s": 0.1, "attempts": 1, "worker": "w", "params": {"speed_kmh": 250.0 + 10 * k, "deviation_seed": k},
            "summary": summary}


def test_columns_keep_one_type_and_parameters_shadowing_summary_keys_are_kept_apart():
    rows = [_row(0, force_N=1.0, label="a", speed_kmh=250.0, n=1), _row(1, force_N=2, label=3, speed_kmh=260.0),
            _row(2, "failed")]
    frame = table_frame(rows)
    assert frame["force_N"].dtype.kind == "f" and frame["force_N"].isna().iloc[2]
    assert list(frame["label"].iloc[:2]) == ["a", "3"]  # text and a number: stored as text
    assert list(frame["summary.speed_kmh"].iloc[:2]) == [250.0, 260.0] and "speed_kmh" in frame.columns
    assert list(frame.columns[:10]) == ["run_id", "index", "grid_point", "sample", "status", "error", "run_wall_s",
                                        "run_cpu_s", "attempts", "worker"]


def test_statistics_plotted_are_the_varying_numeric_summary_entries(tmp_path):
    rows = [_row(k, force_N=float(k * k), constant=1.0, wall_s=0.2 * k, **{"stats.steps": k}) for k in range(3)]
    frame = table_frame(rows)
    assert statistics_columns(frame, ["speed_kmh", "deviation_seed"]) == ["force_N"]
    files = plot_study(frame, ["speed_kmh"], [], tmp_path, ["speed_kmh", "deviation_seed"])
    assert [f.name for f in files] == ["speed_kmh.png"] and files[0].stat().st_size > 1000


def test_a_folder_of_another_study_is_refused_and_the_same_study_resumes(tmp_path):
    sig = {"model": "toy", "set": {}, "grid": {"x": [1.0, 2.0]}, "random": {}, "samples": 1, "seed": 0}
    folder = StudyFolder(tmp_path / "s", sig)
    assert not (tmp_path / "s").exists()  # nothing written before create()
    folder.create()
    folder.add({**_row(0), "run_id": "abc"})
    assert set(StudyFolder(tmp_path / "s", sig).finished()) == {"abc"}
    with pytest.raises(ParameterError, match=r"holds a study of different parameters \(seed: 0 there, 1 here\)"):
        StudyFolder(tmp_path / "s", {**sig, "seed": 1})
    (tmp_path / "f").write_text("")
    with pytest.raises(ParameterError, match=r"--out .*/f: is an existing file"):
        StudyFolder(tmp_path / "f", sig)
