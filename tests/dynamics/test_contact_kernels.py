"""Penalty wire-contact kernels (seed Section 8) against an independent numerical evaluation
of the same geometry and against finite differences."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from symcat.catalog import element_type
from symcat.codegen.library import kernel_library
from symcat.codegen.multibody_kernels import interface
from symcat.scene import AncfBody, Material, Section
from symcat.scene.rigid import rotation_matrix
from symcat.scene.sections import element_parameters

L = 1.3


def _np(x):
    return np.asarray(ca.densify(x)).ravel()


def _setup(element, rng, penetration=1e-3, k=5e4, c=80.0, delta=1e-5):
    """A gently bent element, a rigid body whose point u_j sits ``penetration`` above (along k_t)
    the wire point at s0, so the tangency condition holds at s0."""
    etype = element_type(element)
    elp = element_parameters(etype, [L], Material(1e9, 1000), Section.circle(0.01))[0]
    e = AncfBody.straight("w", element, [0, 0, 0], [L, 0, 0], 1, Material(1e9, 1000), Section.circle(0.01)).q0.ravel()
    e = e + 0.03 * rng.standard_normal(e.size)
    s0 = 0.4 * L
    pos = kernel_library(element)[f"{element}_position"]

    def frame(e, s):
        r, r_x = (_np(x) for x in pos(e, s / L, elp))
        ref = np.array([0, 1.0, 0]) if element == "cable3d" else (1 - s / L) * e[6:9] + s / L * e[18:21]
        i_t = r_x / np.linalg.norm(r_x)
        k_t = np.cross(i_t, ref)
        return r, i_t, k_t / np.linalg.norm(k_t)

    r, i_t, k_t = frame(e, s0)
    th = rng.standard_normal(4)
    th /= np.linalg.norm(th)
    u = rng.uniform(-0.2, 0.2, 3)
    point = r + penetration * k_t
    x_j = np.r_[point - rotation_matrix(th) @ u, th]
    name = f"contact_{element}_rigid"
    values = {"L": L, "d_ref_0": 0.0, "d_ref_1": 1.0, "d_ref_2": 0.0, "uj_0": u[0], "uj_1": u[1], "uj_2": u[2],
              "k": k, "c": c, "delta": delta}
    p = np.array([values[n] for n in interface(name)["params"]])
    return name, e, x_j, s0, p, frame, u


@pytest.mark.parametrize("element", ["cable3d", "beam3d"])
def test_tangency_and_gap_against_numerical_geometry(element, rng):
    name, e, x_j, s0, p, frame, u = _setup(element, rng)
    lib = kernel_library(name)
    for s in (s0, 0.1 * L, 0.9 * L):
        y = np.r_[e, x_j, s]
        r, i_t, k_t = frame(e, s)
        d = r - (x_j[:3] + rotation_matrix(x_j[3:]) @ u)
        assert float(lib[f"{name}_tangency"](y, p)) == pytest.approx(i_t @ d, abs=1e-13)
        _, gap, _ = lib[f"{name}_force"](y, np.zeros(y.size - 1), p)
        assert float(gap) == pytest.approx(k_t @ d, abs=1e-13)
    assert float(lib[f"{name}_tangency"](np.r_[e, x_j, s0], p)) == pytest.approx(0, abs=1e-13)


@pytest.mark.parametrize("element", ["cable3d", "beam3d"])
def test_force_is_the_penalty_law_along_the_normal_at_the_contact_points(element, rng):
    name, e, x_j, s0, p, frame, u = _setup(element, rng, penetration=2e-3, c=0.0)
    lib = kernel_library(name)
    y = np.r_[e, x_j, s0]
    q, gap, f = (_np(x) for x in lib[f"{name}_force"](y, np.zeros(y.size - 1), p))
    assert gap[0] == pytest.approx(-2e-3, rel=1e-9)
    assert f[0] == pytest.approx(5e4 * (2e-3 - 1e-5), rel=1e-9)  # k (pen - delta)
    _, _, n = frame(e, s0)
    # Virtual work of +f n at the wire point and -f n at the body point (n held fixed), by FD.
    h = 1e-7
    work = lambda yy: n @ (frame(yy[: e.size], s0)[0] - yy[e.size : e.size + 3]
                           - rotation_matrix(yy[e.size + 3 : e.size + 7]) @ u)
    fd = np.array([(work(y + h * v) - work(y - h * v)) / (2 * h) for v in np.eye(y.size)[:-1]])
    np.testing.assert_allclose(q, f[0] * fd, rtol=1e-6, atol=1e-6)
    # Separated by 1 mm: no force at all.
    name, e, x_j, s0, p, frame, u = _setup(element, rng, penetration=-1e-3)
    _, _, f = lib[f"{name}_force"](np.r_[e, x_j, s0], np.zeros(e.size + 7), p)
    assert float(f) == 0


@pytest.mark.parametrize("element", ["cable3d", "beam3d"])
def test_damping_uses_the_penetration_rate_with_s_from_the_tangency(element, rng):
    """f(c) - f(0) = c pen_dot in contact, with pen_dot by finite differences of the gap along a
    trajectory on which s is re-solved from the tangency condition at every time."""
    name, e, x_j, s0, p, frame, u = _setup(element, rng, penetration=3e-3, c=80.0)
    lib = kernel_library(name)
    p0 = p.copy()
    p0[list(interface(name)["params"]).index("c")] = 0.0
    y_dot = 0.05 * rng.standard_normal(e.size + 7)
    tang, tang_jac = lib[f"{name}_tangency"], lib[f"{name}_tangency"].jacobian()

    def gap_at(t):
        y = np.r_[e, x_j, s0] + t * np.r_[y_dot, 0.0]
        for _ in range(20):  # Newton on T(y, s) = 0 for s
            slope = _np(tang_jac(y, p, tang(y, p))[0])[-1]
            y[-1] -= float(tang(y, p)) / slope
        return float(lib[f"{name}_force"](y, y_dot, p)[1])

    h = 1e-5
    pen_dot = -(gap_at(h) - gap_at(-h)) / (2 * h)
    y = np.r_[e, x_j, s0]
    f_c = float(lib[f"{name}_force"](y, y_dot, p)[2])
    f_0 = float(lib[f"{name}_force"](y, y_dot, p0)[2])
    assert f_c - f_0 == pytest.approx(80.0 * pen_dot, rel=1e-6, abs=1e-8)


@pytest.mark.parametrize("element", ["cable3d", "beam3d"])
def test_compiled_jacobians_against_finite_differences(element, rng):
    """The jac_ companions (which IDAS and the equilibrium solver use) against central
    differences, in and out of contact, near the smoothed transition."""
    for penetration in (2e-3, 5e-6, -5e-6):
        name, e, x_j, s0, p, frame, u = _setup(element, rng, penetration=penetration, delta=1e-5)
        lib = kernel_library(name)
        force = lib[f"{name}_force"]
        y = np.r_[e, x_j, s0 + 0.01]
        y_dot = 0.02 * rng.standard_normal(y.size - 1)
        out = force(y, y_dot, p)
        jac = force.jacobian()
        res = jac(y, y_dot, p, *out)
        names = jac.name_out()
        for k, (var, base, n_var) in enumerate((("y", y, y.size), ("y_dot", y_dot, y_dot.size))):
            analytic = np.vstack([np.asarray(ca.densify(res[names.index(f"jac_{o}_{var}")])) for o in ("q", "gap", "f")])
            h = 1e-8
            cols = []
            for v in np.eye(n_var):
                args = [y, y_dot]
                plus = [a.copy() for a in args]
                minus = [a.copy() for a in args]
                plus[k] = plus[k] + h * v
                minus[k] = minus[k] - h * v
                fp = np.concatenate([_np(x) for x in force(*plus, p)])
                fm = np.concatenate([_np(x) for x in force(*minus, p)])
                cols.append((fp - fm) / (2 * h))
            fd = np.column_stack(cols)
            np.testing.assert_allclose(analytic, fd, rtol=1e-4, atol=1e-5 * max(1.0, np.abs(fd).max()))
        t_jac = _np(lib[f"{name}_tangency"].jacobian()(y, p, lib[f"{name}_tangency"](y, p))[0])
        t_fd = [(float(lib[f"{name}_tangency"](y + 1e-7 * v, p)) - float(lib[f"{name}_tangency"](y - 1e-7 * v, p))) / 2e-7
                for v in np.eye(y.size)]
        np.testing.assert_allclose(t_jac, t_fd, rtol=1e-6, atol=1e-8)
