"""The sliding joint: a bead on a fixed curved wire, augmented vs embedded, a mass on a taut
flexible wire, and element crossings."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from symcat.assembly.multibody import MultibodyModel
from symcat.integrate import simulate
from symcat.model import run_model
from symcat.scene import AncfBody, Material, RigidBody, Scene, Section, SlidingJoint

G = 9.81


def bead_on_circle(n_elements, element="cable3d", radius=1.0, phi0=0.6):
    """A bead on a fixed semicircular wire (vertical plane xz): the wire's nodes are on the
    circle with unit tangent slopes, all clamped; the bead slides without friction."""
    phi = np.linspace(-np.pi / 2, np.pi / 2, n_elements + 1)
    pos = np.column_stack([radius * np.sin(phi), 0 * phi, radius * (1 - np.cos(phi))])
    tan = np.column_stack([np.cos(phi), 0 * phi, np.sin(phi)])
    nodes = np.hstack([pos, tan])
    if element == "beam3d":
        normal = np.column_stack([-np.sin(phi), 0 * phi, np.cos(phi)])
        nodes = np.hstack([pos, tan, np.tile([0, 1.0, 0], (len(phi), 1)), normal])
    wire = AncfBody.from_nodes("wire", element, nodes, radius * (phi[1] - phi[0]), Material(1e9, 1000), Section.circle(0.01))
    for k in range(n_elements + 1):
        wire.clamp(k)
    scene = Scene(gravity=(0, 0, -G))
    scene.add(wire)
    scene.add(RigidBody("bead", 0.2, (1e-3, 1e-3, 1e-3), (radius * np.sin(phi0), 0, radius * (1 - np.cos(phi0)))))
    scene.add(SlidingJoint("joint", "wire", "bead", s0=radius * (phi0 + np.pi / 2)))
    return MultibodyModel(scene)


@pytest.mark.parametrize("formulation", ["augmented", "embedded"])
@pytest.mark.parametrize("index", ["1", "ggl"])
def test_bead_on_a_fixed_circular_wire(formulation, index):
    """Against phi'' = -(g/R) sin(phi): the error is that of the cubic circle (O(h^4))."""
    errors = []
    for n in (8, 16):
        res = simulate(bead_on_circle(n), 2.0, formulation, index, rtol=1e-9, atol=1e-11, n_out=50, progress=False)
        ref = solve_ivp(lambda t, y: [y[1], -G * np.sin(y[0])], (0, 2), [0.6, 0], t_eval=res.t_s, rtol=1e-12, atol=1e-12)
        errors.append(np.abs(res.s_m[:, 0] - np.pi / 2 - ref.y[0]).max())
        normal_force = 0.2 * (G * np.cos(ref.y[0]) + ref.y[1] ** 2)
        force_err = np.abs(np.linalg.norm(res.reactions_N["joint"], axis=1) - normal_force).max()
    assert errors[-1] < 3e-5
    assert errors[0] / errors[1] > 8          # about 4th order in the wire mesh
    assert force_err < 5e-3 * 0.2 * G * 2
    assert res.position_drift.max() < 1e-7


def test_bead_on_a_beam3d_wire_uses_its_own_frame():
    res = simulate(bead_on_circle(16, "beam3d"), 1.0, "augmented", "1", rtol=1e-10, atol=1e-12, n_out=20, progress=False)
    ref = solve_ivp(lambda t, y: [y[1], -G * np.sin(y[0])], (0, 1), [0.6, 0], t_eval=res.t_s, rtol=1e-12, atol=1e-12)
    assert np.abs(res.s_m[:, 0] - np.pi / 2 - ref.y[0]).max() < 3e-5


@pytest.mark.parametrize("index", ["1", "ggl"])
def test_augmented_and_embedded_give_the_same_motion(index):
    # GGL (index 2) cannot converge IDAS's Newton iteration below rtol ~ 1e-8 (conditioning ~ 1/h^2).
    common = {"t_end": 0.2, "rtol": 1e-9 if index == "1" else 1e-8, "index": index, "n_elements": 6}
    a = run_model("slider_on_wire", {**common, "formulation": "augmented"}).arrays["result"]
    e = run_model("slider_on_wire", {**common, "formulation": "embedded"}).arrays["result"]
    np.testing.assert_allclose(a.s_m, e.s_m, atol=2e-7)
    np.testing.assert_allclose(a.q, e.q, atol=2e-7)
    fa, fe = a.reactions_N["slider"], e.reactions_N["slider"]
    assert np.abs(fa - fe).max() < 1e-3 * np.abs(fa).max()


def ring(n_elements, window, arc_deg=350.0, radius=1.0, speed=5.0, mass=0.3):
    """A fixed horizontal circular wire (no gravity) and a bead launched along it."""
    phi = np.radians(np.linspace(0.0, arc_deg, n_elements + 1))
    nodes = np.column_stack([radius * np.cos(phi), radius * np.sin(phi), 0 * phi, -np.sin(phi), np.cos(phi), 0 * phi])
    wire = AncfBody.from_nodes("ring", "cable3d", nodes, radius * (phi[1] - phi[0]), Material(1e9, 1000), Section.circle(0.01))
    for k in range(n_elements + 1):
        wire.clamp(k)
    scene = Scene()
    scene.add(wire)
    phi0 = phi[1] * 0.5
    scene.add(RigidBody("bead", mass, (1e-4, 1e-4, 1e-4), (radius * np.cos(phi0), radius * np.sin(phi0), 0.0),
                        velocity=(-speed * np.sin(phi0), speed * np.cos(phi0), 0.0)))
    scene.add(SlidingJoint("joint", "ring", "bead", s0=radius * phi0, reference_direction=(0, 0, 1)))
    return MultibodyModel(scene, window=window)


def test_sliding_across_a_hundred_element_ends_is_smooth():
    """The bead crosses 110 element ends of a fixed ring at 5 m/s: speed and normal force
    (m v^2 / R) stay constant, s(t) is a straight line, and a run that moves its element
    window (restarting IDAS) matches a run without restarts."""
    t_end = 1.05
    moving = simulate(ring(128, window=12), t_end, rtol=1e-9, atol=1e-11, n_out=210, progress=False)
    fixed_window = simulate(ring(128, window=128), t_end, rtol=1e-9, atol=1e-11, n_out=210, progress=False)
    s = moving.s_m[:, 0]
    crossed = int(s[-1] // (np.radians(350.0) / 128)) - int(s[0] // (np.radians(350.0) / 128))
    assert crossed >= 100
    assert moving.stats["restarts"] >= 5 and fixed_window.stats["restarts"] == 0
    np.testing.assert_allclose(s, s[0] + 5.0 * moving.t_s, atol=2e-5)               # no jumps in s
    np.testing.assert_allclose(moving.s_dot_m_s[:, 0], 5.0, rtol=5e-6)             # nor in its rate
    force = np.linalg.norm(moving.reactions_N["joint"], axis=1)
    np.testing.assert_allclose(force, 0.3 * 25.0 / 1.0, rtol=2e-3)                  # nor in the force
    assert np.abs(np.diff(force)).max() < 5e-3 * force.mean()
    np.testing.assert_allclose(moving.s_m, fixed_window.s_m, atol=1e-5)  # both within the integration error
    np.testing.assert_allclose(moving.reactions_N["joint"], fixed_window.reactions_N["joint"], atol=1e-4 * force.mean())


def test_cholesky_coordinates_give_the_same_motion():
    common = {"t_end": 0.2, "rtol": 1e-8, "n_elements": 6}
    a = run_model("slider_on_wire", common).arrays["result"]
    c = run_model("slider_on_wire", {**common, "cholesky": True}).arrays["result"]
    np.testing.assert_allclose(c.s_m, a.s_m, atol=1e-7)
    np.testing.assert_allclose(c.q, a.q, atol=1e-7)
    assert np.abs(c.reactions_N["slider"] - a.reactions_N["slider"]).max() < 1e-3 * np.abs(a.reactions_N["slider"]).max()


def _modal_moving_mass(length, tension, ei, mu, mass, s0, t_eval, n_modes=20):
    """Independent reference: a pinned tensioned beam-string in its sine modes (small slopes)
    with a mass sliding on it without friction, Lagrange's equations in (q_1..q_K, s) by
    CasADi AD and scipy's DOP853. Both start straight and at rest."""
    import casadi as ca

    q, s = ca.SX.sym("q", n_modes), ca.SX.sym("s")
    q_dot, s_dot = ca.SX.sym("qd", n_modes), ca.SX.sym("sd")
    k = np.arange(1, n_modes + 1) * np.pi / length
    phi = ca.sin(k * s)
    z = ca.dot(q, phi)
    z_dot = ca.dot(q_dot, phi) + s_dot * ca.dot(q, k * ca.cos(k * s))
    omega2 = k**2 * (tension + ei * k**2) / mu
    kinetic = mu * length / 4 * ca.sumsqr(q_dot) + mass / 2 * (s_dot**2 + z_dot**2)
    weight = mu * G * (1 - np.cos(np.arange(1, n_modes + 1) * np.pi)) / k  # the wire's own weight
    potential = mu * length / 4 * ca.dot(omega2 * q, q) + mass * G * z + ca.dot(q, weight)
    lag = kinetic - potential
    y, y_dot = ca.vertcat(q, s), ca.vertcat(q_dot, s_dot)
    p = ca.gradient(lag, y_dot)
    acc = ca.Function("acc", [y, y_dot], [ca.solve(ca.jacobian(p, y_dot), ca.gradient(lag, y) - ca.mtimes(ca.jacobian(p, y), y_dot))])
    n = n_modes + 1
    sol = solve_ivp(lambda t, Y: np.r_[Y[n:], np.asarray(acc(Y[:n], Y[n:])).ravel()], (0, t_eval[-1]),
                    np.r_[np.zeros(n_modes), s0, np.zeros(n)], t_eval=t_eval, rtol=1e-10, atol=1e-12, method="DOP853")
    s_ref = sol.y[n_modes]
    z_ref = np.array([sol.y[:n_modes, i] @ np.sin(k * s_ref[i]) for i in range(len(s_ref))])
    return s_ref, z_ref


def test_mass_sliding_on_a_taut_flexible_wire_against_a_modal_model():
    """A 0.1 kg mass released on a 2 m, 200 N wire of 0.2 kg (EI = 1 N m^2) slides and bounces;
    the ANCF model meets the modal moving-mass reference to ~1 % of the motion, closer on a
    finer mesh."""
    length, tension, ea, ei, mu, mass, s0 = 2.0, 200.0, 1e4, 1.0, 0.1, 0.1, 0.5
    errors = []
    for n in (8, 16):
        section = Section.from_stiffness(ea, ei, 1e11)
        prestrain = tension / ea
        wire = AncfBody.straight("wire", "cable3d", [0, 0, 0], [length, 0, 0], n,
                                 Material(1e11, mu * (1 + prestrain) / section.A), section, prestrain=prestrain)
        wire.pin(0).pin(-1)
        scene = Scene(gravity=(0, 0, -G))
        scene.add(wire)
        scene.add(RigidBody("bead", mass, (1e-5, 1e-5, 1e-5), (s0, 0, 0)))
        scene.add(SlidingJoint("joint", "wire", "bead", s0=s0))
        res = simulate(MultibodyModel(scene), 0.6, rtol=1e-6, atol=1e-8, n_out=30, progress=False)
        if n == 8:
            s_ref, z_ref = _modal_moving_mass(length, tension, ei, mu, mass, s0, res.t_s)
        errors.append((np.abs(res.s_m[:, 0] - s_ref).max(), np.abs(res.coordinate("bead.z") - z_ref).max()))
    travel, amplitude = s_ref[-1] - s0, np.abs(z_ref).max()   # 10 mm and 7 mm
    assert errors[0][0] < 0.01 * travel and errors[0][1] < 0.025 * amplitude
    assert errors[1][0] < errors[0][0] and errors[1][1] < errors[0][1]


def test_windows_move_only_on_wires_longer_than_the_window():
    from symcat.model import load_model

    slider = load_model("slider_on_wire")
    scene = slider.run.__globals__["build"](slider.resolve({"n_elements": 12}))
    assert MultibodyModel(scene, window=8).windows_move()
    assert not MultibodyModel(scene, window=12).windows_move()
