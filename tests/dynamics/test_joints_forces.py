"""Joints and force elements in motion against closed forms, and bad input."""
from __future__ import annotations

import numpy as np
import pytest

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError, SolverError
from symcat.integrate import simulate
from symcat.scene import (AncfBody, Bushing, Driving, Fixed, Material, PointLoad, Prismatic, Revolute, RigidBody,
                          RotationalSpring, Scene, Section, SlidingJoint, Spherical, SpringDamper)


def _run(scene, t_end, **kw):
    return simulate(MultibodyModel(scene), t_end, rtol=1e-9, atol=1e-11, n_out=40, progress=False, **kw)


def test_mass_on_a_prismatic_joint_with_a_spring_is_a_harmonic_oscillator():
    scene = Scene(gravity=(0, 0, -9.81))
    scene.add(RigidBody("cart", 2.0, (0.1, 0.2, 0.3), (0.1, 0, 0), velocity=(0.5, 0, 0)))
    scene.add(Prismatic("rail", "cart", "ground", at=(0.1, 0, 0), axis=(1, 0, 0)))
    scene.add(SpringDamper("spring", "cart", "ground", at_i=(0.1, 0, 0), at_j=(-1.0, 0, 0), stiffness=50.0, free_length=1.1))
    res = _run(scene, 1.0)
    omega = np.sqrt(50.0 / 2.0)
    x = res.coordinate("cart.x")
    np.testing.assert_allclose(x, 0.1 + 0.5 / omega * np.sin(omega * res.t_s), atol=1e-7)
    # The rail carries the weight: the reaction is reported on the joint's body j, here the
    # ground, which the cart pushes down with m g.
    np.testing.assert_allclose(res.reactions_N["rail"][:, 2], -2.0 * 9.81, rtol=1e-7)


@pytest.mark.parametrize("index", ["1", "ggl"])
def test_torsion_pendulum_on_a_revolute_joint(index):
    scene = Scene()
    scene.add(RigidBody("disc", 1.0, (0.5, 0.5, 0.02), (0, 0, 0), angular_velocity=(0, 0, 0.3)))
    scene.add(Revolute("axle", "disc", "ground", at=(0, 0, 0), axis=(0, 0, 1)))
    scene.add(RotationalSpring("torsion", "disc", "ground", axis=(0, 0, 1), stiffness=0.08))
    res = simulate(MultibodyModel(scene), 2.0, index=index, rtol=1e-9 if index == "1" else 1e-8, atol=1e-11, n_out=40, progress=False)
    omega = np.sqrt(0.08 / 0.02)
    e0, e3 = res.coordinate("disc.e0"), res.coordinate("disc.e3")
    angle = 2 * np.arctan2(e3, e0)
    np.testing.assert_allclose(angle, 0.3 / omega * np.sin(omega * res.t_s), atol=1e-6)


def test_time_dependent_point_load_on_a_free_body():
    scene = Scene()
    scene.add(RigidBody("block", 3.0, (0.1, 0.1, 0.1), (0, 0, 0)))
    scene.add(PointLoad("shaker", "block", force=(6.0, 0, 0), force_amplitude=(0, 3.0, 0), frequency=2.0))
    res = _run(scene, 1.0)
    w = 2 * np.pi * 2.0
    t = res.t_s
    np.testing.assert_allclose(res.coordinate("block.x"), 0.5 * 2.0 * t**2, atol=1e-8)
    np.testing.assert_allclose(res.coordinate("block.y"), 1.0 / w * (t - np.sin(w * t) / w), atol=1e-8)


def test_driving_constraint_and_fixed_joint():
    scene = Scene(gravity=(0, 0, -9.81))
    scene.add(RigidBody("a", 1.0, (0.1, 0.1, 0.1), (0, 0, 0)))
    scene.add(RigidBody("b", 1.0, (0.1, 0.1, 0.1), (0.5, 0, 0)))
    scene.add(Prismatic("rail", "a", "ground", at=(0, 0, 0), axis=(1, 0, 0)))
    scene.add(Driving("drive", "a", direction=(1, 0, 0), velocity=2.0, amplitude=0.1, frequency=1.0))
    scene.add(Fixed("weld", "b", "a", at=(0.5, 0, 0)))
    res = _run(scene, 1.0)
    t = res.t_s
    expected = 2.0 * t + 0.1 * np.sin(2 * np.pi * t)
    np.testing.assert_allclose(res.coordinate("a.x"), expected, atol=1e-9)
    np.testing.assert_allclose(res.coordinate("b.x"), 0.5 + expected, atol=1e-9)
    np.testing.assert_allclose(res.coordinate("b.z"), 0.0, atol=1e-9)


def test_ancf_node_attached_to_a_rigid_body_by_a_spherical_joint():
    """A rigid weight hung on the end node of a cable: released with the cable unstretched, it
    bounces on the rope's axial stiffness; over whole periods the hook carries its weight."""
    wire = AncfBody.straight("rope", "cable3d", [0, 0, 0], [0, 0, -1.0], 4, Material(1e9, 1000), Section.circle(0.005))
    wire.pin(0)
    scene = Scene(gravity=(0, 0, -9.81))
    scene.add(wire)
    scene.add(RigidBody("weight", 5.0, (0.01, 0.01, 0.01), (0, 0, -1.0)))
    scene.add(Spherical("hook", ("rope", -1), "weight", at=(0, 0, -1.0)))
    res = _run(scene, 0.4)
    force = res.reactions_N["hook"][:, 2]  # on the weight, upward
    assert force.min() > -1.0 and force.max() == pytest.approx(2 * 5.0 * 9.81, rel=0.05)
    assert np.mean(force) == pytest.approx(5.0 * 9.81, rel=0.08)
    assert abs(res.coordinate("weight.x")).max() < 1e-9


# --- bad input ---------------------------------------------------------------------------------
def test_joint_on_a_missing_body_names_it():
    scene = Scene()
    scene.add(RigidBody("a", 1.0, (1, 1, 1)))
    with pytest.raises(ParameterError, match="body='b': no such body"):
        scene.add(Revolute("hinge", "a", "b", at=(0, 0, 0)))


def test_sliding_joint_on_a_rigid_body_is_refused():
    scene = Scene()
    scene.add(RigidBody("a", 1.0, (1, 1, 1)))
    scene.add(RigidBody("b", 1.0, (1, 1, 1)))
    with pytest.raises(ParameterError, match="wire='a' is not an ANCF body"):
        scene.add(SlidingJoint("slide", "a", "b", s0=0.0))


def test_redundant_constraints_name_the_joints():
    scene = Scene()
    scene.add(RigidBody("a", 1.0, (1, 1, 1), (1, 0, 0)))
    scene.add(Revolute("hinge", "a", "ground", at=(0, 0, 0)))
    scene.add(Spherical("ball", "a", "ground", at=(0, 0, 0)))  # repeats the hinge's point constraint
    with pytest.raises(SolverError, match="redundant or inconsistent constraints.*(ball|hinge)"):
        _run(scene, 0.1)


def test_idas_failure_reports_time_reason_residual_and_keeps_partial_results():
    """A rod hinged at the origin whose tip is driven sideways at 1 m/s locks when the tip
    reaches x = length (t = 1 s): IDAS fails there, and the run up to then is kept."""
    scene = Scene()
    scene.add(RigidBody("rod", 1.0, (0.1, 0.1, 0.1), (0, 0, -0.5), rotation=np.eye(3)))
    scene.add(Revolute("hinge", "rod", "ground", at=(0, 0, 0), axis=(0, 1, 0)))
    scene.add(Driving("push", "rod", direction=(1, 0, 0), at=(0, 0, -1.0), velocity=1.0))
    with pytest.raises(SolverError) as info:
        simulate(MultibodyModel(scene), 2.0, rtol=1e-8, atol=1e-10, n_out=40, chunks=20, progress=False)
    message = str(info.value)
    assert "IDAS failed in the step after t = 0.9 s" in message and "IDA_CONV_FAIL" in message and "Largest algebraic residual" in message
    assert any(name in message for name in ("rod", "push", "hinge"))  # a residual named by body or joint
    partial = info.value.partial
    assert 0.8 <= partial.t_s[-1] <= 1.0 and len(partial.t_s) == partial.q.shape[0]
    tip_x = partial.coordinate("rod.x") * 2  # centre at half the tip's sideways position
    np.testing.assert_allclose(tip_x, partial.t_s, atol=1e-6)


def _rotation_about(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def test_bushing_in_rotated_axes_is_three_independent_oscillators():
    """A free block on a bushing to the ground, with axes turned off the global ones: a start
    velocity along each bushing axis gives the oscillation sqrt(k / m) of that axis only."""
    axes = _rotation_about((1, 2, 3), 0.7).T          # rows: the bushing's axes
    k = np.array([200.0, 800.0, 1800.0])
    v0 = 0.01 * axes[0] + 0.02 * axes[1] - 0.01 * axes[2]
    scene = Scene()
    scene.add(RigidBody("block", 2.0, (0.1, 0.1, 0.1), (0, 0, 0), velocity=tuple(v0)))
    scene.add(Bushing("mount", "block", "ground", at=(0, 0, 0), stiffness=tuple(k), axes=axes,
                      rotational_stiffness=(1e5, 1e5, 1e5)))
    # (the force acts at the ground's point, which moves in the block's axes: the second-order
    # torque d x K d is held by the stiff torsion terms)
    res = _run(scene, 0.5)
    r = np.column_stack([res.coordinate(f"block.{c}") for c in "xyz"])
    local = r @ axes.T
    omega = np.sqrt(k / 2.0)
    expected = (axes @ v0) / omega * np.sin(np.outer(res.t_s, omega))
    np.testing.assert_allclose(local, expected, atol=1e-8)


def test_bushing_preload_carries_the_weight_and_torsion_oscillates():
    scene = Scene(gravity=(0, 0, -9.81))
    scene.add(RigidBody("base", 5.0, (1.0, 1.0, 1.0), (0, 0, 0)))
    scene.add(Fixed("anchor", "base", "ground", at=(0, 0, 0)))
    # The body hangs on the bushing at its centre of mass with the weight as preload and spins
    # slowly about the bushing's z axis (tilted): a torsion oscillator sqrt(kr / J_z).
    axes = _rotation_about((1, 0, 0), 0.3).T
    j_z = 0.05
    scene.add(RigidBody("head", 3.0, (0.08, 0.06, j_z), (0, 0, 0.5), rotation=axes.T,
                        angular_velocity=tuple(0.01 * axes[2])))
    scene.add(Bushing("mount", "base", "head", at=(0, 0, 0.5), stiffness=(1e4, 1e4, 1e4), axes=axes,
                      preload=tuple(axes @ np.array([0, 0, 3.0 * 9.81])), rotational_stiffness=(40.0, 40.0, 2.0)))
    res = _run(scene, 0.6)
    for c in "xyz":
        np.testing.assert_allclose(res.coordinate(f"head.{c}"), {"x": 0, "y": 0, "z": 0.5}[c], atol=1e-9)
    e = np.column_stack([res.coordinate(f"head.e{k}") for k in range(4)])
    e0_initial = np.r_[np.cos(0.15), np.sin(0.15), 0, 0]
    # rotation relative to the initial orientation, about the tilted z axis
    rel = np.array([_quat_mul(_quat_conj(e0_initial), ei) for ei in e])
    angle = 2 * np.arctan2(rel[:, 1:] @ np.array([0, 0, 1.0]), rel[:, 0])
    omega = np.sqrt(2.0 / j_z)
    np.testing.assert_allclose(angle, 0.01 / omega * np.sin(omega * res.t_s), atol=2e-7)


def _quat_conj(q):
    return np.r_[q[0], -q[1:]]


def _quat_mul(a, b):
    return np.r_[a[0] * b[0] - a[1:] @ b[1:], a[0] * b[1:] + b[0] * a[1:] + np.cross(a[1:], b[1:])]


def test_bushing_stop_engages_beyond_the_free_play():
    """Past the clearance the stop adds its stiffness: a block launched along x oscillates with
    sqrt(k / m) inside the free play and sqrt((k + k_stop) / m) beyond it; energy is conserved."""
    k, k_stop, gap, m, v0 = 100.0, 4900.0, 0.01, 1.0, 0.5
    scene = Scene()
    scene.add(RigidBody("block", m, (0.1, 0.1, 0.1), (0, 0, 0), velocity=(v0, 0, 0)))
    scene.add(Prismatic("guide", "block", "ground", at=(0, 0, 0), axis=(1, 0, 0)))
    scene.add(Bushing("stop", "block", "ground", at=(0, 0, 0), stiffness=(k, 0, 0), clearance=(gap, 0, 0),
                      stop_stiffness=(k_stop, 0, 0)))
    res = _run(scene, 0.3)
    x = res.coordinate("block.x")
    v = np.gradient(x, res.t_s)
    energy = 0.5 * m * v**2 + 0.5 * k * x**2 + 0.5 * k_stop * np.maximum(np.abs(x) - gap, 0) ** 2
    assert np.abs(x).max() > 1.5 * gap                # the stop is reached ...
    # ... and the maximum follows from energy conservation with both springs
    amp = np.abs(x).max()
    np.testing.assert_allclose(0.5 * k * amp**2 + 0.5 * k_stop * (amp - gap) ** 2, 0.5 * m * v0**2, rtol=2e-3)
    assert np.abs(x).max() < v0 / np.sqrt(k / m)      # stiffer than the spring alone
    assert np.all(np.isfinite(energy))


def test_rotational_speed_servo_spins_up_exponentially():
    scene = Scene()
    scene.add(RigidBody("disc", 1.0, (0.5, 0.5, 0.02), (0, 0, 0)))
    scene.add(Revolute("axle", "disc", "ground", at=(0, 0, 0), axis=(0, 0, 1)))
    scene.add(RotationalSpring("motor", "disc", "ground", axis=(0, 0, 1), damping=0.04, rate=-3.0))
    # (the servo holds the rate of body j, here the ground, relative to body i, the disc)
    res = _run(scene, 1.0)
    e0, e3 = res.coordinate("disc.e0"), res.coordinate("disc.e3")
    angle = np.unwrap(2 * np.arctan2(e3, e0))
    tau = 0.02 / 0.04
    np.testing.assert_allclose(angle, 3.0 * (res.t_s - tau * (1 - np.exp(-res.t_s / tau))), atol=1e-6)


def test_bushing_bad_input_names_the_item():
    scene = Scene()
    scene.add(RigidBody("block", 1.0, (0.1, 0.1, 0.1), (0, 0, 0)))
    scene.add(Bushing("mount", "block", "ground", at=(0, 0, 0), stiffness=(1.0, -2.0, 1.0)))
    with pytest.raises(ParameterError, match=r"bushing 'mount': stiffness=\(1.0, -2.0, 1.0\)"):
        MultibodyModel(scene)
