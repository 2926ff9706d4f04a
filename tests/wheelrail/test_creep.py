"""Creepages and creep force laws: Kalker's table, linear theory, FASTSIM, Polach, Shen-Hedrick-Elkins."""

import csv
from importlib.resources import files

import numpy as np
import pytest
from scipy.integrate import quad

from symcat.errors import ParameterError
from symcat.wheelrail.creep import (
    SHEAR_MODULUS_STEEL_PA,
    Creepages,
    contact_creepages,
    creep_forces,
    creepages_from_slip,
    fastsim_forces,
    kalker_coefficients,
    kalker_linear_forces,
    polach_forces,
    polach_friction_coefficient,
    shen_hedrick_elkins_forces,
    wheelset_creepages,
)
from symcat.wheelrail.hertz import hertz_contact, relative_curvatures

G = SHEAR_MODULUS_STEEL_PA
N = 80e3
MU = 0.3
SHAPES = [0.3, 1.0, 3.0]  # a/b: long across, circle, long along the rolling direction


def ellipse(a_over_b, area_scale=5e-3):
    b = area_scale / np.sqrt(a_over_b)
    return a_over_b * b, b, kalker_coefficients(a_over_b)


def saturation_creepages(a, b, coeff):
    """Creepages at which the linear force of each kind alone reaches mu N."""
    xi = MU * N / abs(kalker_linear_forces(1.0, 0.0, 0.0, a, b, coeff).fx_N)
    eta = MU * N / abs(kalker_linear_forces(0.0, 1.0, 0.0, a, b, coeff).fy_N)
    phi = MU * N / abs(kalker_linear_forces(0.0, 0.0, 1.0, a, b, coeff).fy_N)
    return xi, eta, phi


# --------------------------------------------------------------------------
# Kalker's coefficients
# --------------------------------------------------------------------------


def _table():
    path = files("symcat.reference_data").joinpath("kalker_linear_coefficients.csv")
    with path.open() as handle:
        return list(csv.DictReader(line for line in handle if not line.startswith("#")))


@pytest.mark.parametrize("nu,suffix", [(0.0, "0"), (0.25, "025"), (0.5, "05")])
def test_coefficients_reproduce_table_nodes(nu, suffix):
    rows = _table()
    ratio = np.array([float(r["a_over_b"]) for r in rows])
    c = kalker_coefficients(ratio, nu)
    for name, values in zip(("C11", "C22", "C23", "C33"), c):
        expected = np.array([float(r[f"{name}_nu{suffix}"]) for r in rows])
        np.testing.assert_allclose(values, expected, rtol=1e-12, err_msg=name)


def test_coefficients_stay_between_nodes_and_are_smooth():
    rows = _table()
    nodes = np.array([float(r["a_over_b"]) for r in rows])
    for nu, suffix in ((0.0, "0"), (0.25, "025"), (0.5, "05")):
        for k, name in enumerate(("C11", "C22", "C23", "C33")):
            table = np.array([float(r[f"{name}_nu{suffix}"]) for r in rows])
            for i in range(len(nodes) - 1):
                x = np.geomspace(nodes[i], nodes[i + 1], 9)
                v = kalker_coefficients(x, nu)[k]
                lo, hi = sorted(table[i:i + 2])
                assert np.all((v >= lo - 1e-12) & (v <= hi + 1e-12)), (name, nu, nodes[i])
                if table[i + 1] != table[i]:
                    assert np.all(np.diff(v) * np.sign(table[i + 1] - table[i]) >= -1e-12)
    # C1: one-sided slopes in ln(a/b) agree at interior nodes
    h = 1e-6
    for x0 in nodes[1:-1]:
        left = (np.array(kalker_coefficients(x0, 0.3)) - np.array(kalker_coefficients(x0 * np.exp(-h), 0.3))) / h
        right = (np.array(kalker_coefficients(x0 * np.exp(h), 0.3)) - np.array(kalker_coefficients(x0, 0.3))) / h
        np.testing.assert_allclose(left, right, atol=1e-4)


def test_coefficients_in_poisson_ratio():
    c25, c30, c50 = (np.array(kalker_coefficients(1.5, nu)) for nu in (0.25, 0.3, 0.5))
    # between the neighbouring columns; C33 falls with nu at a/b > 1, the others rise
    assert np.all((c30 - c25) * (c50 - c25) > 0)
    assert np.all(np.abs(c30 - c25) < np.abs(c50 - c25))


def test_coefficient_range():
    with pytest.raises(ParameterError, match="a_over_b"):
        kalker_coefficients(12.0)
    with pytest.raises(ParameterError, match="poisson_ratio"):
        kalker_coefficients(1.0, 0.6)
    np.testing.assert_allclose(kalker_coefficients(20.0, 0.25, clamp=True), kalker_coefficients(10.0, 0.25))


# --------------------------------------------------------------------------
# Creepages
# --------------------------------------------------------------------------


def test_creepages_from_slip_components():
    t1 = np.array([1.0, 0.0, 0.0])
    n = np.array([0.0, -np.sin(0.3), np.cos(0.3)])
    t2 = np.cross(n, t1)
    c = creepages_from_slip(0.02 * t1 - 0.01 * t2 + 5.0 * n, 0.4 * n + 3.0 * t1, t1, t2, n, 20.0)
    assert c.xi_x == pytest.approx(1e-3)
    assert c.xi_y == pytest.approx(-5e-4)
    assert c.phi_per_m == pytest.approx(0.02)


def test_pure_rolling_has_no_creepage():
    v, r = 30.0, 0.46
    c = contact_creepages([v, 0, 0], [0, v / r, 0], [0, 0.75, r], [0, 0.75, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1])
    assert np.allclose(c, 0.0, atol=1e-15)


def _wheelset_3d(scale, flange=False):
    """General creepages of a rigid wheelset kept on both rails, and the linearised ones."""
    v, r0, l0 = 30.0, 0.46, 0.75
    angle = np.array([1.0 if flange else 0.05, 0.03])
    radius = r0 + scale * np.array([4e-3, -3e-3])
    y_dot, yaw, yaw_rate = scale * 0.02, scale * 1e-3, scale * 0.01
    spin = v / r0 * (1 + scale * 2e-4)
    side = np.array([1.0, -1.0])
    e_x = np.array([np.cos(yaw), np.sin(yaw), 0.0])
    e_y = np.array([-np.sin(yaw), np.cos(yaw), 0.0])
    centre = np.array([0.0, 0.0, 0.0])
    arms = [side[i] * l0 * e_y - radius[i] * np.array([0, 0, 1.0]) for i in range(2)]
    normals = [np.array([0.0, -side[i] * np.sin(angle[i]), np.cos(angle[i])]) for i in range(2)]
    t1 = np.array([1.0, 0.0, 0.0])

    def velocity(z_dot, roll_rate, i):
        omega = np.array([0, 0, yaw_rate]) + spin * e_y + roll_rate * e_x
        return np.array([v, y_dot, z_dot]) + np.cross(omega, arms[i]), omega

    # vertical velocity and roll rate that keep both wheels on the rails (v.n = 0)
    base = [velocity(0, 0, i)[0] @ normals[i] for i in range(2)]
    matrix = np.array([[(velocity(1, 0, i)[0] @ normals[i]) - base[i],
                        (velocity(0, 1, i)[0] @ normals[i]) - base[i]] for i in range(2)])
    z_dot, roll_rate = np.linalg.solve(matrix, -np.array(base))
    general = []
    for i in range(2):
        n = normals[i]
        omega = velocity(z_dot, roll_rate, i)[1]
        general.append(contact_creepages([v, y_dot, z_dot], omega, centre, centre + arms[i],
                                         t1, np.cross(n, t1), n, rolling_speed_mps=v))
    general = np.array(general).T  # (3 creepages, 2 wheels)
    linear = np.array(wheelset_creepages(v, y_dot, yaw, yaw_rate, radius, angle, l0, r0, spin_radps=spin,
                                         roll_rate_radps=roll_rate))
    return general, linear


@pytest.mark.parametrize("flange", [False, True])
def test_general_and_linearised_creepages_agree_to_second_order(flange):
    general, linear = _wheelset_3d(1.0, flange)
    small_general, small_linear = _wheelset_3d(0.1, flange)
    error = np.abs(general - linear)
    small_error = np.abs(small_general - small_linear)
    # first-order creepages are ~1e-3 (spin up to 1.8 1/m at the flange); the difference is second order
    assert np.all(error < 2e-5)
    big = error > 1e-12
    assert np.all(small_error[big] < 0.02 * error[big])


def test_wheelset_creepages_signs():
    # wheelset moved left: the left wheel rolls on a larger radius and is braked (xi_x < 0)
    c = wheelset_creepages(30.0, 0.0, 0.0, 0.0, [0.462, 0.458], [0.05, 0.05], 0.75, 0.46)
    assert c.xi_x[0] < 0 < c.xi_x[1]
    # tread spin of opposite sign on the two wheels, -sin(angle)/r0 on the left
    assert c.phi_per_m[0] == pytest.approx(-np.sin(0.05) / 0.46)
    assert c.phi_per_m[1] == pytest.approx(np.sin(0.05) / 0.46)


# --------------------------------------------------------------------------
# Linear limit
# --------------------------------------------------------------------------


@pytest.mark.parametrize("a_over_b", SHAPES)
def test_saturating_laws_tend_to_linear_theory(a_over_b):
    a, b, coeff = ellipse(a_over_b)
    xs, es, ps = saturation_creepages(a, b, coeff)
    small = 1e-4
    for creep in ((small * xs, 0, 0), (0, small * es, 0), (0, 0, small * ps),
                  (small * xs, -0.7 * small * es, 0.5 * small * ps)):
        lin = kalker_linear_forces(*creep, a, b, coeff)
        fast = fastsim_forces(*creep, N, a, b, coeff)
        pol = polach_forces(*creep, N, a, b, coeff)
        she = shen_hedrick_elkins_forces(lin, N, MU)
        scale = np.hypot(lin.fx_N, lin.fy_N)
        for law in (fast, she):
            assert abs(law.fx_N - lin.fx_N) < 2e-3 * scale
            assert abs(law.fy_N - lin.fy_N) < 2e-3 * scale
        if creep[0] == 0 or creep[2] == 0:  # Polach's spin term is Kalker's when xi_x = 0
            assert abs(pol.fx_N - lin.fx_N) < 1e-3 * scale
            assert abs(pol.fy_N - lin.fy_N) < 1e-3 * scale
    # FASTSIM's spin moment is approximate
    lin = kalker_linear_forces(0, 0, small * ps, a, b, coeff)
    fast = fastsim_forces(0, 0, small * ps, N, a, b, coeff)
    assert 0.6 < fast.mz_Nm / lin.mz_Nm < 1.0


def test_linear_law_signs_and_casadi():
    a, b, coeff = ellipse(1.5)
    f = kalker_linear_forces(1e-3, 1e-3, 0.1, a, b, coeff)
    assert f.fx_N < 0 and f.fy_N < 0
    casadi = pytest.importorskip("casadi")
    x = casadi.SX.sym("x", 3)
    expr = kalker_linear_forces(x[0], x[1], x[2], a, b, [float(c) for c in coeff])
    fun = casadi.Function("creep", [x], [casadi.vertcat(*expr)])
    np.testing.assert_allclose(np.array(fun([1e-3, 1e-3, 0.1])).ravel(), np.array(f, dtype=float), rtol=1e-14)


# --------------------------------------------------------------------------
# Saturation
# --------------------------------------------------------------------------


@pytest.mark.parametrize("a_over_b", SHAPES)
def test_forces_never_exceed_friction(a_over_b, rng):
    a, b, coeff = ellipse(a_over_b)
    xs, es, ps = saturation_creepages(a, b, coeff)
    m = 300
    scale = 10.0 ** rng.uniform(-2, 1.5, (3, m)) * rng.choice([-1, 1], (3, m))
    xi, eta, phi = scale[0] * xs, scale[1] * es, scale[2] * ps
    lin = kalker_linear_forces(xi, eta, phi, a, b, coeff)
    for law in (fastsim_forces(xi, eta, phi, N, a, b, coeff, n_strips=20, n_points=20),
                fastsim_forces(xi, eta, phi, N, a, b, coeff, n_strips=20, n_points=20, pressure="elliptic"),
                polach_forces(xi, eta, phi, N, a, b, coeff),
                shen_hedrick_elkins_forces(lin, N, MU)):
        assert np.all(np.hypot(law.fx_N, law.fy_N) <= MU * N * (1 + 1e-12))


@pytest.mark.parametrize("a_over_b", SHAPES)
def test_large_creepage_saturates_at_friction(a_over_b):
    a, b, coeff = ellipse(a_over_b)
    xs, es, _ = saturation_creepages(a, b, coeff)
    for creep in ((-100 * xs, 0, 0), (0, 100 * es, 0), (60 * xs, 80 * es, 0)):
        lin = kalker_linear_forces(*creep, a, b, coeff)
        for law in (fastsim_forces(*creep, N, a, b, coeff), polach_forces(*creep, N, a, b, coeff),
                    shen_hedrick_elkins_forces(lin, N, MU)):
            assert np.hypot(law.fx_N, law.fy_N) == pytest.approx(MU * N, rel=0.02)
    # Polach's force opposes the slip in full slip
    pol = polach_forces(60 * xs, 80 * es, 0, N, a, b, coeff)
    assert np.arctan2(-pol.fy_N, -pol.fx_N) == pytest.approx(np.arctan2(80 * es, 60 * xs), abs=0.02)


def test_zero_normal_force_gives_zero_forces():
    a, b, coeff = ellipse(1.0)
    for law in (fastsim_forces(1e-3, 1e-3, 0.1, 0.0, a, b, coeff), polach_forces(1e-3, 1e-3, 0.1, 0.0, a, b, coeff),
                polach_forces(1e-3, 1e-3, 0.1, 0.0, 0.0, 0.0, coeff)):
        assert np.allclose(np.array(law, dtype=float), 0.0)


# --------------------------------------------------------------------------
# FASTSIM against closed forms
# --------------------------------------------------------------------------


def _fastsim_continuum(xi, a, b, coeff):
    """FASTSIM without discretisation: pure longitudinal creepage, parabolic pressure.

    A strip of half-length h = a(y) carrying q(1 - x²/h²) saturates at x_s where
    the linear traction (xi/L1)(h - x) meets the bound; its force is
    mu N_strip (1 - (1 - e)^3), e = xi h / (2 L1 q) (clipped at 1).
    """
    l1 = 8 * a / (3 * G * coeff.c11)
    p0 = 2 * MU * N / (np.pi * a * b)

    def strip(y):
        h = a * np.sqrt(1 - (y / b) ** 2)
        q = p0 * (h / a) ** 2
        e = min(xi * h / (2 * l1 * q), 1.0)
        return 4 / 3 * q * h * (1 - (1 - e) ** 3)

    return -quad(strip, -b, b, limit=200, points=[0.0])[0]


@pytest.mark.parametrize("a_over_b", [0.3, 3.0])
def test_fastsim_converges_to_its_continuum_solution(a_over_b):
    a, b, coeff = ellipse(a_over_b)
    xs, _, _ = saturation_creepages(a, b, coeff)
    creep = xs * np.array([0.1, 0.5, 1.0, 2.0, 5.0])
    exact = np.array([_fastsim_continuum(x, a, b, coeff) for x in creep])
    errors = [np.max(np.abs(fastsim_forces(creep, 0, 0, N, a, b, coeff, n_strips=n, n_points=n).fx_N - exact))
              / (MU * N) for n in (10, 20, 40, 80)]
    assert errors[2] < 1e-3  # the default grid
    assert errors[3] < errors[2] < errors[1] < errors[0]
    assert errors[0] / errors[3] > 20  # about second order


@pytest.mark.parametrize("a_over_b", SHAPES)
def test_fastsim_with_hertz_pressure_is_polach_without_spin(a_over_b):
    # one flexibility and the elliptic bound give Polach's closed form exactly
    a, b, coeff = ellipse(a_over_b)
    xs, es, _ = saturation_creepages(a, b, coeff)
    u = np.array([0.05, 0.3, 1.0, 2.0, 5.0, 20.0])
    for creep, key in (((u * xs, 0, 0), "fx_N"), ((0, -u * es, 0), "fy_N")):
        fast = fastsim_forces(*creep, N, a, b, coeff, pressure="elliptic")
        pol = polach_forces(*creep, N, a, b, coeff)
        assert np.max(np.abs(getattr(fast, key) - getattr(pol, key))) < 3e-3 * MU * N


def test_fastsim_against_carter():
    """Carter's 2D law against FASTSIM with Hertz's pressure (pure longitudinal creepage).

    Both with the linear slope of Kalker's theory (u = linear force / mu N):
    Carter F/mu N = 1 - (1 - u/2)² up to u = 2 (exact 2D elasticity), FASTSIM
    (2/pi)(lam/(1 + lam²) + atan lam), lam = pi u / 4 (strip theory; this is
    independent of a/b with Hertz's pressure). They agree at small u and both
    saturate at mu N. In between the strip theory runs above Carter by up to
    0.017 mu N (u = 0.50), crosses it at u = 0.84 and then lags by up to
    0.082 mu N (u = 1.77), approaching mu N only asymptotically.
    """
    a, b, coeff = ellipse(0.3)
    xs, _, _ = saturation_creepages(a, b, coeff)
    u = np.linspace(0.01, 4.0, 60)
    fast = -fastsim_forces(u * xs, 0, 0, N, a, b, coeff, pressure="elliptic", n_strips=60, n_points=60).fx_N / (MU * N)
    carter = 1 - (1 - np.minimum(u / 2, 1)) ** 2
    gap = carter - fast
    assert gap.max() == pytest.approx(0.082, abs=0.004)
    assert gap.min() == pytest.approx(-0.017, abs=0.003)
    assert np.all(gap[u < 0.8] < 1e-3) and np.all(gap[u > 0.9] > 0)
    assert abs(gap[0]) < 1e-4 and fast[-1] > 0.97


# --------------------------------------------------------------------------
# Polach against FASTSIM
# --------------------------------------------------------------------------


@pytest.mark.parametrize("a_over_b", SHAPES)
def test_polach_against_fastsim(a_over_b):
    """Differences in units of mu N, FASTSIM with its parabolic pressure (default).

    Single creepage: 0.037 (the pressure shape); longitudinal with lateral
    creepage: up to 0.14 at a/b = 0.3 (FASTSIM's L1 != L2); pure spin up to
    twice the linear saturation: up to 0.17.
    """
    a, b, coeff = ellipse(a_over_b)
    xs, es, ps = saturation_creepages(a, b, coeff)
    u = np.array([0.05, 0.2, 0.5, 1.0, 2.0, 4.0, 10.0])
    fast = fastsim_forces(u * xs, 0, 0, N, a, b, coeff).fx_N
    assert np.max(np.abs(fast - polach_forces(u * xs, 0, 0, N, a, b, coeff).fx_N)) < 0.04 * MU * N
    ux, uy = (g.ravel() for g in np.meshgrid(u, np.concatenate([-u, u])))
    fast = fastsim_forces(ux * xs, uy * es, 0, N, a, b, coeff)
    pol = polach_forces(ux * xs, uy * es, 0, N, a, b, coeff)
    assert np.max(np.hypot(fast.fx_N - pol.fx_N, fast.fy_N - pol.fy_N)) < 0.15 * MU * N
    us = np.array([0.05, 0.2, 0.5, 1.0, 2.0])
    fast = fastsim_forces(0, 0, us * ps, N, a, b, coeff).fy_N
    assert np.max(np.abs(fast - polach_forces(0, 0, us * ps, N, a, b, coeff).fy_N)) < 0.18 * MU * N


def test_polach_reduction_factors_and_friction_law():
    a, b, coeff = ellipse(1.0)
    xs, _, _ = saturation_creepages(a, b, coeff)
    plain = polach_forces(5 * xs, 0, 0, N, a, b, coeff)
    reduced = polach_forces(5 * xs, 0, 0, N, a, b, coeff, k_adhesion=0.8, k_slip=0.4)
    assert abs(reduced.fx_N) < abs(plain.fx_N)
    mu = polach_friction_coefficient([0.0, 1.0, 1e3], 0.4, 0.4, 0.6)
    np.testing.assert_allclose(mu, [0.4, 0.4 * (0.6 * np.exp(-0.6) + 0.4), 0.16])


# --------------------------------------------------------------------------
# Dispatch and bad input
# --------------------------------------------------------------------------


def test_creep_forces_dispatch():
    A, B = relative_curvatures(0.46, 0.0, 1 / 0.3)
    contact = hertz_contact(N, A, B)
    creep = Creepages(1e-3, -5e-4, 0.1)
    coeff = kalker_coefficients(contact.a_over_b)
    args = (contact.semi_axis_a_m, contact.semi_axis_b_m, coeff)
    np.testing.assert_allclose(creep_forces(creep, contact, "linear"), kalker_linear_forces(*creep, *args))
    np.testing.assert_allclose(creep_forces(creep, contact, "polach"), polach_forces(*creep, N, *args))
    np.testing.assert_allclose(creep_forces(creep, contact, "fastsim", n_strips=10),
                               fastsim_forces(*creep, N, *args, n_strips=10))
    she = creep_forces(creep, contact, "shen_hedrick_elkins")
    assert np.hypot(she.fx_N, she.fy_N) < MU * N


@pytest.mark.parametrize(
    "call,needle",
    [
        (lambda: creepages_from_slip([0, 0, 0], [0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], 0.0), "rolling_speed_mps"),
        (lambda: creepages_from_slip([0, 0, 0], [0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, -1], 1.0), "right-handed"),
        (lambda: creepages_from_slip([0, 0, 0], [0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 1], 1.0), "t1"),
        (lambda: wheelset_creepages(-1.0, 0, 0, 0, [0.46, 0.46], [0, 0], 0.75, 0.46), "speed_mps"),
        (lambda: wheelset_creepages(30.0, 0, 0, 0, [0.46], [0, 0], 0.75, 0.46), "rolling_radius_m"),
        (lambda: polach_forces(0, 0, 0, -1.0, 1e-3, 1e-3, kalker_coefficients(1.0)), "normal_force_N"),
        (lambda: polach_forces(0, 0, 0, 1.0, 1e-3, 1e-3, kalker_coefficients(1.0), friction_coefficient=0), "friction"),
        (lambda: polach_forces(0, 0, 0, 1.0, 1e-3, 1e-3, kalker_coefficients(1.0), k_slip=1.5), "k_slip"),
        (lambda: fastsim_forces(0, 0, 0, 1.0, -1e-3, 1e-3, kalker_coefficients(1.0)), "semi-axes"),
        (lambda: fastsim_forces(0, 0, 0, 1.0, 1e-3, 1e-3, kalker_coefficients(1.0), pressure="flat"), "pressure"),
        (lambda: fastsim_forces(0, 0, 0, 1.0, 1e-3, 1e-3, kalker_coefficients(1.0), n_strips=0), "n_strips"),
        (lambda: creep_forces(Creepages(0, 0, 0), hertz_contact(N, 1.0, 2.0), "magic"), "law"),
        (lambda: polach_friction_coefficient(1.0, 0.4, 1.5, 0.6), "ratio_A"),
    ],
)
def test_bad_input(call, needle):
    with pytest.raises(ParameterError, match=needle):
        call()
