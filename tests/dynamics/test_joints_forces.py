"""Joints and force elements in motion against closed forms, and bad input."""
from __future__ import annotations

import numpy as np
import pytest

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError, SolverError
from symcat.integrate import simulate
from symcat.model import run_model
from symcat.scene import (AncfBody, Driving, Fixed, Material, PointLoad, Prismatic, Revolute, RigidBody,
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
