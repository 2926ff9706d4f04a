"""The generalized-alpha integrator of the multibody formulation
(:mod:`symcat.integrate.generalized_alpha`) against IDAS: convergence orders on a rigid double
pendulum, bounded energy without numerical dissipation, a body on a sliding joint on a flexible
wire, element windows moving between steps, penalty contacts, the start on a stiff beam3d
catenary, halving of failed steps, and its parameter checks."""
from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError, SolverError
from symcat.integrate import simulate
from symcat.integrate.generalized_alpha import generalized_alpha, integrate_alpha
from symcat.model import model_path
from tests.dynamics.test_contact import head_under_wire
from tests.dynamics.test_sliding import ring

G = 9.81


def _scene_module(name):
    """The module of a shipped model (for its ``build``)."""
    spec = importlib.util.spec_from_file_location(f"alpha_test_{name}", model_path(name))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _defaults(module) -> dict:
    return {p.name: p.default for p in module.PARAMETERS}


def pendulum_scene():
    """The shipped double pendulum (two 1 m, 1 kg rods released at 90 and 45 degrees)."""
    module = _scene_module("pendulum")
    return module.build(_defaults(module))


def pendulum():
    return MultibodyModel(pendulum_scene())


def _slope(dt, err) -> float:
    return float(np.polyfit(np.log(dt), np.log(err), 1)[0])


@pytest.fixture(scope="module")
def pendulum_reference():
    # rtol 1e-11: its own error (~1e-9) is far below the coarsest alpha error used here.
    return simulate(pendulum(), 1.0, rtol=1e-11, atol=1e-13, n_out=10, progress=False)


@pytest.mark.parametrize("variant", ["stabilized", "index3"])
def test_pendulum_converges_with_order_two(variant, pendulum_reference, record_property):
    """Errors at t = 1 s (after 100-800 steps; the index-3 form's start-up transient in the
    multipliers has died out by then) fall like dt^2 in positions, velocities and multipliers."""
    ref = pendulum_reference
    dts = np.array([8e-3, 4e-3, 2e-3, 1e-3])
    errors = []
    for dt in dts:
        run = integrate_alpha(pendulum(), 1.0, dt, rho_inf=0.9, variant=variant, tol=1e-12, n_out=10, progress=False)
        res = run.result()
        errors.append([np.abs(res.q[-1] - ref.q[-1]).max(), np.abs(res.v[-1] - ref.v[-1]).max(),
                       np.abs(run.multipliers[-1] - ref.multipliers[-1]).max()])
    errors = np.array(errors)
    orders = [_slope(dts, errors[:, j]) for j in range(3)]
    record_property("orders_q_v_lambda", orders)
    record_property("errors_at_finest_dt", errors[-1].tolist())
    print(f"{variant}: orders q {orders[0]:.3f}, v {orders[1]:.3f}, lambda {orders[2]:.3f}; errors at dt = 1 ms "
          f"{errors[-1, 0]:.3g} m, {errors[-1, 1]:.3g} m/s, {errors[-1, 2]:.3g} N")
    assert 1.8 <= orders[0] <= 2.3
    assert 1.8 <= orders[1] <= 2.3
    assert 1.7 <= orders[2] <= 2.5
    assert errors[-1, 0] < 5e-5  # m, rad (Euler parameters)


def test_stabilized_multipliers_have_no_start_up_transient():
    """A pendulum launched spinning: the stabilized form's multipliers are second order from
    the first steps (with the starting value a_0 = v_dot(t_0 + (alpha_m - alpha_f) h)), where
    the index-3 form's carry an O(1) start-up error."""
    def spinning():  # rod 1 turning at 3 rad/s about the upper hinge, rod 2 translating with it
        scene = pendulum_scene()
        rod1, rod2 = scene.rigid_bodies
        omega = np.array([0.0, 0.0, 3.0])
        rod1.velocity, rod1.angular_velocity = tuple(np.cross(omega, rod1.position)), tuple(omega)
        rod2.velocity = tuple(np.cross(omega, 2 * np.asarray(rod1.position)))
        return MultibodyModel(scene)

    ref = simulate(spinning(), 0.04, rtol=1e-12, atol=1e-14, n_out=4, progress=False)
    dts = np.array([1e-2, 5e-3, 2.5e-3])
    err = {}
    for variant in ("stabilized", "index3"):
        err[variant] = [np.abs(integrate_alpha(spinning(), 0.04, dt, rho_inf=0.9, variant=variant, tol=1e-13, n_out=4,
                                               progress=False).multipliers[1:] - ref.multipliers[1:]).max()
                        for dt in dts]
    assert _slope(dts, err["stabilized"]) > 1.8
    assert err["stabilized"][-1] < 2e-3          # N, on multipliers of 10-40 N
    assert err["index3"][-1] > 100 * err["stabilized"][-1]


def test_undamped_pendulum_keeps_its_energy():
    """rho_inf = 1 (no numerical dissipation): the energy error of the chaotic double pendulum
    stays bounded (no drift) over 4 s = 1000 steps, and the constraints hold to the Newton
    tolerance (1e-10 by default; the velocity rows are scaled by beta h / gamma)."""
    res = generalized_alpha(pendulum(), 4.0, 4e-3, rho_inf=1.0, n_out=200, progress=False)
    e = res.energy_J["total"]
    scale = 2 * 1.0 * G * 1.0  # J: m g L of the two rods
    change = np.abs(e - e[0]) / scale
    half = len(e) // 2
    assert change.max() < 1e-3
    assert change[half:].max() < 3 * change[:half].max()  # bounded, not growing
    assert res.position_drift.max() < 1e-9
    assert res.velocity_drift.max() < 1e-7
    print(f"energy change {change.max():.3g} m g L, drifts {res.position_drift.max():.3g} m, "
          f"{res.velocity_drift.max():.3g} m/s")


@pytest.fixture(scope="module")
def slider_case():
    module = _scene_module("slider_on_wire")
    params = {**_defaults(module), "n_elements": 8, "t_end": 0.2}

    def model():  # window of 16 elements: the whole wire of 8
        return MultibodyModel(module.build(params), window=16)

    ref = simulate(model(), 0.2, rtol=1e-9, atol=1e-11, n_out=10, progress=False)
    return model, ref


def test_slider_on_a_flexible_wire_matches_idas(slider_case, record_property):
    """A body hanging from a sliding joint on a pretensioned 8-element ANCF wire: the arc length
    and the body's position agree with IDAS within the O(dt^2) error of the step, and the result
    has everything simulate()'s has."""
    model, ref = slider_case
    off = model().rigid_offset["body"]
    s_err, body_err = [], []
    for dt in (2e-3, 1e-3):
        res = generalized_alpha(model(), 0.2, dt, rho_inf=0.9, tol=1e-10, n_out=10, progress=False)
        s_err.append(np.abs(res.s_m[:, 0] - ref.s_m[:, 0]).max())
        body_err.append(np.abs(res.q[:, off : off + 3] - ref.q[:, off : off + 3]).max())
    record_property("s_errors_m", s_err)
    record_property("body_errors_m", body_err)
    print(f"slider: s errors {s_err} m, body errors {body_err} m (dt = 2, 1 ms)")
    assert s_err[-1] < 1e-6 and body_err[-1] < 3e-5
    assert s_err[0] / s_err[1] > 3 and body_err[0] / body_err[1] > 3  # about dt^2
    force, force_ref = res.reactions_N["slider"], ref.reactions_N["slider"]
    assert np.abs(force - force_ref).max() < 0.05 * np.abs(force_ref).max()
    assert res.position_drift.max() < 1e-10
    for name in ("t_s", "q", "v", "s_m", "s_dot_m_s", "multipliers", "a", "output_wall_s"):
        assert getattr(res, name).shape[0] == ref.t_s.shape[0], name
    assert set(res.energy_J) == {"kinetic", "potential", "total"}
    assert res.stats["steps"] == 200 and res.stats["factorizations"] <= res.stats["newton_iterations"]


def test_element_windows_move_between_steps():
    """The bead crosses 16 element ends; its 6-element window moves (the step equations are
    rebuilt) and the motion is that of a run whose window is the whole ring."""
    moving = generalized_alpha(ring(32, window=6), 0.6, 2e-3, n_out=30, progress=False)
    whole = generalized_alpha(ring(32, window=32), 0.6, 2e-3, n_out=30, progress=False)
    assert moving.stats["rebuilds"] >= 5 and whole.stats["rebuilds"] == 0
    s = moving.s_m[:, 0]
    np.testing.assert_allclose(s, s[0] + 5.0 * moving.t_s, atol=3e-5)  # uniform motion on a frictionless ring
    np.testing.assert_allclose(moving.s_m, whole.s_m, atol=1e-6)
    force = np.linalg.norm(moving.reactions_N["joint"], axis=1)
    np.testing.assert_allclose(force, 0.3 * 25.0 / 1.0, rtol=3e-3)


@pytest.mark.parametrize("kwargs, name", [({"dt": 0.0}, "dt"), ({"dt": -1e-3}, "dt"), ({"dt": float("nan")}, "dt"),
                                          ({"rho_inf": -0.1}, "rho_inf"), ({"rho_inf": 1.5}, "rho_inf"),
                                          ({"variant": "index2"}, "variant"), ({"t_end": 0.0}, "t_end"),
                                          ({"max_iterations": 0}, "max_iterations"),
                                          ({"max_halvings": -1}, "max_halvings")])
def test_bad_parameters_are_named(kwargs, name):
    args = {"t_end": 1.0, "dt": 1e-3, **kwargs}
    with pytest.raises(ParameterError, match=rf"^{name}="):
        generalized_alpha(pendulum(), progress=False, **args)


def test_a_failed_step_keeps_the_result_so_far():
    """One Newton iteration per step cannot converge from a step of 0.1 s, nor from its halves
    down to 0.1 s / 16: the error names the time, the step and the smallest step tried, and
    carries the outputs computed before it as a SimulationResult."""
    with pytest.raises(SolverError, match=r"t = 0\.1 s \(dt = 0\.1 s\).*halved 4 times \(the last try, 0\.00625 s "
                                          r"from t = 0 s") as info:
        generalized_alpha(pendulum(), 1.0, 0.1, max_iterations=1, n_out=10, progress=False)
    partial = info.value.partial
    assert partial.t_s.tolist() == [0.0] and partial.q.shape == (1, pendulum().n_q)
    assert partial.stats["halvings"] == 4


def test_a_step_whose_newton_iteration_fails_is_halved():
    """Three Newton iterations per step are too few for some 20 ms steps of the double pendulum:
    those are taken as two (or more) shorter steps, the next step has the full size again (the
    outputs stay on the dt grid), and the motion is that of the run allowed 20 iterations; with
    halving forbidden the run fails, naming it."""
    ref = simulate(pendulum(), 1.0, rtol=1e-10, atol=1e-12, n_out=10, progress=False)
    plain = generalized_alpha(pendulum(), 1.0, 0.02, n_out=10, progress=False)
    halved = generalized_alpha(pendulum(), 1.0, 0.02, max_iterations=3, n_out=10, progress=False)
    assert plain.stats["halvings"] == 0 and plain.stats["steps"] == 50
    assert halved.stats["halvings"] >= 3
    assert halved.stats["steps"] == 50 + halved.stats["halvings"]  # each halving: one step more
    np.testing.assert_allclose(halved.t_s, plain.t_s)
    err_plain, err_halved = np.abs(plain.q - ref.q).max(), np.abs(halved.q - ref.q).max()
    print(f"halvings {halved.stats['halvings']}: errors {err_halved:.3g} (halved) {err_plain:.3g} (plain)")
    assert err_halved < 1.1 * err_plain and np.abs(halved.q - plain.q).max() < 0.5 * err_plain
    with pytest.raises(SolverError, match=r"halving the step was not allowed \(max_halvings=0\)") as info:
        generalized_alpha(pendulum(), 1.0, 0.02, max_iterations=3, max_halvings=0, n_out=10, progress=False)
    assert 1 <= info.value.partial.t_s.size < 11


def test_a_stiff_beam3d_catenary_starts_at_one_millisecond():
    """The seed paper's catenary (beam3d wire under tension with droppers, the pantograph on a
    sliding joint): the projected initial velocities set the wire's cross-section gradient modes
    (near 1e6 rad/s) vibrating, and the start-up value a_0 = v_dot(t_0 + (alpha_m - alpha_f) h),
    unfiltered, carried their jerk (4e7 m/s^2 at dt = 1 ms): the first step's Newton iteration
    diverged. Filtered through the step's iteration matrix, the steps converge in a few
    iterations and the pan-head's a_0 stays its resolved acceleration."""
    module = _scene_module("seo2005_catenary")
    from symcat.analysis.equilibrium import solve_equilibrium

    model = MultibodyModel(module.build(_defaults(module)))
    solve_equilibrium(model).apply(model)
    for variant in ("stabilized", "index3"):
        run = integrate_alpha(model, 0.02, 1e-3, variant=variant, n_out=2, progress=False)
        stats = run.stats
        assert stats["steps"] == 20 and stats["halvings"] == 0, stats
        assert stats["newton_iterations"] <= 6 * stats["steps"], stats
    res = run.result()
    # The pan-head is pushed down by the wire (about 74 N at 17 m/s) and stays on it.
    force = -res.reactions_N["contact"][:, 2]
    assert np.all((force > 50) & (force < 100)), force


def test_penalty_contact_matches_idas_at_order_two():
    """A head pushed against a pretensioned cable by 60 N plus 30 N at 8 Hz through a penalty
    contact (its arc length an algebraic unknown of each step, with its tangency row): position,
    contact force and contact arc length agree with IDAS, the error falling like dt^2."""
    ref = simulate(head_under_wire(shake=30.0)[0], 0.3, rtol=1e-8, atol=1e-10, n_out=30, progress=False)
    off = head_under_wire(shake=30.0)[0].rigid_offset["head"] + 2
    z_err, f_err = [], []
    for dt in (2e-3, 1e-3):
        res = generalized_alpha(head_under_wire(shake=30.0)[0], 0.3, dt, n_out=30, progress=False)
        c, c_ref = res.contacts["contact"], ref.contacts["contact"]
        z_err.append(np.abs(res.q[:, off] - ref.q[:, off]).max())
        f_err.append(np.abs(c["force_N"] - c_ref["force_N"]).max())
        assert np.abs(c["s_m"] - c_ref["s_m"]).max() < 5e-6
    print(f"penalty: head z errors {z_err} m, force errors {f_err} N (dt = 2, 1 ms)")
    assert z_err[-1] < 3e-5 and f_err[-1] < 0.005 * np.ptp(c_ref["force_N"])  # of 43 mm, 49 N
    assert z_err[0] / z_err[1] > 3 and f_err[0] / f_err[1] > 3


def test_penalty_contact_is_lost_and_regained_as_on_idas():
    """The head launched downward at 2 m/s leaves the wire and lands on it again, several times
    in 0.3 s: the time out of contact and the motion are those of IDAS; no force while apart."""
    ref = simulate(head_under_wire(v0=-2.0)[0], 0.3, rtol=1e-8, atol=1e-10, n_out=60, progress=False)
    res = generalized_alpha(head_under_wire(v0=-2.0)[0], 0.3, 1e-3, n_out=60, progress=False)
    c, c_ref = res.contacts["contact"], ref.contacts["contact"]
    off = head_under_wire()[0].rigid_offset["head"] + 2
    assert abs((c["gap_m"] > 0).mean() - (c_ref["gap_m"] > 0).mean()) < 0.05
    assert (c_ref["gap_m"] > 0).mean() > 0.1
    assert np.abs(res.q[:, off] - ref.q[:, off]).max() < 0.005 * np.ptp(ref.q[:, off])
    assert np.all(c["force_N"] >= 0) and np.all(c["force_N"][c["gap_m"] > 0] == 0)


def test_the_integrators_own_multipliers_skip_the_kkt_post_processing():
    """``multipliers="integrator"``: the result's multipliers and accelerations are the
    integrator's own (the AlphaRun's), positions and velocities unchanged; under the stabilized
    variant (order 2 in the multipliers) they agree with the KKT system of the output states
    to the method's error."""
    kkt = generalized_alpha(pendulum(), 0.5, 0.005, n_out=10, progress=False)
    own = generalized_alpha(pendulum(), 0.5, 0.005, n_out=10, progress=False, multipliers="integrator")
    np.testing.assert_array_equal(own.q, kkt.q)
    np.testing.assert_array_equal(own.v, kkt.v)
    assert not np.array_equal(own.multipliers, kkt.multipliers)
    scale = np.abs(kkt.multipliers).max()
    assert np.abs(own.multipliers - kkt.multipliers).max() < 1e-3 * scale
    assert np.abs(own.a - kkt.a).max() < 1e-3 * np.abs(kkt.a).max()
    with pytest.raises(ParameterError, match="multipliers='own': must be 'kkt' or 'integrator'"):
        generalized_alpha(pendulum(), 0.5, 0.005, progress=False, multipliers="own")


def test_a_monitor_sees_every_step():
    """``monitor`` is called at the start and after every step; its values, stacked, match the
    outputs at the output times, and the penalty contact's force matches the result's."""
    model = head_under_wire(shake=30.0)[0]
    seen = generalized_alpha(model, 0.05, 1e-3, n_out=5, progress=False, multipliers="integrator",
                             monitor=lambda s: {"q": s.q, "force_N": s.force_N, "gap_m": s.gap_m})
    m = seen.monitored
    assert m["t_s"].shape == (51,) and np.allclose(m["t_s"], np.linspace(0, 0.05, 51))
    every = np.arange(0, 51, 10)
    np.testing.assert_allclose(m["q"][every], seen.q, atol=1e-12)
    name = next(iter(seen.contacts))
    np.testing.assert_allclose(m["force_N"][every, 0], seen.contacts[name]["force_N"], rtol=1e-9, atol=1e-9)
