"""Constraint, force-element and rigid-body kernels against finite differences along random
trajectories (C_q, C_s, C_t and the acceleration term Q_d of seed eq. 14)."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from symcat.codegen.library import kernel_library
from symcat.codegen.multibody_kernels import interface
from symcat.symbolic.force_elements import FORCES
from symcat.symbolic.joints import CONSTRAINTS


def _np(x):
    return np.asarray(ca.densify(x)).squeeze()


def _trajectory(n, rng, with_rigid_blocks=()):
    """y(t) = y0 + y1 t + y2 t^2 with Euler parameters kept near unit length."""
    y0 = rng.uniform(-1, 1, n)
    for start in with_rigid_blocks:
        th = rng.standard_normal(4)
        y0[start + 3 : start + 7] = th / np.linalg.norm(th)
    y1 = rng.uniform(-1, 1, n)
    y2 = rng.uniform(-1, 1, n)
    return lambda t: y0 + y1 * t + y2 * t**2, lambda t: y1 + 2 * y2 * t, lambda t: 2 * y2


def _rigid_starts(name, info):
    starts = []
    parts = name.split("_")[1:]
    if parts and parts[0] == "rigid":
        starts.append(0)
    if len(parts) > 1 and parts[1] == "rigid":
        starts.append(info["n_i"])
    return starts


@pytest.mark.parametrize("name", sorted(CONSTRAINTS))
def test_constraint_derivatives_along_a_trajectory(name, rng):
    lib = kernel_library(name)
    info = interface(name)
    ny = info["n_i"] + info["n_j"] + info["n_s"]
    p = rng.uniform(-1, 1, len(info["params"]))
    if name.startswith("sliding"):
        p[0] = rng.uniform(1.0, 2.0)  # element length
    y, yd, ydd = _trajectory(ny, rng, _rigid_starts(name, info))
    t0, h = 0.3, 1e-5
    c = lambda t: _np(lib[f"{name}_c"](y(t), t, p))
    c_y, c_t = (_np(m) for m in lib[f"{name}_jac"](y(t0), t0, p))
    c_y = c_y.reshape(info["n_c"], ny)
    c_dot_fd = (c(t0 + h) - c(t0 - h)) / (2 * h)
    np.testing.assert_allclose(c_y @ yd(t0) + c_t, c_dot_fd, rtol=1e-6, atol=1e-7)
    c_ddot_fd = (c(t0 + h) - 2 * c(t0) + c(t0 - h)) / h**2
    gamma = _np(lib[f"{name}_gamma"](y(t0), yd(t0), t0, p))
    np.testing.assert_allclose(c_y @ ydd(t0) + gamma, c_ddot_fd, rtol=1e-3, atol=1e-3)
    # tighter: gamma against the time derivative of the compiled velocity expression
    cdot = lambda t: (lambda cy, ct: cy.reshape(info["n_c"], ny) @ yd(t) + ct)(*(_np(m) for m in lib[f"{name}_jac"](y(t), t, p)))
    np.testing.assert_allclose(c_y @ ydd(t0) + gamma, (cdot(t0 + h) - cdot(t0 - h)) / (2 * h), rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize("name", sorted(FORCES))
def test_force_elements_are_consistent(name, rng):
    lib = kernel_library(name)
    info = interface(name)
    ny = info["n_i"] + info["n_j"]
    p = rng.uniform(0.5, 1.5, len(info["params"]))
    y, yd, _ = _trajectory(ny, rng, _rigid_starts(name, info))
    f = lambda yy, vv, t: _np(lib[name](yy, vv, t, p))
    q = f(y(0.2), yd(0.2), 0.2)
    assert np.all(np.isfinite(q))
    jac = lib[name].jacobian()
    j = [_np(m) for m in jac(y(0.2), yd(0.2), 0.2, p, q)]
    h = 1e-6
    fd = np.column_stack([(f(y(0.2) + h * e, yd(0.2), 0.2) - f(y(0.2) - h * e, yd(0.2), 0.2)) / (2 * h) for e in np.eye(ny)])
    np.testing.assert_allclose(j[0].reshape(ny, ny), fd, rtol=1e-5, atol=1e-6 * max(1, np.abs(fd).max()))


def test_spring_power_and_tension_only():
    lib = kernel_library("springdamper_node_ground")
    names = interface("springdamper_node_ground")["params"]
    par = dict.fromkeys(names, 0.0)
    par.update(l0=1.0, k=100.0, c=2.0, tension_only=1.0)
    p = np.array([par[n] for n in names])
    f = lambda y, v: _np(lib["springdamper_node_ground"](y, v, 0.0, p))
    # stretched to l = 1.5 along x, moving outward at 0.1 m/s: F = 100 * 0.5 + 2 * 0.1 = 50.2 N
    np.testing.assert_allclose(f([1.5, 0, 0], [0.1, 0, 0]), [-50.2, 0, 0], rtol=1e-12)
    assert np.all(f([0.8, 0, 0], [0.0, 0, 0]) == 0)          # slack: no compression
    assert np.all(f([1.01, 0, 0], [-10.0, 0, 0]) == 0)       # damper cannot push
    par["tension_only"] = 0.0
    p = np.array([par[n] for n in names])
    np.testing.assert_allclose(_np(lib["springdamper_node_ground"]([0.8, 0, 0], [0, 0, 0], 0.0, p)), [20.0, 0, 0], rtol=1e-12)


def test_rigid_body_mass_and_quadratic_velocity_against_newton_euler(rng):
    """Euler-parameter Lagrange equations reproduce Euler's equations J w_dot + w x J w = T."""
    lib = kernel_library("rigid")
    jm = rng.uniform(1, 3, 3)
    p = np.r_[2.5, jm, 0.1, -0.2, 0.05]
    inertia = np.array([[p[1], p[4], p[5]], [p[4], p[2], p[6]], [p[5], p[6], p[3]]])
    th = rng.standard_normal(4)
    th /= np.linalg.norm(th)
    omega = rng.standard_normal(3)
    e0, e1, e2, e3 = th
    g_bar = np.array([[-e1, e0, e3, -e2], [-e2, -e3, e0, e1], [-e3, e2, -e1, e0]])
    th_dot = 0.5 * g_bar.T @ omega
    q = np.r_[rng.standard_normal(3), th]
    v = np.r_[rng.standard_normal(3), th_dot]
    m = _np(lib["rigid_mass"](q, p))
    qv = _np(lib["rigid_qv"](q, v, p))
    np.testing.assert_allclose(m[:3, :3], 2.5 * np.eye(3), rtol=1e-14)
    np.testing.assert_allclose(m[3:, 3:], 4 * g_bar.T @ inertia @ g_bar, rtol=1e-12, atol=1e-12)
    # Torque-free motion: with the normalization constraint, the acceleration from
    # [M theta; theta^T 0] [theta_dd; lam] = [Qv; -theta_dot.theta_dot] gives omega_dot of Euler.
    kkt = np.zeros((5, 5))
    kkt[:4, :4] = m[3:, 3:]
    kkt[:4, 4] = th
    kkt[4, :4] = th
    rhs = np.r_[qv[3:], -th_dot @ th_dot]
    th_dd = np.linalg.solve(kkt, rhs)[:4]
    omega_dot = 2 * g_bar @ th_dd  # since G_bar_dot theta_dot = 0
    np.testing.assert_allclose(inertia @ omega_dot + np.cross(omega, inertia @ omega), 0, atol=1e-10)
