"""Profiles: loading and frames, C2 smoothness, the evaluation API, analytic profiles, bad data."""
import math

import numpy as np
import pytest

from symcat.errors import ParameterError
from symcat.wheelrail import (
    PROFILE_NAMES,
    Profile,
    circular_rail,
    circular_wheel,
    coned_wheel,
    gauge_point,
    load_profile,
)


@pytest.fixture(scope="module", params=PROFILE_NAMES)
def shipped(request):
    return load_profile(request.param)


def test_shipped_profiles_fit_their_points(shipped):
    assert shipped.points is not None and len(shipped.points) > 300
    assert shipped.fit_max_m < 2e-6  # smoothing: 0.2 um rms
    assert shipped.source.startswith("source:")
    y0, y1 = shipped.y_range
    assert y1 - y0 > 0.06


def test_wheel_frames_agree():
    # Both wheels: tape circle at y = 0 with z = 0, flange at negative y with its tip 28 mm out.
    for name in ("S1002", "EN15302_wheel_A"):
        w = load_profile(name)
        s, p = w.sample(1e-5)
        tip = p[np.argmax(p[:, 1])]
        assert w.kind == "wheel"
        assert abs(w.z_at(0.0)) < 2e-5, name
        assert -0.057 < tip[0] < -0.053 and abs(tip[1] - 0.028) < 5e-5, (name, tip)
        assert w.y_range[0] == pytest.approx(-0.070, abs=5e-4)
        assert w.slope_at(0.01) < 0  # radius falls toward the field side


def test_rail_frames_agree():
    for name, incl in (("UIC60_canted_1in40", 1 / 40), ("EN15302_rail_A", 1 / 20)):
        r = load_profile(name)
        s, p = r.sample(1e-5)
        assert r.kind == "rail"
        assert p[:, 1].max() == pytest.approx(0.0, abs=2e-6)  # top of rail at z = 0
        g = gauge_point(r)
        assert g[1] == pytest.approx(-0.014, abs=1e-6) and g[0] < -0.03  # gauge face at negative y
        assert r.inclination_rad == pytest.approx(math.atan(incl))
    # EN 15302 rail A: its gauge point and the standard's gauge 1435.16 mm put the rail's origin
    # under the tape circle of wheels 1500 mm apart.
    ya = gauge_point(load_profile("EN15302_rail_A"))[0]
    assert 0.5 * 1.43516 - ya == pytest.approx(0.75, abs=5e-5)


def test_c2_at_every_breakpoint(shipped):
    pp = shipped.piecewise_polynomial()
    c, h = pp.c, np.diff(pp.x)[:-1, None]
    # Left limits at x_{i+1} from piece i (r = c0 h^3 + c1 h^2 + c2 h + c3) against piece i+1 at 0.
    left = [c[0, :-1] * h**3 + c[1, :-1] * h**2 + c[2, :-1] * h + c[3, :-1],
            3 * c[0, :-1] * h**2 + 2 * c[1, :-1] * h + c[2, :-1],
            6 * c[0, :-1] * h + 2 * c[1, :-1]]
    right = [c[3, 1:], c[2, 1:], 2 * c[1, 1:]]
    for order, tol in ((0, 1e-15), (1, 1e-11), (2, 1e-7)):
        scale = max(np.abs(right[order]).max(), 1.0)
        assert np.abs(left[order] - right[order]).max() < tol * scale, (shipped.name, order)
    # The third derivative does jump: these are genuine cubic pieces, not one polynomial.
    assert np.abs(6 * c[0, :-1] - 6 * c[0, 1:]).max() > 1.0


def test_curvature_is_sane(shipped):
    s = np.linspace(shipped.s_min, shipped.s_max, 20000)
    kappa = shipped.curvature(s)
    # The sharpest corner is EN 15302 wheel A's 1:15 -> 1:1 chamfer kink, rounded over ~1 mm.
    assert np.abs(kappa).max() < 2000.0
    speed = np.linalg.norm(shipped.derivative(s, 1), axis=-1)
    assert 0.97 < speed.min() and speed.max() < 1.03  # parameter within 3 % of arc length


def test_evaluation_api_against_finite_differences():
    r = load_profile("UIC60_canted_1in40")
    rng = np.random.default_rng(0)
    s = rng.uniform(r.s_min + 1e-3, r.s_max - 1e-3, (5, 7))
    h = 1e-6
    assert r.position(s).shape == (5, 7, 2)
    fd1 = (r.position(s + h) - r.position(s - h)) / (2 * h)
    fd2 = (r.position(s + h) - 2 * r.position(s) + r.position(s - h)) / h**2
    np.testing.assert_allclose(r.derivative(s, 1), fd1, atol=1e-6)
    np.testing.assert_allclose(r.derivative(s, 2), fd2, atol=2e-2 * np.abs(fd2).max())
    np.testing.assert_allclose(np.linalg.norm(r.tangent(s), axis=-1), 1.0)
    pp = r.piecewise_polynomial()
    assert pp.c.shape[0] == 4 and pp.c.shape[2] == 2
    np.testing.assert_allclose(pp(s), r.position(s), atol=1e-15)
    np.testing.assert_allclose(pp(s, 2), r.derivative(s, 2), rtol=1e-9, atol=1e-9)


def test_graph_lookup_round_trip_including_steep_faces():
    r = load_profile("UIC60_canted_1in40")
    s = np.linspace(r.s_min, r.s_max, 3001)
    p = r.position(s)
    np.testing.assert_allclose(r.z_at(p[:, 0]), p[:, 1], atol=1e-9)
    assert np.isnan(r.z_at(r.y_range[1] + 1e-3))
    # On the near-vertical gauge face the graph slope is huge but finite and positive.
    assert r.slope_at(-0.0435) > 10


def test_envelope_lookup_equals_the_full_newton():
    """s_at's Newton (on the piecewise cubic, from a cubic start, stopping once converged)
    gives the point of four full Newton steps on the scipy spline to rounding, and its slope."""
    r = load_profile("UIC60_canted_1in40")
    y = np.random.default_rng(3).uniform(*r.y_range, 500)
    s, z = r.envelope_at(y)
    lo, hi = r._pieces[0]
    ys, ss = r._ytab[lo:hi + 1], r._stab[lo:hi + 1]
    i = np.clip(np.searchsorted(ys, y) - 1, 0, len(ys) - 2)
    ref = ss[i] + (y - ys[i]) / (ys[i + 1] - ys[i]) * (ss[i + 1] - ss[i])
    for _ in range(4):
        ref = np.clip(ref - (r.position(ref)[:, 0] - y) / r.derivative(ref)[:, 0], ss[i], ss[i + 1])
    assert len(r._pieces) == 1
    np.testing.assert_allclose(s, ref, rtol=0, atol=2e-15)
    np.testing.assert_allclose(z, r.position(ref)[:, 1], rtol=0, atol=2e-15)
    assert np.array_equal(r.s_at(y), s)
    s2, z2, slope = r.envelope_at(y, slope=True)
    assert np.array_equal(s2, s) and np.array_equal(z2, z)
    np.testing.assert_allclose(slope, r.slope(s), rtol=1e-12, atol=1e-15)
    assert np.isnan(r.envelope_at([r.y_range[1] + 1e-3], slope=True)[2]).all()


def test_envelope_of_a_folded_curve_takes_the_highest_branch():
    """Where y(s) turns back (three monotone pieces) the envelope is the branch of largest z."""
    u = np.linspace(-1.5, 1.5, 301)
    r = Profile.from_parametric(0.01 * u, 0.01 * (u**3 - u), 0.01 * u, "rail")
    assert len(r._pieces) >= 3
    y = np.linspace(-0.0035, 0.0035, 29)  # where all three branches pass
    top = [max(root.real for root in np.roots([1.0, 0.0, -1.0, -v / 0.01]) if abs(root.imag) < 1e-9) for v in y]
    s, z = r.envelope_at(y)
    np.testing.assert_allclose(z, 0.01 * np.array(top), atol=1e-12)
    np.testing.assert_allclose(r.position(s)[:, 0], y, atol=1e-12)


def test_normals_point_out_of_the_material():
    r = load_profile("UIC60_canted_1in40")
    w = load_profile("S1002")
    assert r.normal(r.s_at(0.0))[1] > 0.99  # rail top: up, toward the wheel
    assert w.normal(w.s_at(0.0))[1] > 0.99  # tread: +z, toward the rail
    assert w.normal(w.s_at(-0.045))[0] > 0.5  # flange flank: toward the field side, where the rail is


def test_analytic_profiles_are_exact():
    cone = coned_wheel(1 / 40)
    y = np.linspace(-0.06, 0.06, 13)
    np.testing.assert_allclose(cone.z_at(y), -y / 40, atol=1e-15)
    s = np.linspace(cone.s_min, cone.s_max, 50)
    np.testing.assert_allclose(cone.curvature(s), 0.0, atol=1e-10)
    np.testing.assert_allclose(np.linalg.norm(cone.derivative(s, 1), axis=-1), 1.0, atol=1e-12)
    rail = circular_rail(0.3)
    y = np.linspace(-0.029, 0.029, 11)
    np.testing.assert_allclose(rail.z_at(y), np.sqrt(0.09 - y**2) - 0.3, atol=1e-12)
    np.testing.assert_allclose(rail.curvature(rail.s_at(y)), -1 / 0.3, rtol=1e-6)  # convex
    wheel = circular_wheel(0.5, 0.05)
    assert wheel.z_at(0.0) == pytest.approx(0.0, abs=1e-14)
    assert wheel.slope_at(0.0) == pytest.approx(-math.tan(0.05), rel=1e-9)
    np.testing.assert_allclose(wheel.curvature(wheel.s_at(y)), 1 / 0.5, rtol=1e-6)  # hollow


def test_orientation_and_transform():
    y = np.linspace(-0.03, 0.03, 61)
    z = -0.5 * y**2
    a = Profile.from_points(y, z, "rail", "a")
    b = Profile.from_points(y[::-1], z[::-1], "rail", "b")
    s = np.linspace(a.s_min, a.s_max, 7)
    np.testing.assert_allclose(a.position(s), b.position(s), atol=1e-12)
    rot = a.transformed(0.025)
    q = a.position(s) @ np.array([[math.cos(0.025), math.sin(0.025)], [-math.sin(0.025), math.cos(0.025)]])
    np.testing.assert_allclose(rot.position(s), q, atol=1e-15)
    m = a.transformed(mirror=True)
    assert np.all(np.diff(m.position(s)[:, 0]) > 0)  # still runs with increasing y
    np.testing.assert_allclose(m.z_at(-y), a.z_at(y), atol=1e-12)


def _line(n=40):
    y = np.linspace(0.0, 0.05, n)
    return y, -0.05 * y


@pytest.mark.parametrize("case, words", [
    ("nan", ["not finite", "point 5"]),
    ("few", ["distinct points", "at least 10"]),
    ("narrow", ["lateral span", "at least 5"]),
    ("shuffled", ["turn back", "ordered"]),
    ("loop", ["cross", "intersect"]),
    ("lengths", ["y values", "z values"]),
])
def test_bad_profile_data(case, words):
    y, z = _line()
    if case == "nan":
        z[5] = np.nan
    elif case == "few":
        y, z = y[:6], z[:6]
    elif case == "narrow":
        y, z = y * 0.05, z * 0.05
    elif case == "shuffled":
        order = np.random.default_rng(1).permutation(len(y))
        y, z = y[order], z[order]
    elif case == "loop":
        t = np.linspace(-np.pi, np.pi, 200)  # a prolate trochoid: one smooth loop crossing itself
        y, z = 0.01 * (t - 2 * np.sin(t)), -0.02 * np.cos(t)
    elif case == "lengths":
        z = z[:-1]
    with pytest.raises(ParameterError) as err:
        Profile.from_points(y, z, "wheel", "test")
    msg = str(err.value)
    assert "profile 'test'" in msg
    for w in words:
        assert w in msg, msg


def test_bad_analytic_parameters():
    with pytest.raises(ParameterError, match="conicity=0"):
        coned_wheel(0.0)
    with pytest.raises(ParameterError, match="radius_m"):
        circular_rail(-0.3)
    with pytest.raises(ParameterError, match="kind"):
        Profile.from_points(*_line(), "axle")
    with pytest.raises(ParameterError, match="no such profile"):
        load_profile("S1003")
