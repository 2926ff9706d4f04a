"""Robustness of the wheelset model on real profiles: contact jumps caught before the followed
point reaches its fold (EN 15302, S1002 at speed), the derivative-safe creep law, and the pieces
of the jump logic (relative curvature, local minima, jump targets)."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from symcat.assembly.wheelrail import polach_forces_casadi, smooth_positive
from symcat.model import run_model
from symcat.vehicle import wheelset_on_track
from symcat.wheelrail import profile_pair
from symcat.wheelrail.constraint_contact import WheelRailContact
from symcat.wheelrail.creep import kalker_coefficients
from symcat.wheelrail_events.contact_jumps import (FOLD_CURVATURE_PER_M, JUMP_TOLERANCE_M, REFUSED_RADIUS_M,
                                                   ContactCheck, Rival, relative_curvature)

G = 9.81
#: Vertical load per wheel of the wheelset model (its weight and its share of the car body).
WHEEL_LOAD_N = 0.5 * (1813.0 + (32000.0 + 2 * 2615.0) / 4) * G


def _run(**params):
    params = {"n_out": int(round(params["t_end"] / 0.02)), **params}  # the default output interval
    return run_model("wheelset", params).arrays["result"]


def _check_sensible(res, y_bound_m):
    normal = np.array([w["normal_force_N"] for w in res.wheelrail.values()])
    assert normal.min() > 0.85 * WHEEL_LOAD_N and normal.max() < 1.2 * WHEEL_LOAD_N
    assert np.abs(res.coordinate("wheelset.y")).max() < y_bound_m
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.multipliers))


def test_en15302_conformal_profiles_run_through_their_contact_jumps():
    """Failed at 0.38 s with IDA_TOO_MUCH_WORK: the followed minimum met a gap maximum (a fold)
    20 nm above a new minimum, below the old 100 nm jump tolerance."""
    res = _run(profile="en15302_a", creep="linear", t_end=0.5)
    assert res.t_s[-1] == pytest.approx(0.5)
    assert res.stats["contact_jumps"] >= 3
    _check_sensible(res, 0.0035)
    # Kalker's linear creep forces dissipate: F . slip <= 0 at every output, on every wheel.
    for w in res.wheelrail.values():
        power = w["fx_N"] * w["xi_x"] + w["fy_N"] * w["xi_y"] + w["mz_Nm"] * w["phi_per_m"]
        assert power.max() <= 1e-9 * WHEEL_LOAD_N
    assert res.stats["nsteps"] < 8000  # not stalling at a fold


def test_s1002_at_30_m_s_with_polach_creep_runs_past_the_old_failure():
    """Failed at 0.23 s with IDA_LSETUP_FAIL (inf in the Jacobian): a contact jump missed between
    output times, the followed point ran into its fold."""
    res = _run(profile="s1002_uic60", creep="nonlinear", speed_ms=30.0, t_end=0.3)
    assert res.t_s[-1] == pytest.approx(0.3)
    assert res.stats["contact_jumps"] >= 2
    _check_sensible(res, 0.006)
    # Polach's forces oppose the longitudinal creepage.
    for w in res.wheelrail.values():
        assert np.all(w["fx_N"] * w["xi_x"] <= 1e-9)


def test_embedded_form_on_en15302():
    res = _run(profile="en15302_a", creep="linear", formulation="embedded", t_end=0.3)
    assert res.stats["contact_jumps"] >= 1
    _check_sensible(res, 0.0035)


def test_frictionless_wheelset_keeps_its_energy_through_jumps():
    """Without creep the rail's normals have no component along the track, so nothing works on
    the wheelset but gravity and the axle load: its energy (less the driven forward motion's)
    is conserved, up to the plastic impacts of the jumps and the integrator's damping, which
    only take energy out. Measured against the swing of the axle load's potential energy as
    the wheelset rises and falls on the S1002 profile (7.5 J). At rtol 1e-7: the spin's 76 kJ
    at rtol 1e-6 would leave +-0.06 J of integration error in outputs that IDAS interpolates."""
    res = _run(profile="s1002_uic60", creep="none", t_end=0.4, rtol=1e-7)
    assert res.stats["contact_jumps"] >= 4
    names = res.coordinate_names
    x_dot, z = res.v[:, names.index("wheelset.x")], res.q[:, names.index("wheelset.z")]
    axle_load = (32000.0 + 2 * 2615.0) / 4 * G
    energy = res.energy_J["total"] - 0.5 * 1813.0 * x_dot**2 + axle_load * z
    swing = axle_load * np.ptp(z)
    assert swing > 5.0
    change = energy - energy[0]
    assert change.max() < 1e-3 * swing and change.min() > -0.05 * swing


# --- the pieces ---------------------------------------------------------------------------------
def test_smooth_positive_is_finite_and_accurate_everywhere():
    x = ca.SX.sym("x")
    eps = 60.0
    f = ca.Function("f", [x], [smooth_positive(x, eps), ca.jacobian(smooth_positive(x, eps), x)])
    for v in (-1e12, -1e6, -60.0, 0.0, 60.0, 1e6, 1e12):
        value, slope = (float(a) for a in f(v))
        exact = 0.5 * eps**2 / (math.hypot(v, eps) - v) if v < 0 else 0.5 * (v + math.hypot(v, eps))
        assert value == pytest.approx(exact, rel=1e-12) and value > 0
        assert 0 < slope <= 1 and math.isfinite(slope)
    # The plain form cancels to exactly zero there; this one keeps the creep law finite.
    assert 0.5 * (-1e12 + math.hypot(-1e12, eps)) == 0.0


def _polach_function():
    """Polach's forces of the wheel/rail creep function (smoothed normal force, ellipse scaled
    with it) and their Jacobian in (xi_x, xi_y, phi, N)."""
    c = kalker_coefficients(1.3)
    v = ca.SX.sym("v", 4)
    n0 = 6e4
    n_pos = smooth_positive(v[3], 1e-3 * n0)
    scale = (n_pos / n0) ** (1.0 / 3.0)
    f = ca.vertcat(*polach_forces_casadi(v[0], v[1], v[2], n_pos, 6e-3 * scale, 4.6e-3 * scale, c)[:2])
    return ca.Function("f", [v], [f, ca.jacobian(f, v)])


@pytest.mark.parametrize("point", [(0.0, 0.0, 0.0, 6e4), (0.0, 0.0, 0.2, 6e4), (2e-3, -1e-3, 0.5, 6e4),
                                   (1e-4, 1e-4, 0.1, -5e4), (3e-4, 0.0, 0.0, -1e13), (0.0, 0.0, 0.0, 0.0)])
def test_polach_casadi_jacobian_is_finite_and_matches_finite_differences(point):
    """Central differences with steps well below the creepages (Polach's combined coefficient
    ``C = sqrt((C11 xi_x)^2 + (C22 xi_y)^2) / xi`` depends on the direction of the creepage, so
    the law is not differentiable at zero creepage on scales above its 1e-12 regularization: the
    Jacobian there is finite, that of the regularized law, and found with steps below it)."""
    fn = _polach_function()
    x = np.array(point, float)
    jac = np.array(fn(x)[1])
    assert np.all(np.isfinite(jac))
    steps = [1e-15 if x[0] == x[1] == 0 else 1e-6 * np.abs(x[:2]).max()] * 2 + [1e-7, 1e-6 * max(1e4, abs(x[3]))]
    for k, h in enumerate(steps):
        e = np.zeros(4)
        e[k] = h
        fd = (np.array(fn(x + e)[0]) - np.array(fn(x - e)[0])).ravel() / (2 * h)
        # (Round-off of the 1e-15 steps: 1e-16 |F| / 1e-15, below 1e-4 of the slopes.)
        assert jac[:, k] == pytest.approx(fd, rel=1e-4, abs=1e-7 * max(1.0, np.abs(jac).max()))


def test_polach_casadi_is_finite_for_any_creepage_and_normal_force():
    fn = _polach_function()
    rng = np.random.default_rng(1)
    for _ in range(2000):
        creep = 10.0 ** rng.uniform(-16, 1, 3) * rng.choice([-1, 0, 1], 3)
        normal = 10.0 ** rng.uniform(-3, 14) * rng.choice([-1, 1])
        force, jac = (np.array(m) for m in fn(np.r_[creep, normal]))
        assert np.all(np.isfinite(force)) and np.all(np.isfinite(jac))


@pytest.mark.parametrize("offset", [0.0, 0.002, -0.005])
def test_relative_curvature_is_that_of_the_profiles(offset):
    """The Schur complement of the kernel's C_s against the profiles' own curvatures (2D: the
    placed wheelset has roll but no yaw)."""
    pair = profile_pair("s1002_uic60")
    placed = wheelset_on_track(pair.wheel, pair.rail, offset)
    q = np.r_[placed.position_m, _euler(placed.rotation)]
    for side in ("left", "right"):
        contact = WheelRailContact(pair.wheel, pair.rail, side)
        s = contact.solve(q).s
        profiles = -(pair.wheel.curvature(s[0]) + pair.rail.curvature(s[3]))
        assert relative_curvature(contact, q, s) == pytest.approx(float(profiles), rel=2e-3)


def test_local_minima_of_s1002_include_the_lowest_point_and_are_stationary():
    pair = profile_pair("s1002_uic60")
    placed = wheelset_on_track(pair.wheel, pair.rail, 0.0003)  # near the centre's contact jump
    q = np.r_[placed.position_m, _euler(placed.rotation)]
    contact = WheelRailContact(pair.wheel, pair.rail, "left")
    minima = contact.local_minima(q, band_m=5e-4)
    assert len(minima) >= 2
    assert [m.gap_m for m in minima] == sorted(m.gap_m for m in minima)
    assert minima[0].gap_m == pytest.approx(contact.solve(q).gap_m, abs=1e-10)
    for m in minima:
        assert m.residual < 1e-8 and relative_curvature(contact, q, m.s) > 0


def test_jump_targets_need_a_formed_rival_below_the_tolerance():
    class Point:
        def __init__(self, gap):
            self.gap_m = gap

    def check(curvature, *rivals):
        return ContactCheck("w", 0.0, 0.0, curvature, math.inf, np.zeros(4),
                            [Rival(Point(g), k, 0.0) for g, k in rivals])

    formed, newborn = 10 * FOLD_CURVATURE_PER_M, 0.1 * FOLD_CURVATURE_PER_M
    assert check(1.0, (-0.5 * JUMP_TOLERANCE_M, formed)).target() is None      # within the hysteresis
    assert check(1.0, (-2 * JUMP_TOLERANCE_M, formed)).target() is not None
    assert check(1.0, (-1e-6, newborn)).target() is None                       # may vanish again
    near_fold = 0.5 * FOLD_CURVATURE_PER_M
    assert check(near_fold, (-0.1 * JUMP_TOLERANCE_M, newborn)).target() is not None
    assert check(near_fold, (2 * JUMP_TOLERANCE_M, formed)).target() is None   # nothing as low
    assert check(near_fold, (0.5 * JUMP_TOLERANCE_M, formed)).target() is not None  # a flat valley
    assert check(1.0, (5e-9, formed), (1e-8, newborn)).target(relaxed=True).curvature_per_m == formed
    # Formed rivals are preferred when the followed point must go.
    both = check(near_fold, (-2e-9, newborn), (-1e-9, formed))
    assert both.target().curvature_per_m == formed
    # The call length: the rival closing in at 1 um/s from 1 nm above.
    closing = ContactCheck("w", 0.0, 1e-6, 1.0, math.inf, np.zeros(4), [Rival(Point(1e-9), formed, 0.0)])
    assert closing.span_s() == pytest.approx((1e-9 + 2 * JUMP_TOLERANCE_M) / 1e-6)


def test_a_refused_jump_target_is_skipped_unless_relaxed():
    class Point:
        def __init__(self, gap, s1w):
            self.gap_m, self.s = gap, np.array([s1w, 0.0, 0.0, 0.0])

    formed = 10 * FOLD_CURVATURE_PER_M
    two = ContactCheck("w", 0.0, 0.0, 1.0, math.inf, np.zeros(4),
                       [Rival(Point(-1e-8, 0.010), formed, 0.0), Rival(Point(-5e-9, 0.030), formed, 0.0)])
    assert two.target().point.s[0] == 0.010
    assert two.target(refused=0.010 + 0.5 * REFUSED_RADIUS_M).point.s[0] == 0.030  # the next lowest
    one = ContactCheck("w", 0.0, 0.0, 1.0, math.inf, np.zeros(4), [Rival(Point(-1e-8, 0.010), formed, 0.0)])
    assert one.target(refused=0.010) is None
    assert one.target(refused=0.010 + 2 * REFUSED_RADIUS_M) is not None          # another point
    assert one.target(relaxed=True, refused=0.010) is not None                   # IDAS failed here too


def _euler(rotation):
    from symcat.scene.rigid import euler_parameters

    return euler_parameters(rotation)


@pytest.mark.parametrize("index", ["ggl", "1"])
def test_a_jump_to_a_deeper_point_closes_the_gap_in_ggl(index):
    """A rival micrometres below the followed point (a fast lateral motion outran the checks):
    GGL, without Baumgarte terms, needs the state projected onto the constraints after the
    jump; index 1 keeps the positions (its stabilization closes the gap)."""
    from symcat.assembly.multibody import MultibodyModel
    from symcat.dae.formulation import Formulation
    from symcat.dae.initial import consistent_state
    from symcat.wheelrail_events.contact_jumps import check_contacts, jump_contacts
    from symcat.integrate.failure import restart_point, split_state
    from symcat.scene import RigidBody, Scene, WheelRailJoint

    pair = profile_pair("s1002_uic60")
    placed = wheelset_on_track(pair.wheel, pair.rail, 0.0003)  # two minima on the left wheel
    scene = Scene(gravity=(0.0, 0.0, -G))
    scene.add(RigidBody("ws", 1813.0, (1120.0, 112.0, 1120.0), position=placed.position_m,
                        rotation=placed.rotation))
    for side in ("left", "right"):
        scene.add(WheelRailJoint(f"wr_{side}", "ws", side, pair.wheel, pair.rail))
    form = Formulation(MultibodyModel(scene), "augmented", index, 10.0, False)
    x, z = consistent_state(form, 0.0)
    # Follow the higher minimum of the left wheel: the lowest is then a rival below it.
    parts = split_state(form, x, z)
    contact = form.model.wheelrail[0].contact
    minima = contact.local_minima(np.r_[placed.position_m, _euler(placed.rotation)], band_m=5e-4)
    assert len(minima) >= 2
    s = parts["s"].copy()
    s[:4] = minima[1].s  # the placement follows the lowest
    x, z = consistent_state(form, 0.0, start=restart_point(form, parts, s))
    check = check_contacts(form, x, z)[0]
    depth = check.gap_m - check.rivals[0].point.gap_m
    assert depth > 1e-7 and check.target() is check.rivals[0]
    x, z, jumped = jump_contacts(form, x, z, 0.0)
    assert jumped[0] == "wr_left"
    gap = check_contacts(form, x, z)[0].gap_m
    if index == "ggl":
        assert abs(gap) < 1e-10
    else:
        assert gap == pytest.approx(-depth, rel=1e-3)


@pytest.mark.parametrize("profile, shift_m", [("s1002_uic60", 0.0003), ("s1002_uic60", 0.0075),
                                              ("en15302_a", 0.004), ("conical", 0.002)])
@pytest.mark.parametrize("yaw_rad", [0.0, 0.004, -0.02])
def test_screened_gap_minima_equal_the_full_three_angle_search(profile, shift_m, yaw_rad, monkeypatch):
    """gap_minima evaluates the three angles of a circle only where yaw can lower it into the
    band (``R (h' sin psi)^2 / 2``): the same minima as evaluating them everywhere, on the
    flange (7.5 mm) and the conformal centre of S1002, yawed up to 20 mrad."""
    from symcat.scene.rigid import euler_parameters
    from symcat.wheelrail import gap_minima as module

    pair = profile_pair(profile, 0.05)
    placed = wheelset_on_track(pair.wheel, pair.rail, shift_m)
    c, s_ = math.cos(yaw_rad), math.sin(yaw_rad)
    rotation = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]]) @ placed.rotation
    q = np.r_[placed.position_m, euler_parameters(rotation)]
    for side in ("left", "right"):
        contact = WheelRailContact(pair.wheel, pair.rail, side)
        screened = contact.local_minima(q, band_m=5e-4)
        monkeypatch.setattr(module, "OFF_BOTTOM_SAFETY", math.inf)
        full = contact.local_minima(q, band_m=5e-4)
        monkeypatch.undo()
        assert len(screened) == len(full) >= 1
        for a, b in zip(screened, full):
            np.testing.assert_allclose(a.s[[0, 2, 3]], b.s[[0, 2, 3]], atol=1e-9)
            assert a.gap_m == pytest.approx(b.gap_m, abs=1e-12)


def test_dense_output_costs_no_contact_calls():
    """The stepper's calls cross output times (IDAS interpolates them): 15 or 300 outputs (the
    same 0.1 s spans of the driver) give about the same calls (outputs ending calls would make
    300) and the same jumps, and the states at the common times agree. Not bit for bit: the
    integrators on the two output grids differ in their last bits, and a call with one output
    inside runs in a warped time (:func:`symcat.integrate.shifted.warped_grid`) with other steps
    within the tolerance, which the undamped frictionless wheelset's contact jumps (plastic
    impacts) amplify to about 2e-7 m by 0.3 s (34 and 36 calls)."""
    sparse = _run(profile="s1002_uic60", creep="none", t_end=0.3, n_out=15, rtol=1e-8)
    dense = _run(profile="s1002_uic60", creep="none", t_end=0.3, n_out=300, rtol=1e-8)
    assert abs(dense.stats["contact_calls"] - sparse.stats["contact_calls"]) <= 0.1 * sparse.stats["contact_calls"]
    assert dense.stats["contact_jumps"] == sparse.stats["contact_jumps"] >= 1
    y_sparse, y_dense = sparse.coordinate("wheelset.y"), dense.coordinate("wheelset.y")[::20]
    np.testing.assert_allclose(y_dense, y_sparse, rtol=0, atol=1e-6)


def test_a_frictionless_sweep_over_the_conformal_flange_root_is_reported():
    """Released 7 mm toward its left flange without creep, an S1002 wheelset falls off the
    flange flank; the left contact point sweeps over the nearly conformal flange root (gauge
    corner of UIC60) at over 100 m/s along the wheel, faster than IDAS converges (a known limit
    of one constraint point per wheel; with creep it passes, see
    test_s1002_flange_to_tread_and_over_to_the_other_flange). The error says so, with the time,
    and keeps the results."""
    from symcat.errors import SolverError

    with pytest.raises(SolverError, match=r"t = 0\.01\d+ s.*left_wheel contact point was sweeping along its wheel "
                                          r"at \d+ m/s, relative curvature 0\.\d+ 1/m") as err:
        _run(profile="s1002_uic60", creep="none", lateral_offset_m=0.007, t_end=0.05, n_out=10)
    partial = err.value.partial.arrays["result"]  # run_model keeps the run so far (RunStopped)
    assert partial is not None and len(partial.t_s) >= 2


def test_a_late_jump_kept_up_to_an_output_matches_the_call_redone_from_its_start(monkeypatch):
    """A call that passed a contact jump unpredicted is kept up to its last output before the
    crossing (:meth:`ContactEvents.kept_output`) instead of redone from its start: the same
    jumps, no more IDAS steps, and the lateral motion within 5 um of the redone run's (rtol
    1e-6; both jump at an estimated crossing, the kept run from IDAS's interpolated state)."""
    from symcat.wheelrail_events.contact_events import ContactEvents

    # The tolerances that meet a late jump with an output before it (not the model's default
    # velocity tolerance, whose steps pass no such jump in this second).
    params = dict(profile="s1002_uic60", creep="linear", lateral_offset_m=0.002, t_end=1.0, n_out=50, rtol=1e-6,
                  atol=1e-8, atol_velocity=1e-8)
    kept = _run(**params)
    monkeypatch.setattr(ContactEvents, "kept_output", lambda self, *args: None)
    redone = _run(**params)
    assert kept.stats["jump_redos_kept"] >= 1 and redone.stats["jump_redos_kept"] == 0
    assert kept.stats["contact_jumps"] == redone.stats["contact_jumps"] >= 1
    assert kept.stats["nsteps"] <= redone.stats["nsteps"]
    np.testing.assert_allclose(kept.coordinate("wheelset.y"), redone.coordinate("wheelset.y"), rtol=0, atol=5e-6)
