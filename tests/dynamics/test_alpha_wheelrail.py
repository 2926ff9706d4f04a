"""Generalized-alpha on models with wheel/rail contacts: the steps run inside the calls of the
event-stepping driver (symcat.integrate.alpha_events), the contact events (lift-off,
touchdown, contact-point jumps) decided by the same handler as under IDAS."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from symcat.errors import ParameterError
from symcat.integrate.generalized_alpha import generalized_alpha
from symcat.model import run_model
from symcat.wheelrail_events import default_handlers

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "wheelrail"))
from test_lift_off import G, MASS, OMEGA, T_LAND, T_LIFT, _height, _wheelset  # noqa: E402


def _flight(dt):
    model, angle = _wheelset()
    res = generalized_alpha(model, 0.2, dt, 0.9, n_out=100, progress=False, handlers=default_handlers(model))
    z = res.coordinate("ws.z") - res.coordinate("ws.z")[0]
    reference = np.array([_height(t) if T_LIFT < t < T_LAND else 0.0 for t in res.t_s])
    return res, angle, np.abs(z - reference).max()


def test_lifted_wheelset_flies_and_lands_as_in_closed_form_under_generalized_alpha():
    """The closed-form flight of tests/wheelrail/test_lift_off.py (peak 25.2 mm). Measured: lift-off
    5e-7 s late at either step (the handler's switch), touchdown 1.1e-5 s early at dt = 1 ms and
    2.0e-6 s at 0.25 ms; height error 1.1e-5 m and 7.0e-7 m (order 2)."""
    coarse, _, err_coarse = _flight(1e-3)
    fine, angle, err_fine = _flight(2.5e-4)
    assert err_fine < 1.5e-6 and err_coarse < 2.5e-5
    assert err_coarse / err_fine > 10  # order 2: 16
    for side in ("left", "right"):
        c = fine.wheelrail[f"wr_{side}"]
        assert c["lift_off_s"][0] == pytest.approx(T_LIFT, abs=2e-6)
        assert c["touchdown_s"][0] == pytest.approx(T_LAND, abs=5e-6)
        flight = (fine.t_s > c["lift_off_s"][0]) & (fine.t_s < c["touchdown_s"][0])
        assert np.array_equal(c["open"], flight)
        assert np.all(c["normal_force_N"][flight] == 0)
    on = ~fine.wheelrail["wr_left"]["open"]
    load = MASS * G - 2 * MASS * G * np.sin(OMEGA * fine.t_s)
    normal = fine.wheelrail["wr_left"]["normal_force_N"] + fine.wheelrail["wr_right"]["normal_force_N"]
    np.testing.assert_allclose(normal[on], load[on] / math.cos(angle), rtol=1e-8, atol=1e-6)
    assert fine.stats["lift_offs"] == 2 and fine.stats["touchdowns"] == 2


def test_conical_vehicle_agrees_with_idas():
    """The seed vehicle on conical wheels, 2 mm lateral offset: the hunting start and the wheel
    loads of both integrators (measured: wheelset lateral 2e-8 m apart over 0.5 s)."""
    params = {"profile": "conical", "t_end": 0.3, "n_out": 30}
    idas = run_model("vehicle", {**params, "integrator": "idas"}).arrays["result"]
    alpha = run_model("vehicle", {**params, "integrator": "generalized_alpha"}).arrays["result"]
    for ws in ("b1_ws1", "b2_ws2"):
        np.testing.assert_allclose(alpha.coordinate(f"{ws}.y"), idas.coordinate(f"{ws}.y"), atol=1e-7)
    for name, wheel in idas.wheelrail.items():
        np.testing.assert_allclose(alpha.wheelrail[name]["normal_force_N"], wheel["normal_force_N"], rtol=1e-3)


def test_conformal_wheelset_runs_through_its_contact_jumps_under_generalized_alpha():
    """EN 15302 profiles (nearly conformal): the contact points jump, and the run goes on."""
    res = run_model("wheelset", {"profile": "en15302_a", "creep": "linear", "t_end": 0.5, "n_out": 25,
                                 "integrator": "generalized_alpha"}).arrays["result"]
    assert res.t_s[-1] == pytest.approx(0.5)
    assert res.stats["contact_jumps"] >= 1
    load = 0.5 * (1813.0 + (32000.0 + 2 * 2615.0) / 4) * G
    normal = np.array([w["normal_force_N"] for w in res.wheelrail.values()])
    assert normal.min() > 0.85 * load and normal.max() < 1.2 * load
    assert np.abs(res.coordinate("wheelset.y")).max() < 0.0035


def test_seed_scene_contact_force_agrees_with_idas():
    """The seed's complete scene (vehicle, pantograph, 8-element wire): the contact force's
    statistics of both integrators (measured over 0.3 s: mean 6e-6, std 3e-5 apart)."""
    params = {"t_end": 0.1}
    idas = run_model("seo2005", {**params, "integrator": "idas"}).summary
    alpha = run_model("seo2005", {**params, "integrator": "generalized_alpha"}).summary
    assert alpha["contact_force_mean_N"] == pytest.approx(idas["contact_force_mean_N"], rel=1e-4)
    assert alpha["contact_force_std_N"] == pytest.approx(idas["contact_force_std_N"], rel=2e-3)
    np.testing.assert_allclose(alpha["wheel_normal_force_max_N"], idas["wheel_normal_force_max_N"], rtol=1e-4)


def test_generalized_alpha_refuses_wheel_rail_contacts_without_handlers_and_a_monitor_with_them():
    model, _ = _wheelset()
    with pytest.raises(ParameterError, match=r"wheel/rail contacts \(wr_left, wr_right\).*integrate_model"):
        generalized_alpha(model, 0.01, 1e-3, progress=False)
    with pytest.raises(ParameterError, match=r"monitor: not with event handlers"):
        generalized_alpha(model, 0.01, 1e-3, progress=False, handlers=default_handlers(model), monitor=lambda s: {})
