"""Wheel/rail constraint contact (seed eqs. 21, 22): compiled derivatives against finite
differences, agreement with the 2D contact geometry, the two forms against each other, and
continuity across spline pieces."""
import math

import numpy as np
import pytest

from symcat.errors import ParameterError
from symcat.wheelrail import TrackCrossSection, contact_geometry, profile_pair
from symcat.wheelrail.constraint_contact import WheelRailContact, euler_parameters_roll

FORMS = ("global", "railframe")
SHIFTS = np.array([-6e-3, -4e-3, -2e-3, 0.0, 2e-3, 4e-3, 6e-3])
X0 = 0.3  # axle position along the track [m]


@pytest.fixture(scope="module")
def pairs():
    return {name: profile_pair(name) for name in ("conical", "s1002_uic60")}


@pytest.fixture(scope="module")
def geometry(pairs):
    return {name: contact_geometry(p.wheel, p.rail, SHIFTS, roll=True) for name, p in pairs.items()}


def _state(geo, pair, side, k):
    """Wheelset coordinates and 2D surface parameters of shift number ``k`` (both wheels touching)."""
    q = np.r_[X0, SHIFTS[k], geo.axle_height_m[k], euler_parameters_roll(geo.roll_angle_rad[k])]
    s = np.array([pair.wheel.s_at(geo.wheel_y_m[side][k]), 0.0, X0, pair.rail.s_at(geo.rail_y_m[side][k])])
    return q, s


def _yaw_pitch(q, yaw, pitch):
    """Compose the wheelset rotation with a yaw (about z) and a pitch (about y, the axle)."""
    def quat(axis, a):
        return np.r_[math.cos(a / 2), math.sin(a / 2) * np.asarray(axis, float)]

    def mul(p, r):
        return np.r_[p[0] * r[0] - p[1:] @ r[1:], p[0] * r[1:] + r[0] * p[1:] + np.cross(p[1:], r[1:])]

    out = q.copy()
    out[3:7] = mul(quat([0, 0, 1], yaw), mul(q[3:7], quat([0, 1, 0], pitch)))
    return out


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("side", ("left", "right"))
def test_derivatives_against_finite_differences(pairs, geometry, form, side, rng):
    pair = pairs["s1002_uic60"]
    con = WheelRailContact(pair.wheel, pair.rail, side, form=form)
    for trial in range(3):
        k = rng.integers(len(SHIFTS))
        q0, s0 = _state(geometry["s1002_uic60"], pair, side, k)
        q0 = _yaw_pitch(q0, rng.uniform(-0.02, 0.02), rng.uniform(-1, 1))
        q0[:3] += rng.uniform(-1e-3, 1e-3, 3)
        s0 = s0 + np.array([rng.uniform(-2e-3, 2e-3), rng.uniform(-0.05, 0.05), rng.uniform(-1e-3, 1e-3),
                            rng.uniform(-2e-3, 2e-3)])
        y0 = np.r_[q0, s0]
        scale = np.r_[1.0, 0.1, 0.01, 0.2 * np.ones(4), 0.01, 1.0, 1.0, 0.01]
        y1, y2 = scale * rng.uniform(-1, 1, 11), scale * rng.uniform(-1, 1, 11)
        p = con.parameters(s0)  # one spline piece: the kernel is then an exact function of y
        lib, name = con.kernels, con.library
        y = lambda t: y0 + y1 * t + y2 * t**2
        c = lambda t: np.asarray(lib[f"{name}_c"](y(t), 0.0, p)).ravel()

        def jac(t):
            c_y, c_t = (np.asarray(m) for m in lib[f"{name}_jac"](y(t), 0.0, p))
            return c_y.reshape(5, 11), c_t.ravel()

        h = 1e-5
        c_y, c_t = jac(0.0)
        np.testing.assert_array_equal(c_t, 0.0)
        # C_s column by column, and C_y y_dot against the rate of C along the trajectory
        kern = con.evaluate(q0, s0, y1[:7], y1[7:])
        for j in range(4):
            e = np.zeros(4)
            e[j] = 1e-6
            fd = (con.residual(q0, s0 + e, pieces=_pieces(con, s0)) - con.residual(q0, s0 - e, pieces=_pieces(con, s0))) / 2e-6
            np.testing.assert_allclose(kern.C_s[:, j], fd, rtol=1e-6, atol=1e-8 * max(1.0, np.abs(fd).max()))
        np.testing.assert_allclose(np.c_[kern.C_q, kern.C_s], c_y, rtol=1e-14, atol=1e-15)
        rate_fd = (c(h) - c(-h)) / (2 * h)
        np.testing.assert_allclose(c_y @ y1 + c_t, rate_fd, rtol=1e-6, atol=1e-9 * np.abs(rate_fd).max())
        # Q_d: d2C/dt2 = C_y y_ddot + Q_d, against the rate of the compiled C_y y_dot
        q_d = kern.Q_d
        cdot = lambda t: jac(t)[0] @ (y1 + 2 * y2 * t)
        acc_fd = (cdot(h) - cdot(-h)) / (2 * h)
        np.testing.assert_allclose(c_y @ (2 * y2) + q_d, acc_fd, rtol=1e-6, atol=1e-9 * np.abs(acc_fd).max())
        acc_fd2 = (c(1e-4) - 2 * c(0.0) + c(-1e-4)) / 1e-8
        np.testing.assert_allclose(c_y @ (2 * y2) + q_d, acc_fd2, rtol=1e-3, atol=1e-5 * np.abs(acc_fd2).max())


def _pieces(con, s):
    return (int(np.searchsorted(con._wpp.x, s[0], side="right") - 1),
            int(np.searchsorted(con._rpp.x, s[3], side="right") - 1))


@pytest.mark.parametrize("name", ("conical", "s1002_uic60"))
def test_contact_of_the_2d_geometry_is_a_solution(pairs, geometry, name, rng):
    """At the wheelset states where both wheels touch (2D geometry with roll), the five
    constraints vanish at the 2D contact, and Newton from a perturbed guess finds it again."""
    pair, geo = pairs[name], geometry[name]
    worst = {"c": 0.0, "radius": 0.0, "angle": 0.0}
    for side in ("left", "right"):
        cons = {form: WheelRailContact(pair.wheel, pair.rail, side, form=form) for form in FORMS}
        for k in range(len(SHIFTS)):
            q, s = _state(geo, pair, side, k)
            guess = s + np.array([rng.uniform(-2e-3, 2e-3), rng.uniform(-0.02, 0.02), rng.uniform(-5e-3, 5e-3),
                                  rng.uniform(-2e-3, 2e-3)])
            for form, con in cons.items():
                worst["c"] = max(worst["c"], np.abs(con.residual(q, s)).max())
                sol = con.solve(q, guess)
                worst["radius"] = max(worst["radius"], abs(sol.rolling_radius_m - geo.rolling_radius_m[side][k]))
                worst["angle"] = max(worst["angle"], abs(sol.contact_angle_rad - geo.contact_angle_rad[side][k]))
                assert abs(sol.gap_m) < 1e-9
                assert abs(sol.wheel_y_m - geo.wheel_y_m[side][k]) < 1e-6
                assert abs(sol.point_m[1] - geo.contact_y_m[side][k]) < 1e-6
                assert abs(sol.point_m[2] - geo.contact_z_m[side][k]) < 1e-6
                assert abs(sol.s[1]) < 1e-9 and abs(sol.s[2] - X0) < 1e-9
    assert worst["c"] < 1e-9, worst
    assert worst["radius"] < 1e-6, worst
    assert worst["angle"] < 1e-5, worst


def test_forms_agree_on_separated_and_yawed_states(pairs, geometry, rng):
    """Both forms vanish at the same states and locate the same point, also off the 2D states:
    yawed, pitched, lifted or pressed wheelsets (the gap is then the normal distance)."""
    pair, geo = pairs["s1002_uic60"], geometry["s1002_uic60"]
    for side in ("left", "right"):
        rf = WheelRailContact(pair.wheel, pair.rail, side, form="railframe")
        gl = WheelRailContact(pair.wheel, pair.rail, side, form="global")
        for trial in range(4):
            k = rng.integers(len(SHIFTS))
            q, s = _state(geo, pair, side, k)
            np.testing.assert_allclose(gl.residual(q, s), 0, atol=1e-9)
            np.testing.assert_allclose(rf.residual(q, s), 0, atol=1e-9)
            lift = rng.uniform(-2e-4, 1e-3)
            q2 = _yaw_pitch(q, rng.uniform(-0.01, 0.01), rng.uniform(-0.5, 0.5))
            q2[2] += lift
            a, b = rf.solve(q2), gl.solve(q2)  # from the built-in initial guess
            np.testing.assert_allclose(a.s, b.s, rtol=0, atol=1e-10)
            assert abs(a.gap_m - b.gap_m) < 1e-12
            # the gap is the distance along the rail normal, close to lift * cos(angle)
            assert abs(a.gap_m - lift * math.cos(a.contact_angle_rad)) < 5e-5
            # lowering the wheelset by the gap along the normal closes the contact: both forms vanish
            q3 = q2.copy()
            q3[:3] -= a.gap_m * a.normal
            for con in (rf, gl):
                np.testing.assert_allclose(con.residual(q3, a.s), 0, atol=1e-12)


@pytest.mark.parametrize("profile", ("wheel", "rail"))
def test_continuous_across_spline_pieces(pairs, geometry, profile):
    """C and C_s are continuous where the runtime switches spline pieces (C2 profiles)."""
    pair, geo = pairs["s1002_uic60"], geometry["s1002_uic60"]
    q, s = _state(geo, pair, "left", 3)
    for form in FORMS:
        con = WheelRailContact(pair.wheel, pair.rail, "left", form=form)
        pp, j = (con._wpp, 0) if profile == "wheel" else (con._rpp, 3)
        i = int(np.searchsorted(pp.x, s[j]))  # the breakpoint just beyond the contact
        sb = s.copy()
        sb[j] = pp.x[i]
        base = _pieces(con, s)
        before = (i - 1, base[1]) if j == 0 else (base[0], i - 1)
        after = (i, base[1]) if j == 0 else (base[0], i)
        qd, sd = np.r_[0.1, 0.2, 0.3, 0.01, 0.02, -0.01, 0.03], np.array([0.01, 5.0, 1.0, -0.01])
        ka = con.evaluate(q, sb, qd, sd, pieces=before)
        kb = con.evaluate(q, sb, qd, sd, pieces=after)
        np.testing.assert_allclose(ka.c, kb.c, rtol=0, atol=1e-12)
        np.testing.assert_allclose(ka.C_s, kb.C_s, rtol=0, atol=1e-9 * np.abs(ka.C_s).max())
        np.testing.assert_allclose(ka.C_q, kb.C_q, rtol=0, atol=1e-12 * np.abs(ka.C_q).max())
        # Q_d of the point rows needs the profiles' second derivatives (continuous); that of the
        # tangency rows their third (a cubic spline's jumps at the breakpoints): a bounded jump
        np.testing.assert_allclose(ka.Q_d[:3], kb.Q_d[:3], rtol=0, atol=1e-7 * np.abs(ka.Q_d).max())
        # automatic selection just before and after the breakpoint
        e = np.zeros(4)
        e[j] = 1e-9
        np.testing.assert_allclose(con.residual(q, sb - e), con.residual(q, sb + e), atol=1e-8)


def test_inclined_rails_and_cant(pairs):
    """An extra rail inclination (1:20 instead of the built-in 1:40) matches the 2D geometry, and
    canting the whole cross-section with the wheelset leaves the contact unchanged."""
    pair = pairs["s1002_uic60"]
    track = TrackCrossSection(rail_inclination_rad=math.atan(1 / 20))
    geo = contact_geometry(pair.wheel, pair.rail, SHIFTS[[0, 3, 6]], roll=True, track=track)
    cant = 0.1
    for side in ("left", "right"):
        for form in FORMS:
            con = WheelRailContact(pair.wheel, pair.rail, side, form=form, track=track)
            canted = WheelRailContact(pair.wheel, pair.rail, side, form=form, track=track, cant_rad=cant)
            for k in range(3):
                q = np.r_[X0, SHIFTS[[0, 3, 6]][k], geo.axle_height_m[k], euler_parameters_roll(geo.roll_angle_rad[k])]
                sol = con.solve(q)
                assert abs(sol.gap_m) < 1e-9
                assert abs(sol.rolling_radius_m - geo.rolling_radius_m[side][k]) < 1e-9
                assert abs(sol.contact_angle_rad - geo.contact_angle_rad[side][k]) < 1e-8
                qc = np.r_[q[0], _rot_x(cant)[1:, 1:] @ q[1:3], euler_parameters_roll(geo.roll_angle_rad[k] + cant)]
                sc = canted.solve(qc, sol.s)
                np.testing.assert_allclose(sc.s, sol.s, atol=1e-10)
                assert abs(sc.contact_angle_rad - sol.contact_angle_rad) < 1e-10 and abs(sc.gap_m) < 1e-9


def test_buffered_kernels_equal_casadi_calls(pairs):
    """evaluate calls the kernels in preallocated buffers: the same values as CasADi's calls."""
    pair = pairs["s1002_uic60"]
    con = WheelRailContact(pair.wheel, pair.rail, "right", form="global")
    q, s = np.r_[X0, 1e-3, 0.46, 1.0, 0.0, 0.0, 0.0], np.array([0.09, 0.01, X0, 0.066])
    qd, sd = np.linspace(-1, 1, 7), np.array([1e-3, 37.0, 17.0, 1e-3])
    k = con.evaluate(q, s, qd, sd)
    y, p, lib = np.r_[q, s], con.parameters(s), con.kernels
    c_y, c_t = (np.asarray(m) for m in lib[f"{con.library}_jac"](y, 0.0, p))
    assert np.array_equal(k.c, np.asarray(lib[f"{con.library}_c"](y, 0.0, p)).ravel())
    assert np.array_equal(np.hstack([k.C_q, k.C_s]), c_y) and np.array_equal(k.C_t, c_t.ravel())
    assert np.array_equal(k.Q_d, np.asarray(lib[f"{con.library}_gamma"](y, np.r_[qd, sd], 0.0, p)).ravel())


def _rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def test_bad_input(pairs):
    pair = pairs["conical"]
    with pytest.raises(ParameterError, match="side="):
        WheelRailContact(pair.wheel, pair.rail, "middle")
    with pytest.raises(ParameterError, match="form="):
        WheelRailContact(pair.wheel, pair.rail, "left", form="local")
    with pytest.raises(ParameterError, match="rail="):
        WheelRailContact(pair.wheel, pair.wheel, "left")
    con = WheelRailContact(pair.wheel, pair.rail, "left")
    with pytest.raises(ParameterError, match="s1w="):
        con.residual(np.r_[0, 0, 0.46, 1, 0, 0, 0], np.array([5.0, 0, 0, 0.03]))
