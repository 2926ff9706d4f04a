"""The contact ellipse and Kalker's coefficients follow the contact point inside the creep
function's CasADi graph (symcat.assembly.creep_ellipse), checked against the NumPy functions."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from symcat.assembly.creep_ellipse import hertz_semi_axes_sx, kalker_coefficients_sx
from symcat.model import run_model
from symcat.wheelrail import profile_pair
from symcat.wheelrail.creep import _kalker_table, kalker_coefficients, kalker_linear_forces
from symcat.wheelrail.hertz import hertz_contact, relative_curvatures


@pytest.fixture(scope="module")
def hertz_sx():
    n, a, b = ca.SX.sym("N"), ca.SX.sym("A"), ca.SX.sym("B")
    return ca.Function("hertz", [n, a, b], list(hertz_semi_axes_sx(n, a, b)))


@pytest.fixture(scope="module")
def kalker_sx():
    x = ca.SX.sym("a_over_b")
    return ca.Function("kalker", [x], list(kalker_coefficients_sx(x)))


def test_hertz_semi_axes_match_the_numeric_ellipse(hertz_sx):
    """B/A from 1e-12 to 1e12 (hertz_contact's range; both orientations), circles included."""
    rng = np.random.default_rng(7)
    ratios = np.r_[1.0, 1 + 1e-9, 1 - 1e-9, np.geomspace(1e-12, 1e12, 241), rng.uniform(0.05, 200.0, 100)]
    forces = rng.uniform(1e3, 2e5, ratios.size)
    A = rng.uniform(0.3, 3.0, ratios.size)
    got = np.array([[float(v) for v in hertz_sx(n, a, a * r)] for n, a, r in zip(forces, A, ratios)])
    ref = hertz_contact(forces, A, A * ratios)
    np.testing.assert_allclose(got[:, 0], ref.semi_axis_a_m, rtol=1e-8)
    np.testing.assert_allclose(got[:, 1], ref.semi_axis_b_m, rtol=1e-8)


def test_hertz_semi_axes_are_differentiable(hertz_sx):
    """The graph's derivative in B is the numeric one's (central differences)."""
    n, a = ca.SX.sym("N"), ca.SX.sym("A")
    for ratio in (0.3, 1.7, 40.0):
        b = ca.SX.sym("B")
        jac = ca.Function("j", [n, a, b], [ca.jacobian(ca.vertcat(*hertz_semi_axes_sx(n, a, b)), b)])
        h = 1e-6 * ratio
        fd = (np.array([float(hertz_contact(8e4, 1.0, ratio + h).semi_axis_a_m),
                        float(hertz_contact(8e4, 1.0, ratio + h).semi_axis_b_m)])
              - np.array([float(hertz_contact(8e4, 1.0, ratio - h).semi_axis_a_m),
                          float(hertz_contact(8e4, 1.0, ratio - h).semi_axis_b_m)])) / (2 * h)
        np.testing.assert_allclose(np.array(jac(8e4, 1.0, ratio)).ravel(), fd, rtol=1e-5)


def test_kalker_coefficients_at_the_nodes_and_between(kalker_sx):
    nodes = _kalker_table()[1]
    between = np.geomspace(0.02, 50.0, 1501)  # beyond the table too: clamped like the numeric function
    for points, rtol in ((nodes, 1e-13), (between, 1e-12)):
        got = np.array([[float(v) for v in kalker_sx(x)] for x in points]).T
        ref = np.array(kalker_coefficients(points, clamp=True))
        np.testing.assert_allclose(got, ref, rtol=rtol)


def test_kalker_coefficients_with_poisson_ratio_and_factor():
    x = ca.SX.sym("x")
    fn = ca.Function("k", [x], list(kalker_coefficients_sx(x, poisson_ratio=0.25, factor=0.7)))
    for ratio in (0.13, 1.0, 2.2, 9.0):
        np.testing.assert_allclose([float(v) for v in fn(ratio)], 0.7 * np.array(kalker_coefficients(ratio, 0.25)),
                                   rtol=1e-12)


def _numeric_forces(pair, w, i, s, nominal_N, r0_m=0.46):
    """Kalker's linear forces from the creepages recorded at output ``i`` and a Hertz ellipse at
    the contact point of surface parameters ``s`` (NumPy, independent of the graph)."""
    d = pair.wheel.derivative(s[0])
    A, B = relative_curvatures(r0_m + pair.wheel.position(s[0])[1], -pair.wheel.curvature(s[0]),
                               -pair.rail.curvature(s[3]), np.arctan2(-d[1], d[0]))
    e = hertz_contact(nominal_N, A, B)
    a, b = float(e.semi_axis_a_m), float(e.semi_axis_b_m)
    return a / b, kalker_linear_forces(w["xi_x"][i], w["xi_y"][i], w["phi_per_m"][i], a, b,
                                       kalker_coefficients(a / b, clamp=True))


def test_s1002_creep_forces_follow_the_contact_point():
    """The S1002 wheelset of test_s1002_flange_to_tread_and_over_to_the_other_flange: the creep
    forces at every output are Kalker's with the Hertz ellipse at that output's contact point
    (flange flank, flange root, tread), not at the initial one."""
    pair = profile_pair("s1002_uic60", 0.05)
    res = run_model("wheelset", {"profile": "s1002_uic60", "lateral_offset_m": -0.008, "creep": "linear",
                                 "t_end": 0.3, "n_out": 60}).arrays["result"]
    nominal_N = 0.5 * (1813.0 * 9.81 + (32000.0 + 2 * 2615.0) / 4 * 9.81)  # models/wheelset.py
    for name, w in res.wheelrail.items():
        shapes, initial_gap = [], []
        for i in range(len(w["fy_N"])):
            ratio, ref = _numeric_forces(pair, w, i, np.asarray(w["s"])[i], nominal_N)
            shapes.append(ratio)
            got = np.array([w["fx_N"][i], w["fy_N"][i], w["mz_Nm"][i]])
            scale = np.abs(np.array(ref)).max()
            np.testing.assert_allclose(got, np.array(ref), rtol=1e-7, atol=1e-9 * scale, err_msg=f"{name} {i}")
            # with the initial ellipse instead (the former behaviour)
            _, first = _numeric_forces(pair, w, i, np.asarray(w["s"])[0], nominal_N)
            initial_gap.append(abs(first.fy_N - ref.fy_N) / max(abs(ref.fy_N), 1.0))
        assert max(shapes) / min(shapes) > 3.0, name  # the ellipse changes shape along the run
        assert max(initial_gap) > 0.3, name  # and the initial ellipse would give other forces
