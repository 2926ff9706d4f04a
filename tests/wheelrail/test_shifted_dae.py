"""The contact driver's shifted DAE (:func:`symcat.integrate.shifted.shifted_dae`): the
state's scaled departure from its linear extrapolation, consistent at zero for every start."""
import casadi as ca
import numpy as np

from symcat.integrate.shifted import (WARP_ANCHORS, WARP_MAX, CallIntegrators, SharedDerivatives, shifted_dae,
                                      warped_grid)


def _dae():
    """A damped oscillator with an algebraic force, semi-explicit index 1, in the driver's
    signature ``(t, x, z, p, u) -> (ode, alg, quad, zero)``."""
    t, x, z, p, u = ca.MX.sym("t"), ca.MX.sym("x", 2), ca.MX.sym("z"), ca.MX.sym("p", 2), ca.MX.sym("u", 0)
    ode = ca.vertcat(x[1], -p[1] * x[0] - 0.3 * x[1] + z + ca.sin(t + p[0]))
    alg = z - 0.5 * x[0] ** 2
    return ca.Function("dae", [t, x, z, p, u], [ode, alg, ca.MX(0, 1), ca.MX(0, 1)],
                       ["t", "x", "z", "p", "u"], ["ode", "alg", "quad", "zero"])


def test_shifted_dae_starts_consistent_and_follows_the_dae():
    dae = _dae()
    x_a, p = np.array([0.4, -1.2]), np.array([0.7, 40.0])
    z_a = 0.5 * x_a[0] ** 2
    x_dot = np.asarray(dae(0.0, x_a, z_a, p, ca.DM(0, 1))[0]).ravel()
    scale = np.array([3.0, 25.0])
    shifted = shifted_dae(dae)
    p_ext = np.r_[p, x_a, x_dot, scale]
    ode0 = np.asarray(shifted(0.0, np.zeros(2), z_a, p_ext, ca.DM(0, 1))[0]).ravel()
    assert np.abs(ode0).max() == 0.0  # xi = 0, xi_dot = 0 is consistent
    grid = [0.05, 0.2, 0.5]
    opts = {"reltol": 1e-9, "abstol": 1e-10, "calc_ic": False}
    direct = ca.integrator("i", "idas", dae, 0.0, grid, {**opts, "init_xdot": x_dot.tolist()})(x0=x_a, z0=z_a, p=p)
    moved = ca.integrator("i", "idas", shifted, 0.0, grid, opts)(x0=np.zeros(2), z0=z_a, p=p_ext)
    x_moved = x_a[:, None] + np.outer(x_dot, grid) + scale[:, None] * np.asarray(moved["xf"])
    np.testing.assert_allclose(x_moved, np.asarray(direct["xf"]), rtol=0, atol=1e-7)
    np.testing.assert_allclose(np.asarray(moved["zf"]), np.asarray(direct["zf"]), rtol=0, atol=1e-7)
    # A wrong start derivative (zero, as IDAS assumes without one) is not consistent.
    wrong = np.asarray(shifted(0.0, np.zeros(2), z_a, np.r_[p, x_a, 0 * x_dot, scale], ca.DM(0, 1))[0]).ravel()
    assert np.abs(wrong).max() > 1e-3


def test_one_normalized_integrator_serves_calls_of_every_length():
    """In normalized time the integrator depends on the output fractions and the first-step level
    only: calls of 0.1 s and 0.4 s share it, and each matches an integration in seconds. A step
    limit in seconds is converted to units of each call (so the integrators then differ)."""
    dae = _dae()
    x_a, p = np.array([0.4, -1.2]), np.array([0.7, 40.0])
    z_a = 0.5 * x_a[0] ** 2
    x_dot = np.asarray(dae(0.0, x_a, z_a, p, ca.DM(0, 1))[0]).ravel()
    scale = np.array([3.0, 25.0])
    opts = {"reltol": 1e-9, "abstol": 1e-10, "calc_ic": False, "suppress_algebraic": True}  # as the driver
    calls = CallIntegrators(dae, opts)
    short, long = (calls.get([0.5, 1.0], "csparse", True, True, 3, h) for h in (0.1, 0.4))
    assert short is long
    for h in (0.1, 0.4):
        out = short(x0=np.zeros(2), z0=z_a, p=np.r_[p, x_a, x_dot, scale, h, 0.0])
        x_end = x_a + h * x_dot + scale * np.asarray(out["xf"])[:, -1]
        direct = ca.integrator("i", "idas", dae, 0.0, [h], {**opts, "init_xdot": x_dot.tolist()})(x0=x_a, z0=z_a, p=p)
        np.testing.assert_allclose(x_end, np.asarray(direct["xf"]).ravel(), rtol=0, atol=1e-7)
    limited = CallIntegrators(dae, {**opts, "max_step_size": 0.01})
    a, b = (limited.get([1.0], "csparse", True, True, 3, h) for h in (0.1, 0.4))
    assert a is not b
    assert limited.get([1.0], "csparse", True, True, 3, 0.1) is a


def test_a_warped_call_puts_its_output_on_a_cached_grid_and_matches_the_plain_one():
    """One output inside a call, at any fraction between 2 % and 98 %, lies on one of the warped
    grids (``w(g) = fraction`` exactly, time monotonic); the warped integration gives the same
    states at the output and the end as the plain one, and the same integrator serves two
    fractions near one grid point."""
    for fraction in np.linspace(0.02, 0.98, 97):
        (g, end), a = warped_grid(fraction)
        assert end == 1.0 and g in WARP_ANCHORS and abs(a) <= WARP_MAX
        assert abs(g + a * g * (1 - g) - fraction) < 1e-15
    assert warped_grid(0.001) == ([0.001, 1.0], 0.0)  # beyond the anchors: exact, unwarped
    dae = _dae()
    x_a, p = np.array([0.4, -1.2]), np.array([0.7, 40.0])
    z_a = 0.5 * x_a[0] ** 2
    x_dot = np.asarray(dae(0.0, x_a, z_a, p, ca.DM(0, 1))[0]).ravel()
    scale = np.array([3.0, 25.0])
    opts = {"reltol": 1e-9, "abstol": 1e-10, "calc_ic": False, "suppress_algebraic": True}
    calls = CallIntegrators(dae, opts)
    h = 0.3
    used = set()
    for fraction in (0.41, 0.58):
        grid, a = warped_grid(fraction)
        assert a != 0.0
        warped = calls.get(grid, "csparse", True, True, 3, h)
        used.add(id(warped))
        out = np.asarray(warped(x0=np.zeros(2), z0=z_a, p=np.r_[p, x_a, x_dot, scale, h, a])["xf"])
        times = np.array([fraction * h, h])
        x_warped = x_a[:, None] + np.outer(x_dot, times) + scale[:, None] * out
        direct = ca.integrator("i", "idas", dae, 0.0, times.tolist(), {**opts, "init_xdot": x_dot.tolist()})
        np.testing.assert_allclose(x_warped, np.asarray(direct(x0=x_a, z0=z_a, p=p)["xf"]), rtol=0, atol=1e-7)
    assert len(used) == 1


def test_integrators_share_the_derived_functions_and_integrate_as_the_dae_itself():
    """Integrators built on :class:`SharedDerivatives` take the residual and Jacobian functions
    derived for the first one (none derived again, however many grids) and give bit-identical
    states to integrators on the DAE itself; the wrapper evaluates as the DAE."""
    dae = _dae()
    x_a, p = np.array([0.4, -1.2]), np.array([0.7, 40.0])
    z_a = 0.5 * x_a[0] ** 2
    x_dot = np.asarray(dae(0.0, x_a, z_a, p, ca.DM(0, 1))[0]).ravel()
    shared = SharedDerivatives(dae)
    opts = {"reltol": 1e-8, "abstol": 1e-10, "calc_ic": False, "init_xdot": x_dot.tolist()}
    for n, grid in enumerate(([0.1, 0.5], [0.2, 0.3, 0.5], [0.5])):
        own = ca.integrator("i", "idas", dae, 0.0, grid, opts)(x0=x_a, z0=z_a, p=p)
        via = ca.integrator("i", "idas", shared, 0.0, grid, opts)(x0=x_a, z0=z_a, p=p)
        assert np.array_equal(np.asarray(via["xf"]), np.asarray(own["xf"]))
        assert np.array_equal(np.asarray(via["zf"]), np.asarray(own["zf"]))
        if n == 0:
            derived = dict(shared.derived)
            assert {key[0] for key in derived} >= {"daeF", "jacF"}
    assert shared.derived == derived  # the later integrators derived nothing
    args = (0.3, x_a, z_a, p, ca.DM(0, 1))
    for a, b in zip(shared(*args), dae(*args)):
        assert np.array_equal(np.asarray(a), np.asarray(b))
