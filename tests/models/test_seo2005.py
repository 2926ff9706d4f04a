"""The seed paper's example (models/seo2005_catenary.py): short runs of both contact models from
static equilibrium, and bad input."""
from __future__ import annotations

import pytest

from symcat.errors import ParameterError
from symcat.model import run_model

KEYS = ("panhead_z_mean_m", "panhead_z_std_m", "contact_force_mean_N", "contact_force_std_N", "wall_s",
        "simulated_s", "contact_loss_percent", "max_position_drift_m", "energy_change_J")


def test_short_runs_of_both_contact_models_agree_and_start_smoothly(tmp_path):
    out = {}
    for contact in ("bilateral", "penalty"):
        r = run_model("seo2005_catenary", {"t_end": 0.06, "contact": contact, "n_out": 500},
                      out=tmp_path / contact)
        s = r.summary
        assert all(k in s for k in KEYS)
        # From static equilibrium: the force stays near its static value (the paper's start-up
        # oscillation came from not starting there).
        assert abs(s["contact_force_mean_N"] - s["static_contact_force_N"]) < 0.1 * s["static_contact_force_N"]
        assert s["contact_force_std_N"] < 5.0 and s["contact_loss_percent"] == 0.0
        assert s["max_position_drift_m"] < 1e-6
        assert {"seo2005_catenary.png", "seo2005_catenary.npz", "summary.json"} <= {p.name for p in (tmp_path / contact).iterdir()}
        out[contact] = s
    b, p = out["bilateral"], out["penalty"]
    assert p["contact_force_mean_N"] == pytest.approx(b["contact_force_mean_N"], rel=0.02)
    # The penalty pan-head rides above the wire by its penetration (~1.8 mm at 90 N, 5e4 N/m).
    assert 0 < p["panhead_z_mean_m"] - b["panhead_z_mean_m"] < 3e-3


def test_a_pantograph_off_the_wire_is_refused_and_nothing_is_written(tmp_path):
    with pytest.raises(ParameterError, match=r"start=70 m: the pantograph must start on the wire, in \[2, 58\] m"):
        run_model("seo2005_catenary", {"start": 70.0}, out=tmp_path / "a")
    with pytest.raises(ParameterError, match=r"t_end=5 s: at speed=17 m/s the pantograph would leave the wire"):
        run_model("seo2005_catenary", {"t_end": 5.0}, out=tmp_path / "b")
    with pytest.raises(ParameterError, match="contact=rigid: must be one of bilateral, penalty"):
        run_model("seo2005_catenary", {"contact": "rigid"})
    assert not any(tmp_path.iterdir())
