"""Rigid bodies that hold some coordinates (``RigidBody.held``): the held coordinates are
eliminated like an ANCF body's pinned ones, and the motion is that of the same body guided by
joints to the ground."""
from __future__ import annotations

import math

import numpy as np
import pytest

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError
from symcat.integrate import generalized_alpha, simulate
from symcat.scene import GROUND, Driving, Prismatic, RigidBody, Scene, SpringDamper

G = 9.81
MASS, K, C = 3.0, 400.0, 2.0
SPEED = 2.0


def _oscillator(held: bool):
    """A mass hanging from a spring-damper under a carrier driven along x: by held coordinates,
    or by prismatic joints to the ground and to the carrier."""
    scene = Scene(gravity=(0.0, 0.0, -G))
    v = (SPEED, 0.0, 0.0)
    if held:
        scene.add(RigidBody("carrier", 1.0, (1.0, 1.0, 1.0), (0.0, 0.0, 1.0), velocity=v, held=("y", "z", "rotation")))
        scene.add(RigidBody("mass", MASS, (0.1, 0.1, 0.1), (0.0, 0.0, 0.0), velocity=v, held=("y", "rotation")))
        scene.add(Driving("mass_drive", "mass", direction=(1.0, 0.0, 0.0), velocity=SPEED))
    else:
        scene.add(RigidBody("carrier", 1.0, (1.0, 1.0, 1.0), (0.0, 0.0, 1.0), velocity=v))
        scene.add(Prismatic("track", "carrier", GROUND, at=(0.0, 0.0, 1.0), axis=(1.0, 0.0, 0.0)))
        scene.add(RigidBody("mass", MASS, (0.1, 0.1, 0.1), (0.0, 0.0, 0.0), velocity=v))
        scene.add(Prismatic("guide", "mass", "carrier", at=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0)))
    scene.add(Driving("drive", "carrier", direction=(1.0, 0.0, 0.0), velocity=SPEED))
    # free length 1 m: the mass starts 1 m below the carrier and falls into the spring
    scene.add(SpringDamper("spring", "carrier", "mass", at_i=(0.0, 0.0, 1.0), at_j=(0.0, 0.0, 0.0), stiffness=K,
                           damping=C, free_length=1.0))
    return MultibodyModel(scene)


def _closed_form(t):
    """Drop from the spring's free length: z(t) of a damped oscillator about -m g / k."""
    z_eq = -MASS * G / K
    wn = math.sqrt(K / MASS)
    zeta = C / (2 * math.sqrt(K * MASS))
    wd = wn * math.sqrt(1 - zeta**2)
    return z_eq * (1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t)))


def test_held_coordinates_leave_three_unknowns_and_no_normalization_rows():
    held, guided = _oscillator(True), _oscillator(False)
    # the carrier's x, the mass's x and z; the coordinate names say which
    assert held.free.size == 3 and guided.free.size == 14
    assert [held.coordinate_names()[i] for i in held.free] == ["carrier.x", "mass.x", "mass.z"]
    assert not any("normalization" in r for r in held.row_names)
    assert len(held.row_names) == 2 and len(guided.row_names) > 10


@pytest.mark.parametrize("integrator", ["idas_1", "idas_ggl", "generalized_alpha"])
def test_a_held_body_moves_as_the_guided_one_and_as_the_closed_form(integrator):
    results = []
    for held in (True, False):
        model = _oscillator(held)
        if integrator.startswith("idas"):
            index = integrator.split("_")[1]
            res = simulate(model, 0.5, "augmented", index, rtol=1e-9, atol=1e-11, n_out=50, progress=False)
            # GGL's default QR fails to start here (h -> 1e-18); the run goes on with LU.
            assert res.stats.get("linear_solver_fallbacks", 0) == (1 if index == "ggl" else 0)
        else:
            res = generalized_alpha(model, 0.5, 2.5e-4, 0.9, n_out=50, progress=False)
        results.append(res)
        z = res.coordinate("mass.z")
        np.testing.assert_allclose(z, _closed_form(res.t_s), atol=1e-6 if integrator != "generalized_alpha" else 2e-5)
        np.testing.assert_allclose(res.coordinate("mass.x"), SPEED * res.t_s, atol=1e-9)
        np.testing.assert_allclose(res.coordinate("mass.y"), 0.0, atol=1e-12)
    np.testing.assert_allclose(results[0].coordinate("mass.z"), results[1].coordinate("mass.z"),
                               atol=1e-7 if integrator != "generalized_alpha" else 1e-8)


def test_bad_held_coordinates_are_refused_with_their_names():
    with pytest.raises(ParameterError, match=r"mass.held=\('w',\): 'w' not a coordinate; allowed: x, y, z, rotation"):
        RigidBody("mass", 1.0, (1.0, 1.0, 1.0), held=("w",))
    with pytest.raises(ParameterError, match=r"mass.held=\('x',\): a held coordinate must start at rest"):
        RigidBody("mass", 1.0, (1.0, 1.0, 1.0), velocity=(1.0, 0.0, 0.0), held=("x",))
    with pytest.raises(ParameterError, match=r"must start at rest"):
        RigidBody("mass", 1.0, (1.0, 1.0, 1.0), angular_velocity=(0.0, 0.0, 1.0), held=("rotation",))
