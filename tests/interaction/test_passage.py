"""Pantograph passages on the shared multibody path (the lumped pantograph as scene bodies under
the catenary scene, generalized-alpha): analytic moving force, static contact force, penalty
against bilateral contact, contact loss, bad inputs, solver failure and time-step convergence.

The short line (5 spans, 10 elements per span, one analysis span) keeps the default run fast;
the physics each test checks does not need a finer mesh.
"""
import numpy as np
import pytest

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary import CatenaryDesign, Wire, benchmark2015, find_form
from symcat.catenary.scene import catenary_scene
from symcat.errors import ParameterError, SolverError
from symcat.integrate import generalized_alpha
from symcat.interaction.scene_passage import lumped_fragment, run_scene_passage
from symcat.interaction.statistics import lowpass
from symcat.model import run_model
from symcat.pantograph import LumpedPantograph, benchmark2015_pantograph
from symcat.pantograph.lumped_scene import add_lumped_pantograph

WIRE = Wire(tension=22000.0, mass_per_length=1.35, EA=1.5e7, EI=195.0)
#: The short line of the passages below (benchmark2015 model parameters).
SHORT = dict(n_spans=5, elements_per_span=10, analysis_spans=1, progress=False, paraview=False,
             snapshot_interval=0.2)


def _bare_wire(elements: int):
    """One 55 m span whose contact wire is effectively free between its end pins: soft
    droppers, no gravity to speak of, no damping."""
    d = CatenaryDesign(n_spans=1, span_length=55.0, encumbrance=1.2, dropper_positions=(27.5,), presag=(0.0,),
                       contact_wire=WIRE, messenger_wire=Wire(16000.0, 1.08, 1.164e7, 131.7), dropper_EA=1.0,
                       dropper_stiffness=1e-3, gravity=1e-6, stagger=0.0)
    return find_form(d, elements, progress=False)


def _moving_force_on_beam_string(x, t, force, speed, L, T, EI, m, modes=3000):
    """Pinned-pinned tensioned beam under a constant moving force from x=0 at rest: modal series."""
    n = np.arange(1, modes + 1)
    k = n * np.pi / L
    omega = np.sqrt((T * k**2 + EI * k**4) / m)
    big = k * speed
    amp = 2 * force / (m * L) / (omega**2 - big**2)
    return np.sum(amp * np.sin(k * x) * (np.sin(big * t) - big / omega * np.sin(omega * t)))


def test_moving_force_matches_modal_solution():
    """A weightless pan-head pressed up by a constant force, held on the wire by a sliding joint
    and driven from the end pin at half the wave speed: the wire's mid-span deflection is the
    modal series' (an independent, analytic computation), and the joint carries the force."""
    form = _bare_wire(40)
    force, speed = 100.0, 0.5 * WIRE.wave_speed
    probe = LumpedPantograph((1e-4,), (0.0,), (0.0,), uplift=force)  # a weightless constant force
    scene = catenary_scene(form)
    info = add_lumped_pantograph(scene, probe, "contact", 0.0, speed, contact="bilateral")
    model = MultibodyModel(scene)
    solve_equilibrium(model).apply(model)
    t_end, dt = 0.8 * 55.0 / speed, 2.5e-4
    res = generalized_alpha(model, t_end, dt, 1.0, n_out=round(t_end / dt), tol=1e-10, progress=False,
                            multipliers="integrator")
    names = res.coordinate_names
    xs = np.array([model.q0[names.index(f"contact[{k}].x")] for k in range(41)])
    mid = int(np.argmin(np.abs(xs - 27.5)))
    assert xs[mid] == pytest.approx(27.5)
    z = res.coordinate(f"contact[{mid}].z")
    sim = z - z[0]
    exact = np.array([_moving_force_on_beam_string(27.5, t, force, speed, 55.0, WIRE.tension, WIRE.EI,
                                                   WIRE.mass_per_length) for t in res.t_s])
    assert np.max(np.abs(exact)) > 0.05  # the load really deflects the wire by several cm
    assert np.max(np.abs(sim - exact)) < 0.01 * np.max(np.abs(exact))
    # the joint's reaction on the weightless pan-head is the applied force (filtered: the
    # undamped scheme, rho_inf = 1, lets the multiplier chatter at the step frequency)
    reaction = -res.reactions_N[info["contact"]][:, 2]
    settle = int(0.06 / np.median(np.diff(res.t_s)))  # the zero-phase filter's edges need ~50 ms to settle
    np.testing.assert_allclose(lowpass(res.t_s, reaction)[settle:-settle], force, rtol=5e-3)


@pytest.fixture(scope="module")
def short_line():
    return find_form(benchmark2015(n_spans=SHORT["n_spans"]), SHORT["elements_per_span"], progress=False)


@pytest.mark.parametrize("contact", ["penalty", "bilateral"])
def test_static_contact_force_is_the_uplift(short_line, contact):
    """The lumped pantograph's weights are cancelled and its roof held: in the static state the
    contact carries exactly the uplift (plus the aerodynamic force), so trimming the uplift to
    that force gives back the pantograph's own uplift."""
    panto = benchmark2015_pantograph(250)
    speed = 250 / 3.6
    target = float(panto.static_force(speed).sum())
    assert target == pytest.approx(panto.uplift + panto.aero_coefficient * speed**2)
    res = run_scene_passage(short_line.structure.design, lumped_fragment(panto, contact, form=short_line), speed,
                            target, form=short_line, analysis_spans=1, t_end=0.0, progress=False)
    assert res.static_contact_force_N == pytest.approx(target, rel=1e-5)
    assert res.uplift_N == pytest.approx(panto.uplift, rel=1e-5)
    assert res.static_solves <= 2


def _passage(**kw):
    run = run_model("benchmark2015", {**SHORT, **kw})
    return run.summary, run.arrays["result"].record


def test_stiffer_penalty_converges_to_the_bilateral_contact():
    bil = _passage(speed_kmh=200.0, contact="bilateral")[0]
    soft = _passage(speed_kmh=200.0)[0]
    stiff = _passage(speed_kmh=200.0, contact_stiffness=5.0e5)[0]
    assert soft["contact_loss_percent"] == 0.0
    for s in (soft, stiff):
        assert s["contact_force_mean_N"] == pytest.approx(bil["contact_force_mean_N"], rel=0.01)
    assert stiff["contact_force_std_N"] == pytest.approx(bil["contact_force_std_N"], rel=0.05)
    assert abs(stiff["contact_force_std_N"] - bil["contact_force_std_N"]) < abs(
        soft["contact_force_std_N"] - bil["contact_force_std_N"])


def test_contact_loss_and_recontact_without_step_collapse():
    near_wave_speed = dict(speed_kmh=0.9 * 459.6, uplift_N=40.0)
    s, rec = _passage(**near_wave_speed)
    f = rec.contact_force_N[:, 0]
    lost = f <= 0
    assert lost.any() and (~lost).any()
    assert np.sum(np.diff(lost.astype(int)) == -1) >= 2  # several re-contacts
    assert s["contact_loss_percent"] > 0
    assert rec.stats["halvings"] == 0 and rec.stats["newton_iterations"] <= 4 * rec.stats["steps"]
    assert np.all(f >= 0)
    # droppers near the pantograph go slack under the uplift wave and take load again
    slack = rec.dropper_tension_N <= 0
    assert slack.any() and np.any(np.diff(slack.astype(int), axis=0) == -1)
    assert not slack[0].any()
    # the bilateral model on the same run must pull (negative force) where the penalty lets go
    _, bil = _passage(**near_wave_speed, contact="bilateral")
    assert bil.contact_force_N[:, 0].min() < 0


def test_bad_inputs_name_the_parameter(short_line):
    panto = benchmark2015_pantograph(250)
    design = short_line.structure.design
    with pytest.raises(ParameterError, match="speed_kmh=500"):
        run_model("benchmark2015", {**SHORT, "speed_kmh": 500.0})
    with pytest.raises(ParameterError, match="speed=0"):
        run_scene_passage(design, lumped_fragment(panto), 0.0, 120.0, form=short_line, progress=False)
    with pytest.raises(ParameterError, match="target_force=-1"):
        run_scene_passage(design, lumped_fragment(panto), 50.0, -1.0, form=short_line, progress=False)
    with pytest.raises(ParameterError, match="x=-5"):
        add_lumped_pantograph(catenary_scene(short_line), panto, "contact", -5.0, 50.0)
    with pytest.raises(ParameterError, match="contact='sticky'"):
        add_lumped_pantograph(catenary_scene(short_line), panto, "contact", 10.0, 50.0, contact="sticky")
    with pytest.raises(ParameterError, match="uplift"):
        LumpedPantograph((1.0,), (1.0,), (0.0,), uplift=-3.0)
    with pytest.raises(ParameterError, match="n_spans"):
        run_scene_passage(design, [lumped_fragment(panto, name="a"), lumped_fragment(panto, name="b")], 60.0, 120.0,
                          spacing=200.0, form=short_line, progress=False)


def test_solver_failure_reports_time_and_keeps_the_record(short_line):
    """A passage whose Newton iteration cannot converge (tolerance below round-off) stops with
    the time of the failing step in the message and what was computed before it."""
    panto = benchmark2015_pantograph(250)
    with pytest.raises(SolverError, match=r"t = \d") as info:
        run_scene_passage(short_line.structure.design, lumped_fragment(panto, form=short_line), 250 / 3.6,
                          float(panto.static_force(250 / 3.6).sum()), form=short_line, analysis_spans=1, t_end=0.05,
                          tol=1e-15, progress=False)
    partial = info.value.partial
    assert partial is not None and len(partial.t_s) >= 1 and partial.t_s[0] == 0.0  # the static start at least


def test_statistics_converge_with_the_time_step():
    """The filter settles past the section end, so the statistics do not drift with dt."""
    stats = [_passage(speed_kmh=250.0, dt=dt)[0] for dt in (2e-3, 5e-4)]
    assert stats[0]["contact_force_mean_N"] == pytest.approx(stats[1]["contact_force_mean_N"], rel=2e-3)
    assert stats[0]["contact_force_std_N"] == pytest.approx(stats[1]["contact_force_std_N"], rel=1e-2)
