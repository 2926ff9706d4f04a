"""Wheel/rail constraint contact on curved track (kernels ``wheelrail_*_rigid_track``): compiled
derivatives against finite differences on a curve and in a transition, reduction to the
tangent-track kernels, placement on a canted curve, and steady curving of a free coned
wheelset (kinematic pure rolling)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError, SolverError
from symcat.scene import CreepModel, PointLoad, RigidBody, Scene, WheelRailJoint
from symcat.scene.rigid import euler_parameters
from symcat.simulation import simulate
from symcat.vehicle import wheelset_on_track
from symcat.wheelrail import TrackCrossSection, contact_geometry, profile_pair
from symcat.wheelrail.constraint_contact import WheelRailContact
from symcat.wheelrail.track import Curve, Irregularities, Tangent, TrackLayout, Transition, rail_offset_for

FORMS = ("global", "railframe")
G = 9.81
MASS = 1813.0
INERTIA = (1120.0, 112.0, 1120.0)


@pytest.fixture(scope="module")
def pair():
    return profile_pair("s1002_uic60")


@pytest.fixture(scope="module")
def layout(pair):
    """Tangent, transition into a canted left curve on a gradient, with an alignment irregularity."""
    s = np.linspace(0.0, 80.0, 161)
    irr = Irregularities(s, alignment_m=1e-3 * np.sin(2 * np.pi * s / 20.0) * np.sin(np.pi * s / 80.0) ** 2)
    return TrackLayout([Tangent(5.0), Transition(30.0), Curve(45.0, 300.0, "left", 0.12)],
                       rail_offset_m=rail_offset_for(pair.rail), gradient=0.01, irregularities=irr)


def _perturbed(rng, placed, con):
    q = np.r_[placed.position_m, euler_parameters(placed.rotation)]
    s = con.solve(q).s
    dq = np.r_[rng.uniform(-1e-3, 1e-3, 3), np.zeros(4)]
    yaw = rng.uniform(-0.01, 0.01)
    c, sn = math.cos(yaw / 2), math.sin(yaw / 2)
    e = q[3:7]
    q = q + dq
    q[3:7] = np.r_[c * e[0] - sn * e[3], c * e[1] - sn * e[2], c * e[2] + sn * e[1], c * e[3] + sn * e[0]]
    return q, s + np.array([rng.uniform(-2e-3, 2e-3), rng.uniform(-0.05, 0.05), rng.uniform(-5e-3, 5e-3),
                            rng.uniform(-2e-3, 2e-3)])


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("where", [("transition", 20.0), ("curve", 62.0)])
def test_track_kernels_against_finite_differences(pair, layout, form, where, rng):
    """C_q, C_s (C_y y_dot against the rate of C) and Q_d against finite differences, at fixed
    kernel parameters (one track piece, one spline piece of each profile)."""
    placed = wheelset_on_track(pair.wheel, pair.rail, 0.002, x_m=where[1], track=layout)
    for side in ("left", "right"):
        con = WheelRailContact(pair.wheel, pair.rail, side, form=form, track=layout)
        assert con.library == f"wheelrail_{form}_rigid_track"
        q0, s0 = _perturbed(rng, placed, con)
        y0 = np.r_[q0, s0]
        scale = np.r_[1.0, 0.1, 0.01, 0.2 * np.ones(4), 0.01, 1.0, 1.0, 0.01]
        y1, y2 = scale * rng.uniform(-1, 1, 11), scale * rng.uniform(-1, 1, 11)
        p = con.parameters(s0)
        assert p.size == 46
        lib, name = con.kernels, con.library
        c = lambda y: np.asarray(lib[f"{name}_c"](y, 0.0, p)).ravel()

        def jac(y):
            c_y, c_t = (np.asarray(m) for m in lib[f"{name}_jac"](y, 0.0, p))
            return c_y.reshape(5, 11), c_t.ravel()

        c_y, c_t = jac(y0)
        np.testing.assert_array_equal(c_t, 0.0)
        for j in range(11):
            e = np.zeros(11)
            e[j] = 1e-6
            fd = (c(y0 + e) - c(y0 - e)) / 2e-6
            np.testing.assert_allclose(c_y[:, j], fd, rtol=1e-6, atol=1e-7 * max(1.0, np.abs(fd).max()))
        path = lambda t: y0 + y1 * t + y2 * t**2
        h = 1e-5
        rate_fd = (c(path(h)) - c(path(-h))) / (2 * h)
        np.testing.assert_allclose(c_y @ y1, rate_fd, rtol=1e-6, atol=1e-9 * np.abs(rate_fd).max())
        q_d = con.evaluate(q0, s0, y1[:7], y1[7:]).Q_d
        cdot = lambda t: jac(path(t))[0] @ (y1 + 2 * y2 * t)
        acc_fd = (cdot(h) - cdot(-h)) / (2 * h)
        np.testing.assert_allclose(c_y @ (2 * y2) + q_d, acc_fd, rtol=1e-6, atol=1e-8 * np.abs(acc_fd).max())


@pytest.mark.parametrize("form", FORMS)
def test_zero_curvature_reproduces_the_tangent_kernels(pair, form, rng):
    """On a tangent layout (here with a 1:20 rail inclination) the track kernels give the tangent
    kernels' C, C_q, C_s and Q_d, and the same contact point; turned and shifted in plan, the
    same contact relative to the track."""
    incl = math.atan(1 / 20)
    cross = TrackCrossSection(rail_inclination_rad=incl)
    offset = rail_offset_for(pair.rail, rail_inclination_rad=incl)
    straight = TrackLayout([Tangent(30.0)], rail_offset_m=offset, rail_inclination_rad=incl,
                           profile_inclination_rad=pair.rail.inclination_rad)
    heading, start = 0.7, np.array([100.0, -50.0, 2.0])
    turned = TrackLayout([Tangent(30.0)], rail_offset_m=offset, rail_inclination_rad=incl,
                         profile_inclination_rad=pair.rail.inclination_rad, start_heading_rad=heading,
                         start_position_m=start)
    rz = np.array([[math.cos(heading), -math.sin(heading), 0], [math.sin(heading), math.cos(heading), 0], [0, 0, 1]])
    placed = wheelset_on_track(pair.wheel, pair.rail, -0.003, x_m=12.0, track=cross)
    for side in ("left", "right"):
        flat = WheelRailContact(pair.wheel, pair.rail, side, form=form, track=cross)
        track = WheelRailContact(pair.wheel, pair.rail, side, form=form, track=straight)
        assert (flat.library, track.library) == (f"wheelrail_{form}_rigid_ground", f"wheelrail_{form}_rigid_track")
        for _ in range(3):
            q, s = _perturbed(rng, placed, flat)
            qd, sd = rng.normal(0, 0.3, 7), rng.normal(0, 0.3, 4)
            a, b = flat.evaluate(q, s, qd, sd), track.evaluate(q, s, qd, sd)
            for name in ("c", "C_q", "C_s", "Q_d"):
                np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=0,
                                           atol=1e-12 * max(1.0, np.abs(getattr(a, name)).max()), err_msg=name)
            q[2] += rng.uniform(0.0, 5e-4)  # lifted: a gap to find
            pa, pb = flat.solve(q), track.solve(q)
            np.testing.assert_allclose(pb.s, pa.s, rtol=0, atol=1e-10)
            assert abs(pb.gap_m - pa.gap_m) < 1e-12
            assert abs(pb.contact_angle_rad - pa.contact_angle_rad) < 1e-10
            np.testing.assert_allclose(pb.point_m, pa.point_m, atol=1e-12)
            # the same wheelset turned and shifted with the track
            moved = WheelRailContact(pair.wheel, pair.rail, side, form=form, track=turned)
            qt = np.r_[start + rz @ q[:3], euler_parameters(rz @ _rotation(q[3:7]))]
            pt = moved.solve(qt)
            np.testing.assert_allclose(pt.s, pa.s, rtol=0, atol=1e-9)
            assert abs(pt.gap_m - pa.gap_m) < 1e-11


def _rotation(e):
    e0, v = e[0], e[1:]
    skew = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return (2 * e0**2 - 1) * np.eye(3) + 2 * (np.outer(v, v) + e0 * skew)


def test_placement_on_a_canted_curve(pair):
    """A radial wheelset in a canted circular curve touches both rails at the 2D contact of the
    canted cross-section: the contact points lie on the rail surfaces, at the curve radius minus
    their lateral position in plan."""
    radius, cant = 300.0, 0.12
    layout = TrackLayout([Curve(60.0, radius, "left", cant)], rail_offset_m=rail_offset_for(pair.rail))
    phi = math.asin(-cant / layout.cant_base_m)  # left curve: the outer (right) rail is raised
    shifts = [0.0, 0.002, -0.004]
    geo = contact_geometry(pair.wheel, pair.rail, shifts, roll=True)
    for k, shift in enumerate(shifts):
        s = 25.0 + 5.0 * k
        placed = wheelset_on_track(pair.wheel, pair.rail, shift, x_m=s, track=layout)
        tangent = wheelset_on_track(pair.wheel, pair.rail, shift, cant_rad=phi)
        assert placed.roll_rad == pytest.approx(tangent.roll_rad, abs=1e-10)
        assert placed.roll_rad == pytest.approx(geo.roll_angle_rad[k], abs=2e-6)
        for side in ("left", "right"):
            c = placed.contacts[side]
            assert abs(c.gap_m) < 1e-11
            assert c.s[2] == pytest.approx(s, abs=1e-9) and abs(c.s[1]) < 1e-9  # in the radial plane
            assert c.rolling_radius_m == pytest.approx(tangent.contacts[side].rolling_radius_m, abs=1e-10)
            assert c.rolling_radius_m == pytest.approx(geo.rolling_radius_m[side][k], abs=2e-6)
            assert c.contact_angle_rad == pytest.approx(tangent.contacts[side].contact_angle_rad, abs=1e-9)
            # on the rail surface of the layout (exact frames, not the kernel's cubic pieces)
            rail_z = float(pair.rail.position(c.s[3])[1])
            on_rail = layout.surface_point(c.s[2], side, c.rail_y_m, rail_z)[0]
            np.testing.assert_allclose(c.point_m, on_rail, atol=1e-10)
            # plan radius from the curve centre (0, R) and height, from the 2D cross-section
            y2d, z2d = geo.contact_y_m[side][k], geo.contact_z_m[side][k]
            assert math.hypot(c.point_m[0], c.point_m[1] - radius) == pytest.approx(
                radius - (y2d * math.cos(phi) - z2d * math.sin(phi)), abs=2e-6)
            assert c.point_m[2] == pytest.approx(y2d * math.sin(phi) + z2d * math.cos(phi), abs=2e-6)


def test_bad_track_input(pair, layout):
    con = WheelRailContact(pair.wheel, pair.rail, "left", track=layout)
    q = np.r_[0.0, 0.0, 0.46, 1.0, 0.0, 0.0, 0.0]
    with pytest.raises(ParameterError, match=r"s1r=90 m: the left rail's contact point leaves the track, "
                                             r"defined for 0 <= s1r <= 80 m"):
        con.evaluate(q, np.array([0.06, 0.0, 90.0, 0.05]))
    with pytest.raises(ParameterError, match="x_m=95.0: must lie on the track layout"):
        wheelset_on_track(pair.wheel, pair.rail, x_m=95.0, track=layout)
    with pytest.raises(ParameterError, match="cant_rad=0.1: a TrackLayout carries its own cant"):
        WheelRailContact(pair.wheel, pair.rail, "left", track=layout, cant_rad=0.1)
    with pytest.raises(ParameterError, match="track='curved': must be a TrackCrossSection"):
        WheelRailContact(pair.wheel, pair.rail, "left", track="curved")


# --- dynamics ----------------------------------------------------------------------------------
CONICITY, RADIUS, SPEED, AXLE_LOAD = 0.1, 600.0, 5.0, 50e3


def _lateral_offset(layout, position, s):
    """Lateral offset of points from the centreline in the track frame, and their chainage."""
    s = np.array(s, float)
    for _ in range(4):
        f = layout.track_frame(s)
        s = s + np.einsum("ni,ni->n", position - f.R, f.A[:, :, 0])
    f = layout.track_frame(s)
    return np.einsum("ni,ni->n", position - f.R, f.A[:, :, 1]), s


def _pure_rolling_shift(pair, layout, s, centre):
    """Kinematic steady state of a radial wheelset: the shift at which the rolling radii are in
    the ratio of the contact points' plan radii from the curve centre (secant iterations)."""
    def mismatch(y):
        c = wheelset_on_track(pair.wheel, pair.rail, y, x_m=s, track=layout).contacts
        rho = {k: math.hypot(*(c[k].point_m[:2] - centre)) for k in c}
        return c["left"].rolling_radius_m / rho["left"] - c["right"].rolling_radius_m / rho["right"]

    y0, y1 = -0.004, -0.006
    f0, f1 = mismatch(y0), mismatch(y1)
    for _ in range(8):
        y0, y1, f0 = y1, y1 - f1 * (y1 - y0) / (f1 - f0), f1
        f1 = mismatch(y1)
        if abs(y1 - y0) < 1e-10:
            break
    return y1


def test_free_coned_wheelset_curves_at_the_pure_rolling_offset():
    """A free coned wheelset (linear creep, no driving constraint) coasts from tangent track
    through a clothoid into a 600 m curve (no cant) and settles where its wheels roll without
    longitudinal slip: offset toward the outer rail ``y = r0 b / (gamma R)``, with ``b`` half the
    contact-point distance and ``gamma`` the conicity of the rolled wheelset from the placement
    geometry (1:10 cone; the tread conicity, ignoring the roll, is 7.8 % too small here). The
    transition is two Klingel wavelengths long, so little oscillation is left."""
    pair = profile_pair("conical", CONICITY)
    klingel = 2 * math.pi * math.sqrt(0.46 * 0.75 / CONICITY)
    layout = TrackLayout([Tangent(5.0), Transition(2 * klingel), Curve(1.6 * klingel, RADIUS, "left")],
                         rail_offset_m=rail_offset_for(pair.rail))
    placed = wheelset_on_track(pair.wheel, pair.rail, 0.0, x_m=2.0, track=layout)
    r0 = placed.contacts["left"].rolling_radius_m
    scene = Scene(gravity=(0.0, 0.0, -G))
    scene.add(RigidBody("ws", MASS, INERTIA, position=placed.position_m, rotation=placed.rotation,
                        velocity=tuple(SPEED * placed.rotation[:, 0]),
                        angular_velocity=tuple(placed.rotation[:, 1] * SPEED / r0)))
    scene.add(PointLoad("axle_load", "ws", force=(0.0, 0.0, -AXLE_LOAD)))
    creep = CreepModel("linear", nominal_normal_force_N=0.5 * (MASS * G + AXLE_LOAD))
    for side in ("left", "right"):
        scene.add(WheelRailJoint(f"wr_{side}", "ws", side, pair.wheel, pair.rail, track=layout, creep=creep))
    model = MultibodyModel(scene)
    assert {e.library for e in model.wheelrail} == {"wheelrail_railframe_rigid_track"}
    t_end = (layout.length_m - 4.0) / SPEED
    res = simulate(model, t_end, n_out=int(3 * t_end), progress=False)
    s_contact = 0.5 * (res.wheelrail["wr_left"]["s"][:, 2] + res.wheelrail["wr_right"]["s"][:, 2])
    lateral, s = _lateral_offset(layout, res.q[:, :3], s_contact)
    # the last Klingel wavelength, in the curve: mean offset and what is left of the oscillation
    last = s > s[-1] - klingel
    assert s[last].min() > 5.0 + 2 * klingel
    measured = float(np.mean(lateral[last]))
    # kinematic pure rolling from the placement geometry in the curve
    s_ref = float(s[-1])
    frame = layout.track_frame(s_ref)
    centre = frame.R[0, :2] + RADIUS * np.array([-frame.A[0, 1, 0], frame.A[0, 0, 0]])
    exact = _pure_rolling_shift(pair, layout, s_ref, centre)
    centred = wheelset_on_track(pair.wheel, pair.rail, 0.0, x_m=s_ref, track=layout).contacts
    b = 0.5 * math.hypot(*(centred["left"].point_m[:2] - centred["right"].point_m[:2]))
    shifted = wheelset_on_track(pair.wheel, pair.rail, exact, x_m=s_ref, track=layout).contacts
    gamma = (shifted["right"].rolling_radius_m - shifted["left"].rolling_radius_m) / (-2 * exact)
    formula = -r0 * b / (gamma * RADIUS)  # toward the outer (right) rail
    print(f"steady offset: simulated {measured * 1e3:.4f} mm, pure rolling {exact * 1e3:.4f} mm, "
          f"r0 b/(gamma R) {formula * 1e3:.4f} mm (gamma {gamma:.4f}), tread-conicity formula "
          f"{-r0 * b / (CONICITY * RADIUS) * 1e3:.4f} mm; oscillation +-{np.ptp(lateral[last]) * 5e2:.4f} mm")
    assert measured == pytest.approx(exact, rel=5e-3)
    assert measured == pytest.approx(formula, rel=1e-2)
    assert abs(-r0 * b / (CONICITY * RADIUS) / measured - 1) > 0.05  # the roll correction matters
    assert np.ptp(lateral[last]) < 0.05 * abs(exact)
    # coasting: the speed along the track decays only slightly, the wheels hardly slip
    speed = np.linalg.norm(res.v[:, :3], axis=1)
    assert speed[-1] == pytest.approx(SPEED, rel=2e-3) and speed[-1] < SPEED
    assert np.abs(res.wheelrail["wr_left"]["xi_x"][last]).max() < 1e-5
    assert res.position_drift.max() < 5e-5  # index-1 drift at rtol 1e-6, as on tangent track


def test_crossing_the_end_of_a_cant_ramp():
    """A linear cant ramp ends with a kink in the rails (the cant rate steps; the raised rail's
    slope drops by 4 mrad here): the rigid contact crosses it as an impact, which the driver's
    contact-jump projection carries (augmented formulation); the wheelset follows the cant."""
    pair = profile_pair("conical", CONICITY)
    layout = TrackLayout([Tangent(3.0), Transition(10.0), Curve(10.0, 300.0, "right", 0.08)],
                         rail_offset_m=rail_offset_for(pair.rail))
    x0 = 11.0
    placed = wheelset_on_track(pair.wheel, pair.rail, 0.0, x_m=x0, track=layout)
    axes = layout.track_frame(x0).A[0]
    cant_rate = float(np.diff(layout.cant_angle([x0 - 1e-4, x0 + 1e-4]))[0] / 2e-4)
    omega = (placed.rotation[:, 1] * SPEED / 0.46 + SPEED * cant_rate * axes[:, 0]
             + SPEED * float(layout.curvature(x0)[0]) * np.array([0.0, 0.0, 1.0]))
    scene = Scene(gravity=(0.0, 0.0, -G))
    scene.add(RigidBody("ws", MASS, INERTIA, position=placed.position_m, rotation=placed.rotation,
                        velocity=tuple(SPEED * axes[:, 0]), angular_velocity=tuple(omega)))
    creep = CreepModel("linear", nominal_normal_force_N=0.5 * MASS * G)
    for side in ("left", "right"):
        scene.add(WheelRailJoint(f"wr_{side}", "ws", side, pair.wheel, pair.rail, track=layout, creep=creep))
    res = simulate(MultibodyModel(scene), 0.8, n_out=40, progress=False)
    assert res.stats.get("contact_jumps", 0) >= 1
    s = res.wheelrail["wr_left"]["s"][:, 2]
    assert s[0] < 13.0 < s[-1]
    tilt = np.array([math.asin(_rotation(q[3:7])[2, 1]) for q in res.q])  # axle against the horizontal
    ramp = s < 13.0
    np.testing.assert_allclose(tilt[ramp], layout.cant_angle(s[ramp]), atol=1e-3)
    assert abs(tilt[-1] - layout.cant_angle(s[-1])[0]) < 3e-3  # in the curve: the cant plus the rolled offset
    normal = np.c_[res.wheelrail["wr_left"]["normal_force_N"], res.wheelrail["wr_right"]["normal_force_N"]]
    assert normal[1:].min() > 0.7 * 0.5 * MASS * G
    assert res.position_drift[-1] < 5e-5


def test_running_off_the_layout_stops_the_run_with_its_chainage():
    pair = profile_pair("conical", CONICITY)
    layout = TrackLayout([Curve(6.0, RADIUS, "left")], rail_offset_m=rail_offset_for(pair.rail))
    placed = wheelset_on_track(pair.wheel, pair.rail, 0.0, x_m=5.0, track=layout)
    scene = Scene(gravity=(0.0, 0.0, -G))
    scene.add(RigidBody("ws", MASS, INERTIA, position=placed.position_m, rotation=placed.rotation,
                        velocity=tuple(SPEED * placed.rotation[:, 0]),
                        angular_velocity=tuple(placed.rotation[:, 1] * SPEED / 0.46)))
    for side in ("left", "right"):
        scene.add(WheelRailJoint(f"wr_{side}", "ws", side, pair.wheel, pair.rail, track=layout))
    with pytest.raises(SolverError, match=r"at t = .* the wr_left contact point left the track: .* defined for 0 <= s1r <= 6 m") as err:
        simulate(MultibodyModel(scene), 1.0, n_out=10, progress=False)
    assert err.value.partial is not None
