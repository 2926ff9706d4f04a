"""The seed's complete scene on the benchmark line (``models/seo2005_line.py``): the vehicle
carries the four-body pantograph under the form-found catenary from their joint static
equilibrium. Small lines (3 spans, one element per dropper interval) and a few hundredths of a
second keep the file short."""
from __future__ import annotations

import numpy as np
import pytest

from symcat import cli
from symcat.integrate import IdasSettings
from symcat.interaction.scene_pantographs import seo2005_fragment, trim_uplifts
from symcat.model import load_model
from symcat.simulation import integrate_model
from symcat.vehicle import wheel_forces

SMALL = {"spans": 3, "t_end": 0.05, "n_out": 400, "progress": False, "integrator": "idas"}


@pytest.fixture(scope="module")
def small_run():
    model = load_model("seo2005_line")
    return model.run(model.resolve(SMALL))


def test_at_rest_the_wheels_carry_vehicle_pantograph_and_the_wires_push(small_run):
    s, sim, layout, line = (small_run.summary, small_run.arrays["simulation"], small_run.arrays["layout"],
                            small_run.arrays["line"])
    g = 9.81
    forces = wheel_forces(sim, layout)
    q0 = sum(forces[n]["Q_N"][0] for n in layout.contact_names)
    # The wire pushes the pan-head down with the static contact force: the wheels carry it with
    # the weights (the pantograph's uplift acts between roof and frame, an internal force).
    expected = (layout.parameters.total_mass_kg + 22.0) * g + s["static_contact_force_N"]
    assert line.pantograph_mass_kg == 22.0
    np.testing.assert_allclose(q0, expected, rtol=1e-6)
    np.testing.assert_allclose(s["static_wheel_load_sum_N"], s["static_weight_and_push_N"], rtol=1e-6)
    # ... and it is a static state, not a preload bookkeeping: no body accelerates at t = 0
    # (the wheel loads above are the KKT multipliers of the same solve).
    assert abs(s["static_vertical_momentum_rate_N"]) < 1e-6 * expected
    names = sim.coordinate_names
    for body in ["car_body", *line.pantograph_bodies]:
        k = names.index(f"{body}.x")
        assert np.abs(sim.a[0, k: k + 3]).max() < 1e-3, (body, sim.a[0, k: k + 3])
    wires = [k for k, n in enumerate(names) if n.startswith(("contact[", "messenger["))]
    assert np.abs(sim.a[0, wires]).max() < 1e-4
    assert s["static_residual_N"] < 1e-5
    # symmetric vehicle, load shared equally by the wheels of each wheelset side
    w = np.array(s["wheel_normal_force_static_N"])
    np.testing.assert_allclose(w, w.mean(), rtol=1e-8)


def test_static_contact_force_is_the_target_and_the_panhead_sits_on_the_wire(small_run):
    s, sim, line = small_run.summary, small_run.arrays["simulation"], small_run.arrays["line"]
    target = 0.00097 * (3.6 * 17.0) ** 2 + 70.0  # EN 50367 at 17 m/s
    assert s["target_static_contact_force_N"] == pytest.approx(target, rel=1e-12)
    assert s["static_contact_force_N"] == pytest.approx(target, rel=1e-8)
    contact = sim.contacts["pantograph_contact"]
    assert contact["force_N"][0] == pytest.approx(target, rel=1e-8)
    # pressing on the wire: the penalty law's penetration F / k, plus at most its smoothing depth (1e-5 m)
    assert -target / 5.0e4 - 1.1e-5 < contact["gap_m"][0] < -target / 5.0e4
    # at its start, a support, on the roof: base hinge 2.5 m under the wire at 6.3 m
    assert line.x_start_m == 55.0 and s["base_hinge_height_m"] == pytest.approx(3.8, abs=1e-6)
    z = sim.coordinate("pantograph_panhead.z")[0]
    assert 6.3 < z < 6.32  # the static uplift lifts the wire about 1 cm
    assert s["uplift_static_solves"] <= 8


def test_a_short_idas_run_keeps_the_static_force_and_the_vehicle_carries_like_a_fixed_carrier(small_run):
    s, sim, line = small_run.summary, small_run.arrays["simulation"], small_run.arrays["line"]
    force = sim.contacts["pantograph_contact"]["force_N"]
    static = s["static_contact_force_N"]
    # The wire starts at rest under a load that starts moving: an 8 % dip at 25 ms (a start
    # transient of the catenary, the reason passages have a lead-in span); the mean over the
    # first 50 ms is 4 % low (2.4 % over 0.2 s), aerodynamics (none) and dampers aside.
    assert abs(np.mean(force) / static - 1) < 0.05
    assert s["contact_force_run_mean_N"] == pytest.approx(np.mean(force), rel=1e-12)
    assert s["contact_loss_percent"] is None and s["analysis_complete"] is False  # section not reached
    for key in ("wheel_normal_force_min_N", "wheel_normal_force_max_N", "wheel_normal_force_static_N"):
        assert len(s[key]) == 8 and np.all(np.isfinite(s[key])) and min(s[key]) > 5e4
    assert max(s["wheelset_lateral_displacement_max_m"]) < 1e-9
    # The same pantograph on its driven carrier (the scene passage's fragment) presses the same:
    # the vehicle under it stays still vertically, so the contact force is the catenary's.
    u, _, (_, carrier, _, eq), _ = trim_uplifts(line.form, [seo2005_fragment("penalty")], line.target_force_N,
                                                "contact", [line.x_start_m], 17.0)
    assert u[0] == pytest.approx(s["uplift_N"], rel=1e-9)
    eq.apply(carrier)
    alone = integrate_model(carrier, {"integrator": "idas"}, 0.05, "augmented", "ggl",
                            IdasSettings(rtol=1e-6, atol=1e-8, n_out=len(sim.t_s) - 1, progress=False))
    np.testing.assert_allclose(force, alone.contacts["pantograph_contact"]["force_N"], atol=0.02)


def test_the_same_short_run_on_generalized_alpha(small_run):
    model = load_model("seo2005_line")
    out = model.run(model.resolve({**SMALL, "integrator": "generalized_alpha", "dt": 1e-3}))
    s = out.summary
    assert abs(s["contact_force_run_mean_N"] / s["static_contact_force_N"] - 1) < 0.05
    assert np.all(np.isfinite(s["wheel_normal_force_min_N"])) and min(s["wheel_normal_force_min_N"]) > 5e4
    # IDAS's run at the same outputs (0.05 N apart over 0.2 s, measured)
    idas = small_run.arrays["simulation"].contacts["pantograph_contact"]["force_N"]
    np.testing.assert_allclose(out.arrays["simulation"].contacts["pantograph_contact"]["force_N"], idas, atol=0.1)
    np.testing.assert_allclose(s["wheel_normal_force_max_N"], small_run.summary["wheel_normal_force_max_N"], atol=1.0)


@pytest.mark.parametrize("values, text", [
    (["speed_ms=100"], "speed_ms=100 m/s: must be a number > 0 and <= 89.3"),
    (["spans=2"], "spans=2: must be an integer >= 3"),
    (["spans=3", "analysis_spans=2", "t_end=0.05"], "spans=3, analysis_spans=2: the pantograph would start at x=27.5"),
    (["spans=3"], "spans=3: the passage over 1 analysis span(s)"),
    (["t_end=0"], "t_end=0 s: must be > 0, or -1"),
    (["static_force_N=0"], "static_force_N=0 N: must be > 0, or -1"),
    (["formulation=eq27"], "formulation=eq27: must be one of augmented, embedded"),
])
def test_bad_input_is_one_line_naming_the_parameter(values, text, tmp_path, capsys):
    args = ["run", "seo2005_line", "--out", str(tmp_path / "out")]
    for v in values:
        args += ["--set", v]
    assert cli.main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and text in err[0], err
    assert not (tmp_path / "out").exists()
