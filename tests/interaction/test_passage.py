"""Pantograph passages: analytic moving force, static contact, penalty vs bilateral, contact loss."""
import math

import numpy as np
import pytest

from symcat.catenary import CatenaryDesign, Wire, benchmark2015, find_form
from symcat.errors import ParameterError
from symcat.interaction import CoupledLine, PantographRun, integrate
from symcat.interaction.contact import WireLocator
from symcat.interaction.passage import run_passage
from symcat.pantograph import LumpedPantograph, benchmark2015_pantograph

WIRE = Wire(tension=22000.0, mass_per_length=1.35, EA=1.5e7, EI=195.0)


def _bare_wire(elements: int):
    """One 55 m span whose contact wire is effectively free between its end pins: soft
    droppers, no gravity to speak of, no damping."""
    d = CatenaryDesign(n_spans=1, span_length=55.0, encumbrance=1.2, dropper_positions=(27.5,), presag=(0.0,),
                       contact_wire=WIRE, messenger_wire=Wire(16000.0, 1.08, 1.164e7, 131.7), dropper_EA=1.0,
                       dropper_stiffness=1e-3, gravity=1e-6, stagger=0.0)
    return find_form(d, elements)


def _moving_force_on_beam_string(x, t, force, speed, L, T, EI, m, modes=3000):
    """Pinned-pinned tensioned beam under a constant moving force from x=0 at rest: modal series."""
    n = np.arange(1, modes + 1)
    k = n * np.pi / L
    omega = np.sqrt((T * k**2 + EI * k**4) / m)
    big = k * speed
    amp = 2 * force / (m * L) / (omega**2 - big**2)
    return np.sum(amp * np.sin(k * x) * (np.sin(big * t) - big / omega * np.sin(omega * t)))


def test_moving_force_matches_modal_solution():
    form = _bare_wire(40)
    force, speed = 100.0, 0.5 * WIRE.wave_speed
    probe = LumpedPantograph((1e-4,), (0.0,), (0.0,), uplift=force)  # a weightless constant force
    line = CoupledLine(form, [PantographRun(probe, 0.0)], speed, contact="bilateral")
    t_end = 0.8 * 55.0 / speed
    rec = integrate(line, t_end, dt=2.5e-4, rho_inf=1.0, tol=1e-10, progress=False)
    st = form.structure
    mid = np.argmin(np.abs(st.x - 27.5))
    z0 = st.contact_wire_z(form.q)[mid]
    snaps = rec.snapshot_t_s
    sim = np.array([st.contact_wire_z(q)[mid] for q in rec.snapshot_q]) - z0
    exact = np.array([_moving_force_on_beam_string(27.5, t, force, speed, 55.0, WIRE.tension, WIRE.EI,
                                                   WIRE.mass_per_length) for t in snaps])
    assert np.max(np.abs(exact)) > 0.05  # the load really deflects the wire by several cm
    assert np.max(np.abs(sim - exact)) < 0.01 * np.max(np.abs(exact))
    # the contact force of a weightless pan-head is the applied force (the multiplier of the
    # undamped scheme, rho_inf = 1, chatters at the step frequency; filtered it is the force)
    from symcat.interaction.statistics import lowpass

    settle = int(0.06 / 2.5e-4)  # the zero-phase filter's edges need ~50 ms to settle
    filtered = lowpass(rec.t_s, rec.contact_force_N[:, 0])[settle:-settle]
    np.testing.assert_allclose(filtered, force, rtol=5e-3)


@pytest.fixture(scope="module")
def short_line():
    return find_form(benchmark2015(n_spans=5), 20)


@pytest.mark.parametrize("contact", ["penalty", "bilateral"])
def test_static_contact_force_is_the_uplift(short_line, contact):
    panto = benchmark2015_pantograph(250)
    line = CoupledLine(short_line, [PantographRun(panto, 100.0)], 250 / 3.6, contact=contact)
    y, fc = line.static_state()
    assert fc[0] == pytest.approx(panto.uplift, rel=1e-9)
    states = line.contact_states(y, np.zeros(line.n), 0.0)
    expected_gap = panto.uplift / line.k_c if contact == "penalty" else 0.0
    assert states[0].delta == pytest.approx(expected_gap, abs=1e-9)


def _stats(form, contact, kmh, uplift=None, stiffness=5.0e4):
    panto = benchmark2015_pantograph(kmh)
    if uplift is not None:
        panto = LumpedPantograph(panto.masses, panto.stiffness, panto.damping, uplift)
    return run_passage(form.structure.design, [panto], kmh / 3.6, contact=contact, analysis_spans=1, form=form,
                       progress=False, contact_stiffness=stiffness)


def test_stiffer_penalty_converges_to_the_bilateral_contact(short_line):
    bil = _stats(short_line, "bilateral", 200).statistics[0]
    soft = _stats(short_line, "penalty", 200).statistics[0]
    stiff = _stats(short_line, "penalty", 200, stiffness=5.0e5).statistics[0]
    assert soft["contact_loss_percent"] == 0.0
    for s in (soft, stiff):
        assert s["contact_force_mean_N"] == pytest.approx(bil["contact_force_mean_N"], rel=0.01)
    assert stiff["contact_force_std_N"] == pytest.approx(bil["contact_force_std_N"], rel=0.05)
    assert abs(stiff["contact_force_std_N"] - bil["contact_force_std_N"]) < abs(
        soft["contact_force_std_N"] - bil["contact_force_std_N"])


def test_contact_loss_and_recontact_without_step_collapse(short_line):
    res = _stats(short_line, "penalty", 0.9 * 459.6, uplift=40.0)
    rec = res.record
    f = rec.contact_force_N[:, 0]
    lost = f <= 0
    assert lost.any() and (~lost).any()
    assert np.sum(np.diff(lost.astype(int)) == -1) >= 2  # several re-contacts
    assert res.statistics[0]["contact_loss_percent"] > 0
    assert rec.stats["halvings"] == 0 and rec.iterations.max() <= 12
    assert np.all(f >= 0)
    # droppers near the pantograph go slack under the uplift wave and take load again
    slack = rec.dropper_tension_N <= 0
    assert slack.any() and np.any(np.diff(slack.astype(int), axis=0) == -1)
    assert not slack[0].any()
    # the bilateral model on the same run must pull (negative force) where the penalty lets go
    bil = _stats(short_line, "bilateral", 0.9 * 459.6, uplift=40.0)
    assert bil.record.contact_force_N[:, 0].min() < 0


def test_wire_locator_matches_compiled_position_kernel(short_line):
    from symcat.codegen.library import kernel_library

    st = short_line.structure
    dofs = st.system.dofs
    body = st.contacts[0]
    lengths = body.params[:, 0]
    loc = WireLocator(st.cw_xyz[:, 0], [dofs.index(body, k, "x_x") for k in range(body.n_nodes)], st.cw_xyz[:, 2],
                      st.cw_zx, lengths)
    q = short_line.q
    position = kernel_library("cable3d")["cable3d_position"]
    for x in (3.1, 27.4, 131.0, 250.2):
        point = loc.locate(q, x)
        e = q[dofs.element_indices(body)[point.element]]
        r, _ = position(e, point.xi, body.params[point.element])
        assert float(r[0]) == pytest.approx(x, abs=1e-10)
        assert point.height(q) == pytest.approx(float(r[2]), abs=1e-12)


def test_bad_inputs_name_the_parameter(short_line):
    panto = benchmark2015_pantograph(250)
    with pytest.raises(ParameterError, match="speed"):
        CoupledLine(short_line, [PantographRun(panto, 100.0)], 130.0)
    with pytest.raises(ParameterError, match="x_start"):
        CoupledLine(short_line, [PantographRun(panto, -5.0)], 50.0)
    with pytest.raises(ParameterError, match="contact"):
        CoupledLine(short_line, [PantographRun(panto, 10.0)], 50.0, contact="sticky")
    with pytest.raises(ParameterError, match="uplift"):
        LumpedPantograph((1.0,), (1.0,), (0.0,), uplift=-3.0)
    with pytest.raises(ParameterError, match="n_spans"):
        run_passage(short_line.structure.design, [panto, panto], 60.0, spacing=200.0, form=short_line, progress=False)


def test_two_pantographs_each_get_statistics():
    from symcat.interaction.passage import spans_needed

    d = benchmark2015(n_spans=spans_needed(55.0, 2, 110.0, analysis_spans=1))
    form = find_form(d, 10)
    panto = benchmark2015_pantograph(250)
    res = run_passage(d, [panto, panto], 250 / 3.6, spacing=110.0, analysis_spans=1, form=form, progress=False,
                      elements_per_span=10)
    assert len(res.statistics) == 2
    for s in res.statistics:
        assert 100 < s["contact_force_mean_N"] < 200
    assert math.isclose(res.record.x_contact_m[0, 0] - res.record.x_contact_m[0, 1], 110.0)  # leading first


def test_linearized_wires_agree_with_nonlinear_ancf(short_line):
    """Around the static catenary the wires' geometric nonlinearity is small: the two models
    must give the same statistics (and the linear one must really differ in the forces)."""
    d = short_line.structure.design
    runs = {w: run_passage(d, [benchmark2015_pantograph(250)], 250 / 3.6, analysis_spans=1, form=short_line,
                           wires=w, progress=False) for w in ("linear", "nonlinear")}
    a, b = runs["linear"].statistics[0], runs["nonlinear"].statistics[0]
    for key in ("contact_force_mean_N", "contact_force_std_N", "contact_force_max_N"):
        assert a[key] == pytest.approx(b[key], rel=5e-3)
    assert not np.array_equal(runs["linear"].record.contact_force_N, runs["nonlinear"].record.contact_force_N)
    short_line.structure.linearize_wires(None)


@pytest.mark.parametrize("rayleigh", [0.0, 1.0])
def test_energy_balance_closes(rayleigh):
    """Energy change = work of the moving contact - damper dissipation (undamped and damped)."""
    d = benchmark2015(n_spans=5)
    d = d.with_(rayleigh_alpha=rayleigh * d.rayleigh_alpha, rayleigh_beta=rayleigh * d.rayleigh_beta)
    form = find_form(d, 20)
    res = run_passage(d, [benchmark2015_pantograph(250)], 250 / 3.6, form=form, progress=False, dt=5e-4,
                      rho_inf=1.0, analysis_spans=1)
    balance = res.record.energy_balance()
    assert balance["work_scale_J"] > 5.0
    assert np.abs(balance["error_J"]).max() < 0.01 * balance["work_scale_J"]
    if rayleigh:
        assert np.sum(res.record.dissipation_power_W) > 0


def test_solver_failure_reports_time_and_keeps_the_record(short_line):
    from symcat.errors import SolverError

    panto = benchmark2015_pantograph(250)
    line = CoupledLine(short_line, [PantographRun(panto, 100.0)], 250 / 3.6)
    with pytest.raises(SolverError, match=r"t=\d") as info:
        integrate(line, 0.05, dt=1e-3, tol=1e-14, max_iterations=1, progress=False)
    partial = info.value.partial
    assert partial is not None and len(partial.t_s) >= 1  # the static start at least


def test_statistics_converge_with_the_time_step(short_line):
    """The filter settles past the section end, so the statistics do not drift with dt."""
    d = short_line.structure.design
    stats = [run_passage(d, [benchmark2015_pantograph(250)], 250 / 3.6, analysis_spans=1, form=short_line,
                         progress=False, dt=dt).statistics[0] for dt in (2e-3, 5e-4)]
    assert stats[0]["contact_force_mean_N"] == pytest.approx(stats[1]["contact_force_mean_N"], rel=2e-3)
    assert stats[0]["contact_force_std_N"] == pytest.approx(stats[1]["contact_force_std_N"], rel=1e-2)
