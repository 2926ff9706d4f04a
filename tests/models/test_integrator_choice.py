"""The dynamic multibody models (pendulum, slider_on_wire, seo2005_catenary with either contact
model) run on either integrator (the model parameter ``integrator``), and a combination that
cannot run is one line naming it."""
from __future__ import annotations

import pytest

from symcat import cli
from symcat.errors import ParameterError
from symcat.model import run_model


def test_pendulum_on_generalized_alpha_meets_the_minimal_coordinate_reference_at_order_two():
    errors = {}
    for dt in (2e-3, 1e-3):
        s = run_model("pendulum", {"t_end": 1.0, "integrator": "generalized_alpha", "index": "ggl", "dt": dt}).summary
        errors[dt] = s["max_tip_error_m"]
        assert s["max_position_drift_m"] < 1e-9 and s["stats"]["steps"] == pytest.approx(1.0 / dt, abs=1)
    assert errors[1e-3] < 5e-5
    assert 3.0 < errors[2e-3] / errors[1e-3] < 5.0  # second order


def test_slider_on_wire_runs_the_same_on_both_integrators():
    idas = run_model("slider_on_wire", {"t_end": 0.5}).summary
    alpha = run_model("slider_on_wire", {"t_end": 0.5, "integrator": "generalized_alpha", "index": "ggl"}).summary
    assert alpha["s_final_m"] == pytest.approx(idas["s_final_m"], abs=2e-6)
    assert alpha["body_position_m"] == pytest.approx(idas["body_position_m"], abs=5e-5)
    assert alpha["steps"] == 500 and alpha["max_position_drift_m"] < 1e-9


@pytest.mark.parametrize("contact", ["bilateral", "penalty"])
def test_seo2005_catenary_runs_the_same_on_both_integrators(contact):
    """The seed paper's pantograph under the 8-element beam3d wire, 0.2 s from static
    equilibrium at 17 m/s, on the sliding joint or the penalty contact: generalized-alpha at
    dt = 1 ms (the stabilized form) gives IDAS's contact-force statistics (measured: mean within
    0.02 %, standard deviation within 0.4 %) in a quarter of IDAS's steps."""
    values = {"t_end": 0.2, "contact": contact}
    idas = run_model("seo2005_catenary", values).summary
    alpha = run_model("seo2005_catenary", {**values, "integrator": "generalized_alpha", "dt": 1e-3}).summary
    assert alpha["contact_force_mean_N"] == pytest.approx(idas["contact_force_mean_N"], rel=1e-3)
    assert alpha["contact_force_std_N"] == pytest.approx(idas["contact_force_std_N"], rel=0.02)
    assert alpha["panhead_z_mean_m"] == pytest.approx(idas["panhead_z_mean_m"], rel=1e-3)
    assert alpha["contact_loss_percent"] == idas["contact_loss_percent"] == 0.0
    stats = alpha["stats"]
    assert stats["steps"] <= 201 and stats["halvings"] == 0 and stats["variant"] == "stabilized"
    assert alpha["max_position_drift_m"] < 1e-9


@pytest.mark.parametrize("model, values, message", [
    ("pendulum", {"formulation": "embedded"}, "formulation=embedded with integrator=generalized_alpha"),
    ("slider_on_wire", {"formulation": "embedded"}, "use formulation=augmented, or integrator=idas"),
    ("seo2005_catenary", {"formulation": "embedded"}, "use formulation=augmented, or integrator=idas"),
])
def test_a_combination_that_cannot_run_is_one_line(model, values, message, capsys, tmp_path):
    sets = [f"{k}={v}" for k, v in {**values, "integrator": "generalized_alpha", "t_end": 0.01}.items()]
    code = cli.main(["run", model, *sum((["--set", s] for s in sets), []), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0], err
    assert not (tmp_path / "o").exists()
    with pytest.raises(ParameterError, match="generalized_alpha"):
        run_model(model, {**values, "integrator": "generalized_alpha", "t_end": 0.01})


def test_wheel_rail_contacts_run_on_generalized_alpha_with_their_event_handler():
    from symcat.simulation import integrate_model
    from tests.codegen.test_model_dae import _wheelset

    p = {"integrator": "generalized_alpha", "dt": 1e-3, "rho_inf": 0.9}
    res = integrate_model(_wheelset(), p, 0.01, "augmented", "ggl", n_out=2, progress=False)
    assert res.t_s[-1] == pytest.approx(0.01) and res.stats["steps"] == 10
    assert res.stats["contact_calls"] >= 1  # through the event driver, the contact handler attached
    with pytest.raises(ParameterError, match=r"formulation=embedded with integrator=generalized_alpha"):
        integrate_model(_wheelset(), p, 0.01, "embedded", "1")
