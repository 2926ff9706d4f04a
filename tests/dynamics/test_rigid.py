"""Rigid multibody dynamics: the double pendulum against a minimal-coordinate integration,
energy conservation, drift, and the four DAE forms."""
from __future__ import annotations

import pytest

from symcat.model import run_model


@pytest.mark.parametrize("formulation", ["augmented", "embedded"])
@pytest.mark.parametrize("index", ["1", "ggl"])
def test_double_pendulum_against_minimal_coordinates(formulation, index):
    s = run_model("pendulum", {"t_end": 2.0, "formulation": formulation, "index": index, "rtol": 1e-9}).summary
    assert s["max_tip_error_m"] < 2e-6          # over the whole 2 s, tip of a 2 m chaotic pendulum
    assert s["energy_drift_rel"] < 1e-6         # conservative system
    assert s["max_position_drift_m"] < 1e-7


@pytest.mark.parametrize("index", ["1", "ggl"])
def test_constraint_drift_stays_bounded_over_a_long_run(index):
    """20 s of a chaotic double pendulum: drift below 1e-6 m (index 1, Baumgarte 10/s) and
    1e-8 m (GGL enforces C = 0 itself)."""
    s = run_model("pendulum", {"t_end": 20.0, "index": index, "rtol": 1e-7}).summary
    assert s["max_position_drift_m"] < (1e-6 if index == "1" else 1e-8)
    assert s["energy_drift_rel"] < 1e-3
