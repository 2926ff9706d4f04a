"""The compiled model DAE (symcat.codegen.model_dae) against the graph over the kernels it
replaces: same residual, same Jacobian, same simulation, and compiled once per model."""
import casadi as ca
import numpy as np
import pytest

from symcat.codegen.model_dae import COMPILED, compiled_dae
from symcat.dae.formulation import Formulation
from symcat.dae.initial import consistent_state
from symcat.assembly.multibody import MultibodyModel
from symcat.scene import CreepModel, Driving, PointLoad, RigidBody, Scene, WheelRailJoint
from symcat.simulation import simulate
from symcat.vehicle import wheelset_on_track
from symcat.wheelrail import WheelsetDimensions, profile_pair


def _wheelset(profile="s1002_uic60", creep="polach"):
    """A wheelset rolling at 10 m/s, 2 mm off centre, with creep forces."""
    pair = profile_pair(profile, 0.05)
    dims = WheelsetDimensions(tape_circle_distance_m=1.5, nominal_radius_m=0.46)
    placed = wheelset_on_track(pair.wheel, pair.rail, 0.002, wheelset=dims)
    r_mean = 0.5 * sum(placed.contacts[side].rolling_radius_m for side in ("left", "right"))
    spin = placed.rotation[:, 1] * 10.0 / r_mean
    scene = Scene(gravity=(0.0, 0.0, -9.81))
    scene.add(RigidBody("wheelset", 1813.0, (1120.0, 112.0, 1120.0), position=placed.position_m,
                        rotation=placed.rotation, velocity=(10.0, 0.0, 0.0), angular_velocity=tuple(spin)))
    scene.add(PointLoad("axle_load", "wheelset", force=(0.0, 0.0, -100e3)))
    for side in ("left", "right"):
        scene.add(WheelRailJoint(f"wr_{side}", "wheelset", side, pair.wheel, pair.rail, wheelset=dims,
                                 creep=CreepModel(creep, nominal_normal_force_N=59e3)))
    scene.add(Driving("drive", "wheelset", direction=(1.0, 0.0, 0.0), velocity=10.0))
    return MultibodyModel(scene)


@pytest.mark.parametrize("formulation,index", [("augmented", "ggl"), ("augmented", "1")])
def test_compiled_residual_and_jacobian_equal_the_graph(formulation, index, rng):
    model = _wheelset()
    form = Formulation(model, formulation, index, 10.0, False)
    x, z = consistent_state(form, 0.0)
    graph = form.dae_function()
    compiled = compiled_dae(form.dae_function)
    assert compiled.class_name() == "External"
    n_p = graph.size1_in(3)
    for k in range(4):
        # Perturbed states, and an open contact (the released gap row) in the last sample.
        xs = x + (1e-4 * rng.standard_normal(len(x)) if k else 0.0)
        zs = z * (1 + 1e-3 * rng.standard_normal(len(z)))
        p = np.r_[0.1 * k, np.zeros(n_p - 1)]
        if k == 3:
            p[1] = 1.0
        for a, b in list(zip(graph(0.05, xs, zs, p, ca.DM(0, 1)), compiled(0.05, xs, zs, p, ca.DM(0, 1))))[:2]:
            a, b = np.asarray(a).ravel(), np.asarray(b).ravel()
            assert np.allclose(a, b, rtol=1e-11, atol=1e-9 * (1 + np.abs(a).max()))
        # The Jacobian IDAS uses: the compiled companion against CasADi's AD of the graph.
        jg = graph.jacobian()
        jc = compiled.jacobian()
        args = [0.05, xs, zs, p, ca.DM(0, 1)] + [ca.DM.zeros(graph.sparsity_out(i)) for i in range(4)]
        for a, b in zip(jg(*args), jc(*args)):
            a, b = np.asarray(ca.densify(a)), np.asarray(ca.densify(b))
            if a.size == 0:
                continue
            assert np.allclose(a, b, rtol=1e-9, atol=1e-9 * (1 + np.abs(a).max()))


def test_compiled_once_and_same_simulation():
    model = _wheelset("conical", "linear")
    graph = simulate(model, 0.2, index="1", rtol=1e-8, n_out=10, progress=False, compiled=False)
    simulate(model, 0.05, index="1", rtol=1e-8, n_out=2, progress=False, compiled=True)
    before = COMPILED["n"]
    compiled = simulate(model, 0.2, index="1", rtol=1e-8, n_out=10, progress=False, compiled=True)
    assert COMPILED["n"] == before  # the second run of a model loads its library
    # Equal residuals up to rounding: the runs part by the integration error only (rtol 1e-8 on
    # coordinates of order 0.5 m; a wrong residual would move the wheelset by millimetres).
    for name in ("wheelset.y", "wheelset.z"):
        assert np.abs(graph.coordinate(name) - compiled.coordinate(name)).max() < 1e-7


def test_ancf_model_compiles_whole_after_its_graph_was_built(rng):
    """A wire (ANCF elements, their forces a cached function over the compiled kernels) with a
    body on a sliding joint: the compiled DAE, built after the graph (so after that cache was
    filled), contains the elements' SX and calls no kernel library (it used to call the cached
    externals: a library with undefined symbols), and equals the graph."""
    from symcat.model import load_model

    slider = load_model("slider_on_wire")
    model = MultibodyModel(slider.run.__globals__["build"](slider.resolve({"n_elements": 4})))
    form = Formulation(model, "augmented", "ggl", 10.0, False)
    x, z = consistent_state(form, 0.0)
    graph = form.dae_function()
    graph(0.0, x, z, np.zeros(graph.size1_in(3)), ca.DM(0, 1))  # the cached force function exists
    compiled = compiled_dae(form.dae_function)
    assert compiled.class_name() == "External"
    p = np.zeros(graph.size1_in(3))
    for k in range(3):
        xs = x + (1e-4 * rng.standard_normal(len(x)) if k else 0.0)
        zs = z * (1 + 1e-3 * rng.standard_normal(len(z)))
        for a, b in list(zip(graph(0.01, xs, zs, p, ca.DM(0, 1)), compiled(0.01, xs, zs, p, ca.DM(0, 1))))[:2]:
            a, b = np.asarray(a).ravel(), np.asarray(b).ravel()
            assert np.allclose(a, b, rtol=1e-10, atol=1e-9 * (1 + np.abs(a).max()))
