"""The seed vehicle on a track layout (symcat.vehicle with ``track=``): bad starts and drives,
wheel-force frames on a canted curve against the layout's exact frames, a straight layout
turned in plan against tangent track, and steady curving against the quasi-static force
balance."""
from __future__ import annotations

import numpy as np
import pytest

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError
from symcat.scene import Scene
from symcat.simulation import simulate
from symcat.vehicle import (VehicleLayout, add_vehicle, curve_track, lateral_displacement_m, lateral_force_sum_N,
                            steady_curving_forces_N, wheel_forces)
from symcat.vehicle.wheel_forces import contact_frames
from symcat.wheelrail import profile_pair
from symcat.wheelrail.track import Curve, Tangent, TrackLayout, rail_offset_for

G = 9.81


@pytest.fixture(scope="module")
def pair():
    return profile_pair("conical", 0.05)


def _simulate(pair, t_end, n_out, **kw):
    scene = Scene(gravity=(0.0, 0.0, -G))
    layout = add_vehicle(scene, pair, creep="linear", **kw)
    res = simulate(MultibodyModel(scene), t_end, index="ggl", rtol=1e-7, n_out=n_out, progress=False)
    return layout, res


def test_a_start_off_the_lead_in_or_a_driving_constraint_in_a_curve_is_refused(pair):
    track, x0 = curve_track(pair, 500.0, cant_m=0.05, transition_length_m=10.0, curve_length_m=50.0)
    assert x0 == pytest.approx(11.78)  # outermost wheelsets 1 m from the ends of the 23.56 m lead-in
    allowed = r"allowed: 10.78 <= x_m <= 12.78 m"
    with pytest.raises(ParameterError, match=r"x_m=30: the vehicle's wheelsets \(chainages 19.22 to 40.78 m\) must "
                                             r"all start on a tangent .*" + allowed):
        add_vehicle(Scene(), pair, speed_ms=10.0, drive="torque", track=track, x_m=30.0)
    with pytest.raises(ParameterError, match=r"x_m=5: .*chainages -5.78 to 15.78 m.*" + allowed):
        add_vehicle(Scene(), pair, speed_ms=10.0, drive="torque", track=track, x_m=5.0)
    with pytest.raises(ParameterError, match=r"drive='constraint': .*cannot follow a curved track layout; use "
                                             r"drive='torque' \(traction servo\)"):
        add_vehicle(Scene(), pair, speed_ms=10.0, drive="constraint", track=track, x_m=x0)
    short = TrackLayout([Tangent(10.0), Curve(50.0, 300.0)], rail_offset_m=rail_offset_for(pair.rail))
    with pytest.raises(ParameterError, match=r"x_m=5: .*allowed: none: no tangent stretch .* \(21.56 m\)"):
        add_vehicle(Scene(), pair, speed_ms=10.0, drive="torque", track=short, x_m=5.0)
    with pytest.raises(ParameterError, match="track='curved': must be a TrackLayout or None"):
        add_vehicle(Scene(), pair, speed_ms=10.0, track="curved")
    with pytest.raises(ParameterError, match=r"cant_m=0.05 with transition_length_m=0: a cant needs a transition"):
        curve_track(pair, 500.0, cant_m=0.05, transition_length_m=0.0)
    # a straight layout keeps the driving constraint (along its tangent)
    straight = TrackLayout([Tangent(30.0)], rail_offset_m=rail_offset_for(pair.rail), start_heading_rad=0.5)
    layout = add_vehicle(Scene(), pair, speed_ms=10.0, drive="constraint", track=straight, x_m=15.0)
    assert layout.track is straight


@pytest.mark.parametrize("ramp, atol", [("linear", 1e-9), ("smooth", 5e-8)])
def test_contact_frames_on_a_canted_curve_are_the_track_frames(pair, ramp, atol):
    """The creep direction ``t1`` and the axes of Y and Q at contacts in a transition and in a
    canted curve: the rail tangent and the canted track frame of the layout's exact frames
    (the kernels' are cubic pieces of at most 1 m: exact to 1e-9 for the linear cant ramp,
    whose cant angle is nearly linear, to 1.4e-8 for the cubic smooth ramp): the lateral axis
    normal to the centre line and tilted by the cant angle."""
    track, _ = curve_track(pair, 300.0, cant_m=0.12, transition_length_m=20.0, curve_length_m=40.0,
                           direction="right", cant_ramp=ramp)
    layout = VehicleLayout(pair=pair, track=track)
    chainage = np.array([25.3, 33.9, 47.1, 60.0])
    s2r = np.array([0.035, 0.03, 0.04, 0.038])
    for side, sign in (("left", 1.0), ("right", -1.0)):
        s = np.column_stack([np.zeros(4), np.zeros(4), chainage, s2r])
        t1, n, axes = contact_frames(layout, side, s)
        exact = track.rail_frame(chainage, side)
        point, slope = pair.rail.position(s2r), pair.rail.derivative(s2r)
        u = np.column_stack([np.zeros(4), sign * point[:, 0], point[:, 1]])
        du = np.column_stack([np.zeros(4), sign * slope[:, 0], slope[:, 1]])
        tangent = exact.dR_ds + np.einsum("nij,nj->ni", exact.dA_ds, u)
        np.testing.assert_allclose(t1, tangent / np.linalg.norm(tangent, axis=1, keepdims=True), atol=atol)
        normal = sign * np.cross(t1, np.einsum("nij,nj->ni", exact.A, du))
        np.testing.assert_allclose(n, normal / np.linalg.norm(normal, axis=1, keepdims=True), atol=atol)
        frame = track.track_frame(chainage)
        np.testing.assert_allclose(axes, frame.A, atol=atol)
        phi = track.cant_angle(chainage)
        np.testing.assert_allclose(axes[:, 2, 1], np.sin(phi), atol=atol)           # lateral axis tilted by the cant
        np.testing.assert_allclose(np.einsum("ni,ni->n", axes[:, :, 1], frame.A[:, :, 0]), 0.0, atol=1e-12)
        assert np.all(np.abs(phi[1:]) > 0.03)                                         # canted: a real test


@pytest.mark.slow
def test_a_straight_layout_turned_in_plan_runs_as_tangent_track(pair):
    """The same displaced vehicle on tangent track and on a straight layout turned by 0.5 rad
    and shifted: lateral motion, Y and Q agree in track coordinates (the driving constraint
    acts along the layout's tangent)."""
    kw = dict(speed_ms=17.0, drive="constraint", lateral_offset_m=0.002)
    ref_layout, ref = _simulate(pair, 0.15, 6, x_m=15.0, **kw)
    turned = TrackLayout([Tangent(40.0)], rail_offset_m=rail_offset_for(pair.rail), start_heading_rad=0.5,
                         start_position_m=(100.0, -30.0, 2.0))
    layout, res = _simulate(pair, 0.15, 6, x_m=15.0, track=turned, **kw)
    y_ref, y = lateral_displacement_m(ref, ref_layout), lateral_displacement_m(res, layout)
    assert np.ptp(y_ref["b1_ws1"]) > 5e-4  # it moves
    for w in layout.wheelsets:
        np.testing.assert_allclose(y[w], y_ref[w], atol=1e-8)
    f_ref, f = wheel_forces(ref, ref_layout), wheel_forces(res, layout)
    for name in layout.contact_names:
        np.testing.assert_allclose(f[name]["Q_N"], f_ref[name]["Q_N"], rtol=1e-5)
        # a creep force along global x instead of the rail tangent would be off by fx sin(0.5) here
        np.testing.assert_allclose(f[name]["Y_N"], f_ref[name]["Y_N"], atol=1e-6 * f_ref[name]["Q_N"].max())


# --- steady curving ----------------------------------------------------------------------------
RADIUS, SPEED, STEEP_CONE = 800.0, 15.0, 0.3


def _about_the_centre(res, name, centre, h):
    """Plan distance ``rho`` (m) of a body's centre of mass from the curve centre and its
    acceleration toward the centre, ``(v_h^2 - rho_dot^2) / rho - rho_ddot`` (m/s^2), with
    ``rho_ddot`` by central differences of the outputs (``h`` apart; NaN at the ends)."""
    i = res.coordinate_names.index(f"{name}.x")
    rel, vel = res.q[:, i : i + 2] - centre, res.v[:, i : i + 2]
    rho = np.linalg.norm(rel, axis=1)
    rho_dot = np.einsum("ni,ni->n", vel, rel) / rho
    rho_ddot = np.full_like(rho, np.nan)
    rho_ddot[1:-1] = (rho[2:] - 2 * rho[1:-1] + rho[:-2]) / h**2
    return rho, (np.einsum("ni,ni->n", vel, vel) - rho_dot**2) / rho - rho_ddot


@pytest.mark.slow
def test_steady_curving_the_rails_carry_the_centripetal_force():
    """The vehicle runs (traction servos, 15 m/s) from its lead-in through a 10 m clothoid into
    an uncanted 800 m curve to the left. The rails' forces on the wheels are the only external
    forces besides gravity, so once every body is in the circular curve the sum of the wheels'
    lateral forces (each in the track frame at its contact: horizontal toward the curve centre)
    equals ``sum m_b a_b``, ``a_b`` the body's acceleration toward the centre from its simulated
    positions and velocities alone (polar coordinates about the curve centre); in steady curving
    that is ``M v^2 / R``, which the run oscillates about while its entry transient decays. The
    vertical forces carry the weight, and the wheel forces are the whole contact forces: their
    sum is ``sum m_b (a_b - g)`` with the solver's accelerations at every output (lead-in and
    transition included). A steep cone (0.3, a worn-wheel equivalent conicity) keeps the
    wheelsets' curving offsets small and so the run short."""
    pair = profile_pair("conical", STEEP_CONE)
    track, x0 = curve_track(pair, RADIUS, transition_length_m=10.0, curve_length_m=40.0)
    scene = Scene(gravity=(0.0, 0.0, -G))
    layout = add_vehicle(scene, pair, speed_ms=SPEED, creep="linear", drive="torque", track=track,
                         x_m=x0 + 1.0)  # the leading wheelset at the end of the lead-in
    t_end, n_out = 2.6, 52
    res = simulate(MultibodyModel(scene), t_end, index="ggl", rtol=1e-7, n_out=n_out, progress=False)
    forces = wheel_forces(res, layout)
    mass = {b.name: b.mass for b in scene.rigid_bodies}
    total = sum(mass.values())
    assert total == pytest.approx(layout.parameters.total_mass_kg)
    # the whole contact forces: Newton's law for the vehicle with the solver's accelerations
    acc = sum(m * (res.a[:, res.coordinate_names.index(f"{b}.x"):][:, :3] - np.array([0.0, 0.0, -G]))
              for b, m in mass.items())
    total_force = np.sum([f["force_N"] for f in forces.values()], axis=0)
    np.testing.assert_allclose(total_force, acc, rtol=0, atol=1e-9 * total * G)
    q_sum = np.sum([f["Q_N"] for f in forces.values()], axis=0)
    np.testing.assert_allclose(q_sum, total * G, rtol=2e-4)
    # every body in the circular curve: the lateral force sum against the bodies' motion
    start = track.joins_m[-2]
    frame = track.track_frame(start)
    centre = frame.R[0, :2] + RADIUS * frame.A[0, :2, 1]
    h = t_end / n_out
    inward, rho_min = np.zeros(len(res.t_s)), np.full(len(res.t_s), np.inf)
    for b, m in mass.items():
        rho, a_in = _about_the_centre(res, b, centre, h)
        inward += m * a_in
        rho_min = np.minimum(rho_min, rho)
    rear = [res.wheelrail[layout.contacts[layout.wheelsets[-1]][side]]["s"][:, 2] for side in ("left", "right")]
    curving = (np.minimum(*rear) > start + 0.5) & np.isfinite(inward)
    assert curving.sum() >= 8
    lateral = lateral_force_sum_N(forces)
    error = np.abs(lateral[curving] / inward[curving] - 1)
    i = res.coordinate_names.index("car_body.x")
    speed = np.linalg.norm(res.v[curving, i : i + 2], axis=1)
    steady = steady_curving_forces_N(total, float(speed.mean()), 1.0 / RADIUS, 0.0)
    mean = float(np.mean(lateral[curving]))
    print(f"curving from t = {res.t_s[curving][0]:.2f} s: lateral force sum {lateral[curving].min() / 1e3:.3f} to "
          f"{lateral[curving].max() / 1e3:.3f} kN, against the bodies' accelerations max error "
          f"{error.max() * 100:.2f} %; mean {mean / 1e3:.3f} kN, steady M v^2/R {steady[0] / 1e3:.3f} kN "
          f"({(mean / steady[0] - 1) * 100:+.1f} %); wall {res.stats['wall_s']:.1f} s for {t_end} s")
    assert error.max() < 0.01
    assert mean == pytest.approx(steady[0], rel=0.08)
    assert steady[1] == pytest.approx(total * G)
    # curving posture: the leading wheelset of each bogie outward (the right, y < 0), the trailing one inward
    y = lateral_displacement_m(res, layout)
    assert y["b1_ws1"][-1] < -2e-3 and y["b1_ws2"][-1] > 2e-3
    assert max(np.abs(v).max() for v in y.values()) < 0.02


@pytest.mark.slow
def test_the_vehicle_crosses_a_smooth_cant_ramp():
    """A 100 mm cant ramped over a 10 m clothoid: with the smooth (Bloss) ramp the rails have no
    kinks, and the vehicle's leading wheelset runs from the lead-in over the whole ramp into the
    canted curve (with a linear ramp its rigid contacts stop at the ramp's start, an impact:
    ``cant_ramp="linear"``). The wheels' contact forces are the vehicle's whole external force
    besides gravity (Newton's law with the solver's accelerations, at every output), and the
    wheels stay loaded."""
    pair = profile_pair("conical", STEEP_CONE)
    track, x0 = curve_track(pair, RADIUS, cant_m=0.1, transition_length_m=10.0, curve_length_m=10.0)
    assert track.superelevation(np.array([track.joins_m[1] + 5.0]))[0] == pytest.approx(-0.05)
    scene = Scene(gravity=(0.0, 0.0, -G))
    layout = add_vehicle(scene, pair, speed_ms=SPEED, creep="linear", drive="torque", track=track, x_m=x0 + 1.0)
    res = simulate(MultibodyModel(scene), 0.8, index="ggl", rtol=1e-7, n_out=16, progress=False)
    lead = [res.wheelrail[layout.contacts[layout.wheelsets[0]][side]]["s"][:, 2] for side in ("left", "right")]
    assert np.min(lead, axis=0)[-1] > track.joins_m[2] + 0.5  # past the ramp's end
    forces = wheel_forces(res, layout)
    mass = {b.name: b.mass for b in scene.rigid_bodies}
    acc = sum(m * (res.a[:, res.coordinate_names.index(f"{b}.x"):][:, :3] - np.array([0.0, 0.0, -G]))
              for b, m in mass.items())
    total_force = np.sum([f["force_N"] for f in forces.values()], axis=0)
    np.testing.assert_allclose(total_force, acc, rtol=0, atol=1e-9 * sum(mass.values()) * G)
    normal = np.array([f["normal_N"] for f in forces.values()])
    assert normal.min() > 0.5 * normal[:, 0].min()
