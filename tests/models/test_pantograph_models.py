"""benchmark2015 and en50318 models: summaries, EN 50318 validation at 250 km/h, bad input."""
import json
import math

import pytest

from symcat.errors import ParameterError
from symcat.interaction.statistics import STAT_KEYS
from symcat.model import run_model
from symcat.validation import EN50318_RANGES, check, format_table


def test_benchmark_static_summary_has_dropper_lengths(tmp_path):
    res = run_model("benchmark2015", {"t_end": 0.0, "progress": False}, out=tmp_path)
    lengths = res.summary["dropper_lengths_m"]
    assert len(lengths) == 9
    assert lengths == pytest.approx(lengths[::-1], abs=2e-3)
    assert 0.7 < min(lengths) < max(lengths) < 1.1
    assert res.summary["form_finding_height_error_m"] < 1e-8
    assert res.summary["simulated_s"] == 0.0 and "wall_s" in res.summary
    assert json.loads((tmp_path / "summary.json").read_text())["model"] == "benchmark2015"


def test_en50318_at_250_kmh_lands_in_the_contact_force_ranges(tmp_path):
    """The standard's acceptance check (force statistics; see the issue notes for the uplift)."""
    res = run_model("en50318", {"speed_kmh": 250.0, "progress": False, "paraview": True}, out=tmp_path)
    s = res.summary
    for key in STAT_KEYS:
        assert key in s and s[key] is not None and math.isfinite(s[key])
    rows = {r[0]: r for r in check(s, 250)}
    for key in ("contact_force_mean_N", "contact_force_std_N", "contact_force_stat_max_N",
                "contact_force_stat_min_N", "contact_force_max_N", "contact_force_min_N", "contact_loss_percent"):
        assert rows[key][4], f"{key}={rows[key][1]:.4g} outside {rows[key][2]}..{rows[key][3]}"
    for name in ("en50318_contact_force.png", "en50318_panhead.png", "en50318_uplift_droppers.png", "en50318.npz",
                 "paraview/en50318.pvd"):
        assert (tmp_path / name).is_file(), name
    assert len(list((tmp_path / "paraview").glob("*.vtu"))) > 10
    from symcat.interaction import load_passage

    arrays = load_passage(tmp_path / "en50318.npz")
    assert arrays["contact_force_N"].shape == arrays["x_contact_m"].shape


def test_validation_table_marks_failures():
    summary = {k: (lo + hi) / 2 for k, v in EN50318_RANGES.items() for lo, hi in [v[300]]}
    summary["contact_force_std_N"] = 99.0
    table = format_table({300: check(summary, 300)})
    assert "FAIL" in table and "1 quantities outside" in table


@pytest.mark.parametrize("model, values, name", [
    ("benchmark2015", {"speed_kmh": 470.0}, "speed_kmh"),
    ("benchmark2015", {"dropper_positions_m": "4.5,60"}, "dropper_positions_m"),
    ("benchmark2015", {"contact_wire_tension_N": -5.0}, "contact_wire_tension_N"),
    ("benchmark2015", {"presag_scale": 8.0}, "presag"),
    ("benchmark2015", {"n_pantographs": 2, "n_spans": 8}, "n_spans"),
    ("en50318", {"speed_kmh": 440.0}, "speed_kmh"),
])
def test_bad_input_names_the_parameter_and_writes_nothing(tmp_path, model, values, name):
    out = tmp_path / "out"
    with pytest.raises(ParameterError, match=name):
        run_model(model, {**values, "progress": False}, out=out)
    assert not out.exists()


def test_benchmark_over_an_overlap_reports_both_wires(tmp_path):
    """Two tension sections: the analysis spans cover the overlap; the pan-head presses on both
    wires somewhere in the transition span and the per-wire forces add up to the total."""
    import numpy as np

    from symcat.interaction import load_passage

    res = run_model("benchmark2015", {"tension_sections": 2, "n_spans": 6, "analysis_spans": 3, "speed_kmh": 250.0,
                                      "elements_per_span": 20, "progress": False, "paraview": False}, out=tmp_path)
    s = res.summary
    assert s["n_spans"] == 9 and s["tension_sections"] == 2
    assert s["analysis_section_m"] == [165.0, 330.0]
    assert 100 < s["contact_force_mean_N"] < 200 and s["contact_loss_percent"] < 20
    arrays = load_passage(tmp_path / "benchmark2015.npz")
    wire = arrays["contact_force_wire_N"]
    assert wire.shape[1:] == (1, 2)
    assert wire.sum(axis=2) == pytest.approx(arrays["contact_force_N"], abs=1e-9)
    x = arrays["x_contact_m"][:, 0]
    both = (wire[:, 0, 0] > 0) & (wire[:, 0, 1] > 0)
    assert both.any() and np.all((x[both] > 220.0) & (x[both] < 275.0))
    assert (tmp_path / "benchmark2015_contact_force.png").is_file()


@pytest.mark.parametrize("speed", [250, 300])
def test_en50318_with_20_mm_presag_lands_every_quantity_in_range(speed):
    """The public data leave the presag open below 55 mm; with 20 mm (the sensitivity study in
    models/en50318.py) all eight quantities, support uplift included, fall in the ranges."""
    res = run_model("en50318", {"speed_kmh": float(speed), "presag_mm": 20.0, "progress": False, "paraview": False})
    failed = [(r[0], round(r[1], 4)) for r in check(res.summary, speed) if not r[4]]
    assert not failed
