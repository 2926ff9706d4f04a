"""Checks of the analytic reference solutions in symcat.analytic."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from symcat.analytic import (
    ElasticCatenary,
    cantilever_tip_load,
    cantilever_tip_load_linear,
    cantilever_tip_load_ode,
    elastic_catenary,
    elastic_catenary_sag,
    elastic_catenary_shape,
    elastic_catenary_span,
    rollup_tip_position,
    taut_wire_frequencies,
)

INF = float("inf")

# Mattiasson (1981), Table 1: (alpha, ux/L, uy/L) to 5 decimals, load in -y.
MATTIASSON = [
    (1.0, -0.05643, -0.30172),
    (2.0, -0.16064, -0.49346),
    (3.0, -0.25442, -0.60325),
    (4.0, -0.32894, -0.66996),
    (5.0, -0.38763, -0.71379),
    (10.0, -0.55500, -0.81061),
]


# --------------------------------------------------------------------------
# Elastica: tip load
# --------------------------------------------------------------------------


@pytest.mark.parametrize("alpha", [0.1, 1.0, 3.0, 10.0, 20.0])
def test_elliptic_and_shooting_agree(alpha):
    ux_e, uy_e = cantilever_tip_load(alpha)
    ux_o, uy_o = cantilever_tip_load_ode(alpha)
    # observed agreement is ~1e-14; 1e-10 leaves room for other platforms
    assert abs(ux_e - ux_o) < 1e-10
    assert abs(uy_e - uy_o) < 1e-10


@pytest.mark.parametrize("alpha, ux_ref, uy_ref", MATTIASSON)
def test_tip_load_matches_mattiasson_table(alpha, ux_ref, uy_ref):
    for solve in (cantilever_tip_load, cantilever_tip_load_ode):
        ux, uy = solve(alpha)
        assert abs(ux - ux_ref) < 5e-5
        assert abs(uy - uy_ref) < 5e-5
    # the closed form reproduces every tabulated digit (rounding half-ulp)
    ux, uy = cantilever_tip_load(alpha)
    assert abs(ux - ux_ref) <= 5e-6 + 1e-12
    assert abs(uy - uy_ref) <= 5e-6 + 1e-12


@pytest.mark.parametrize("solve", [cantilever_tip_load, cantilever_tip_load_ode])
def test_small_load_tends_to_linear_solution(solve):
    errors = []
    for alpha in (1e-1, 1e-2, 1e-3):
        ux, uy = solve(alpha)
        ux_lin, uy_lin = cantilever_tip_load_linear(alpha)
        assert ux_lin == 0.0 and uy_lin == pytest.approx(-alpha / 3.0, rel=1e-15)
        errors.append(abs(uy / uy_lin - 1.0))
        # leading nonlinear terms from the perturbation series:
        # ux = -alpha^2/15 + O(alpha^4), uy = -alpha/3 + 4 alpha^3/105 + O(alpha^5)
        assert ux == pytest.approx(-alpha**2 / 15.0, rel=0.2 * alpha**2 + 1e-12)
        assert (uy + alpha / 3.0) / alpha**3 == pytest.approx(4.0 / 105.0, rel=0.25 * alpha**2 + 1e-6)
    # relative deviation from linear theory shrinks like alpha^2 (4/35 alpha^2)
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 2e-7


def test_tip_load_is_continuous_across_series_switch():
    # the closed form switches to its small-load series at alpha = 0.05
    for alpha in (0.05 * (1 - 1e-9), 0.05, 0.05 * (1 + 1e-9)):
        ux_e, uy_e = cantilever_tip_load(alpha)
        ux_o, uy_o = cantilever_tip_load_ode(alpha)
        assert ux_e == pytest.approx(ux_o, rel=1e-10)
        assert uy_e == pytest.approx(uy_o, rel=1e-10)


def test_tip_load_signs_monotonicity_and_mirror():
    alphas = [0.0, 0.5, 1.0, 2.0, 5.0, 20.0, 100.0, 1000.0, 1e4]
    tips = [cantilever_tip_load(a) for a in alphas]
    assert tips[0] == (0.0, 0.0)
    ux = np.array([t[0] for t in tips])
    uy = np.array([t[1] for t in tips])
    assert np.all(np.diff(ux) < 0.0) and np.all(np.diff(uy) < 0.0)
    # the tip never passes below the clamp: ux > -1 and uy > -1
    assert ux[-1] > -1.0 and uy[-1] > -1.0
    # an inextensible beam cannot reach beyond its length
    assert np.all(np.hypot(1.0 + ux, uy) <= 1.0 + 1e-15)
    for alpha in (0.02, 3.0):
        assert cantilever_tip_load(-alpha) == (cantilever_tip_load(alpha)[0],
                                               -cantilever_tip_load(alpha)[1])
        ux_o, uy_o = cantilever_tip_load_ode(-alpha)
        assert (ux_o, -uy_o) == pytest.approx(cantilever_tip_load_ode(alpha), abs=1e-15)


# --------------------------------------------------------------------------
# Elastica: pure end moment
# --------------------------------------------------------------------------


def test_rollup_limits():
    length = 2.5
    assert rollup_tip_position(0.0, length) == (length, 0.0)
    # full circle: the tip is back at the clamp
    x, y = rollup_tip_position(1.0, length)
    assert abs(x) < 1e-14 * length and abs(y) < 1e-14 * length
    # half circle of radius L/pi: the tip sits one diameter above the clamp
    x, y = rollup_tip_position(0.5, length)
    assert abs(x) < 1e-14 * length
    assert y == pytest.approx(2.0 * length / math.pi, rel=1e-14)
    # quarter circle of radius 2L/pi
    x, y = rollup_tip_position(0.25, length)
    assert x == pytest.approx(2.0 * length / math.pi, rel=1e-14)
    assert y == pytest.approx(2.0 * length / math.pi, rel=1e-14)


def test_rollup_small_moment_and_mirror():
    length, k = 3.0, 1e-9
    x, y = rollup_tip_position(k, length)
    # linear theory: tip deflection M L^2 / (2 E I) = pi k L
    assert y == pytest.approx(math.pi * k * length, rel=1e-12)
    assert x == pytest.approx(length, rel=1e-15)
    for k in (0.3, 0.8, 1.7):
        x, y = rollup_tip_position(k, length)
        radius = length / (2.0 * math.pi * k)
        assert (x, y) == pytest.approx((radius * math.sin(2 * math.pi * k),
                                        radius * (1 - math.cos(2 * math.pi * k))), abs=1e-14)
        assert rollup_tip_position(-k, length) == pytest.approx((x, -y), abs=1e-15)


# --------------------------------------------------------------------------
# Taut wire
# --------------------------------------------------------------------------


def test_taut_wire_reduces_to_string_and_beam():
    length, tension, mu, ei = 12.0, 2.0e4, 1.07, 150.0
    n = np.arange(1, 6)
    f_string = taut_wire_frequencies(length, tension, mu, 0.0, 5)
    assert f_string.shape == (5,)
    np.testing.assert_allclose(f_string, n / (2 * length) * math.sqrt(tension / mu), rtol=1e-15)
    f_beam = taut_wire_frequencies(length, 0.0, mu, ei, 5)
    np.testing.assert_allclose(f_beam, (n * math.pi / length) ** 2 * math.sqrt(ei / mu) / (2 * math.pi),
                               rtol=1e-14)
    f = taut_wire_frequencies(length, tension, mu, ei, 5)
    expected = (n / (2 * length) * math.sqrt(tension / mu)
                * np.sqrt(1 + ei / tension * (n * math.pi / length) ** 2))
    np.testing.assert_allclose(f, expected, rtol=1e-14)
    # bending stiffness can only raise the frequencies, and f^2 = f_string^2 + f_beam^2
    assert np.all(f > f_string)
    np.testing.assert_allclose(f**2, f_string**2 + f_beam**2, rtol=1e-14)


# --------------------------------------------------------------------------
# Elastic catenary
# --------------------------------------------------------------------------

W = 1.35 * 9.81  # N/m, a typical contact wire
EA = 1.2e7  # N


@pytest.mark.parametrize("ea", [EA, INF])
@pytest.mark.parametrize("span, h", [(1.0, 1.0e3), (50.0, 1.0e2), (50.0, 1.0e4), (65.0, 2.0e4)])
def test_catenary_solver_round_trip(span, h, ea):
    c = elastic_catenary(span, W, ea, horizontal_tension=h)
    assert isinstance(c, ElasticCatenary)
    assert c.horizontal_tension_N == h and c.span_m == span
    assert elastic_catenary_span(h, c.unstretched_length_m, W, ea) == pytest.approx(span, rel=1e-14)
    assert c.sag_m == elastic_catenary_sag(h, c.unstretched_length_m, W, ea)
    assert c.support_tension_N == pytest.approx(math.hypot(h, 0.5 * W * c.unstretched_length_m), rel=1e-15)
    # and back: the length determines the tension
    c2 = elastic_catenary(span, W, ea, unstretched_length=c.unstretched_length_m)
    assert c2.horizontal_tension_N == pytest.approx(h, rel=1e-9)
    assert c2.sag_m == pytest.approx(c.sag_m, rel=1e-9)


def test_catenary_inextensible_closed_form():
    # EA = inf is the classic catenary z = c (cosh(x/c) - 1), c = H / w
    span, h = 80.0, 500.0
    cat = h / W
    c = elastic_catenary(span, W, INF, horizontal_tension=h)
    assert c.unstretched_length_m == pytest.approx(2 * cat * math.sinh(span / (2 * cat)), rel=1e-14)
    assert c.sag_m == pytest.approx(cat * (math.cosh(span / (2 * cat)) - 1), rel=1e-14)
    x, z = elastic_catenary_shape(c, 41)
    np.testing.assert_allclose(z, cat * (np.cosh((x - span / 2) / cat) - np.cosh(span / (2 * cat))),
                               rtol=1e-12, atol=1e-12 * span)
    # large EA approaches the inextensible solution
    c_stiff = elastic_catenary(span, W, 1e15, horizontal_tension=h)
    assert c_stiff.unstretched_length_m == pytest.approx(c.unstretched_length_m, rel=1e-10)


def test_catenary_shallow_limit_is_parabola():
    span = 60.0
    for h in (1e4, 1e5, 1e6):
        c = elastic_catenary(span, W, INF, horizontal_tension=h)
        parabola = W * span**2 / (8 * h)
        # relative difference is (2/3)(d/l)^2 to leading order
        assert c.sag_m == pytest.approx(parabola, rel=2 * (parabola / span) ** 2)
    # the exact shallow limit holds to round-off (no cancellation in the sag)
    c = elastic_catenary(span, W, INF, horizontal_tension=1e12)
    assert c.sag_m == pytest.approx(W * span**2 / (8 * 1e12), rel=1e-12)


@pytest.mark.parametrize("ea", [EA, 5e4, INF])
def test_catenary_shape_endpoints_midpoint_and_length(ea):
    c = elastic_catenary(50.0, W, ea, unstretched_length=52.0)
    x, z = elastic_catenary_shape(c, 2001)
    assert x.shape == z.shape == (2001,)
    assert x[0] == 0.0 and z[0] == 0.0 and z[-1] == 0.0
    assert x[-1] == pytest.approx(c.span_m, rel=1e-14)
    assert x[1000] == pytest.approx(c.span_m / 2, rel=1e-14)
    assert z[1000] == pytest.approx(-c.sag_m, rel=1e-14)
    assert np.all(np.diff(x) > 0.0) and np.all(z <= 0.0)
    np.testing.assert_allclose(z, z[::-1], atol=1e-12 * c.span_m)
    # stretched length = integral of (1 + T/EA) over the unstretched length,
    # T = sqrt(H^2 + (V - w s)^2): checks the Lagrangian parameterization
    h, l0 = c.horizontal_tension_N, c.unstretched_length_m
    stretched, _ = quad(lambda s: 1 + math.hypot(h, W * (l0 / 2 - s)) / ea, 0.0, l0)
    polyline = np.sum(np.hypot(np.diff(x), np.diff(z)))
    assert polyline == pytest.approx(stretched, rel=1e-7)


def test_catenary_taut_and_unreachable_spans():
    # with finite EA any span is reachable, even beyond the unstretched length
    c = elastic_catenary(100.0, W, EA, unstretched_length=99.0)
    assert c.horizontal_tension_N > EA * 0.01
    assert elastic_catenary_span(c.horizontal_tension_N, 99.0, W, EA) == pytest.approx(100.0, rel=1e-14)
    # an inextensible cable cannot
    with pytest.raises(ValueError, match=r"span=100\.0: must be < unstretched_length=99\.0"):
        elastic_catenary(100.0, W, INF, unstretched_length=99.0)


# --------------------------------------------------------------------------
# Input validation
# --------------------------------------------------------------------------


@pytest.mark.parametrize("call, message", [
    (lambda: cantilever_tip_load(float("nan")), r"alpha=nan: must be a finite real number"),
    (lambda: cantilever_tip_load(2e4), r"alpha=20000\.0: must satisfy \|alpha\| <= 10000"),
    (lambda: cantilever_tip_load("1"), r"alpha='1': must be a finite real number"),
    (lambda: cantilever_tip_load_ode(1e3), r"alpha=1000\.0: must satisfy \|alpha\| <= 400"),
    (lambda: cantilever_tip_load_linear(INF), r"alpha=inf: must be a finite real number"),
    (lambda: rollup_tip_position(0.5, -2.0), r"length=-2\.0: must be > 0"),
    (lambda: rollup_tip_position(None, 1.0), r"moment_factor=None: must be a finite real number"),
    (lambda: taut_wire_frequencies(0.0, 1.0, 1.0, 1.0, 3), r"length=0\.0: must be > 0"),
    (lambda: taut_wire_frequencies(1.0, -1.0, 1.0, 1.0, 3), r"tension=-1\.0: must be >= 0"),
    (lambda: taut_wire_frequencies(1.0, 1.0, 0.0, 1.0, 3), r"mass_per_length=0\.0: must be > 0"),
    (lambda: taut_wire_frequencies(1.0, 1.0, 1.0, -5.0, 3), r"bending_stiffness=-5\.0: must be >= 0"),
    (lambda: taut_wire_frequencies(1.0, 0.0, 1.0, 0.0, 3), r"tension=0\.0, bending_stiffness=0\.0"),
    (lambda: taut_wire_frequencies(1.0, 1.0, 1.0, 1.0, 0), r"n_modes=0: must be an integer >= 1"),
    (lambda: taut_wire_frequencies(1.0, 1.0, 1.0, 1.0, 2.5), r"n_modes=2\.5: must be an integer >= 1"),
    (lambda: elastic_catenary_span(-1.0, 1.0, 1.0, 1.0), r"horizontal_tension=-1\.0: must be > 0"),
    (lambda: elastic_catenary_sag(1.0, 0.0, 1.0, 1.0), r"unstretched_length=0\.0: must be > 0"),
    (lambda: elastic_catenary_sag(1.0, 1.0, INF, 1.0),
     r"weight_per_length=inf: must be a positive real number"),
    (lambda: elastic_catenary_span(1.0, 1.0, 1.0, -INF),
     r"axial_stiffness=-inf: must be a positive real number or inf"),
    (lambda: elastic_catenary(-2.0, W, EA, horizontal_tension=1.0), r"span=-2\.0: must be > 0"),
    (lambda: elastic_catenary(2.0, W, EA),
     r"horizontal_tension=None, unstretched_length=None: exactly one"),
    (lambda: elastic_catenary(2.0, W, EA, horizontal_tension=1.0, unstretched_length=3.0),
     r"horizontal_tension=1\.0, unstretched_length=3\.0: exactly one"),
    (lambda: elastic_catenary(2.0, W, EA, unstretched_length=float("nan")), r"unstretched_length=nan"),
    (lambda: elastic_catenary(1e3, W, INF, horizontal_tension=1e-3),
     r"horizontal_tension=0\.001: too small"),
    (lambda: elastic_catenary_shape("cable", 5), r"c='cable': must be an ElasticCatenary"),
    (lambda: elastic_catenary_shape(elastic_catenary(2.0, W, EA, horizontal_tension=10.0), 1),
     r"n_points=1: must be an integer >= 2"),
])
def test_bad_input_raises_value_error_naming_the_parameter(call, message):
    with pytest.raises(ValueError, match=message):
        call()
