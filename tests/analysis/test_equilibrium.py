"""Multibody static equilibrium (pseudo-transient continuation on the KKT system) against
closed forms, and on the seed paper's pantograph scene."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from symcat.analysis import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.model import run_model
from symcat.scene import AncfBody, Material, RigidBody, Scene, Section, SlidingJoint

G = 9.81


def mass_on_wire(n_elements, s0, force, tension=1000.0, ea=1e7, length=10.0):
    """A body (weight ``force``) hanging 0.1 m below a sliding joint on a pinned, pretensioned,
    almost massless cable."""
    sec = Section.from_stiffness(ea, 1e-3, 1e11)
    wire = AncfBody.straight("wire", "cable3d", [0, 0, 0], [length, 0, 0], n_elements, Material(1e11, 1e-6 / sec.A),
                             sec, prestrain=tension / ea)
    wire.pin(0).pin(-1)
    scene = Scene(gravity=(0, 0, -G))
    scene.add(wire)
    scene.add(RigidBody("mass", force / G, (0.01, 0.01, 0.01), (s0, 0, -0.1)))
    scene.add(SlidingJoint("slider", "wire", "mass", s0=s0, at=(s0, 0, 0)))
    return MultibodyModel(scene)


def elastic_string_sag(force, tension, ea, half):
    """Exact sag of an elastic string under a central point load: F = 2 T sin(theta) with
    T = EA ((1 + T0/EA) / cos(theta) - 1) (strain measured against the stress-free length)."""
    p = tension / ea
    theta = brentq(lambda th: 2 * ea * ((1 + p) / np.cos(th) - 1) * np.sin(th) - force, 1e-12, 1.0)
    return half * np.tan(theta)


def test_mass_at_midspan_sags_f_l_over_4t():
    force, tension, length = 2.0, 1000.0, 10.0
    errors = []
    for n in (16, 32):
        model = mass_on_wire(n, 5.0, force)
        eq = solve_equilibrium(model)
        sag = -(eq.q[model.rigid_offset["mass"] + 2] + 0.1)
        errors.append(abs(sag / elastic_string_sag(force, tension, 1e7, 5.0) - 1))
        assert sag == pytest.approx(force * length / (4 * tension), rel=0.03)    # small-sag formula
        assert eq.residual_N < 1e-6 and eq.constraint_residual < 1e-12
        np.testing.assert_allclose(eq.reactions_N["slider"], [0, 0, force], atol=1e-6 * force)
    # The C1 cubics round the kink under the load: the error is O(element length)
    # (measured 1.5 % with 16 elements, 0.7 % with 32).
    assert errors[1] < 0.01 and errors[0] / errors[1] > 1.8


def test_sliding_point_crosses_element_ends_to_the_lowest_point():
    """Released off-centre on 9 elements, the frictionless joint must travel across two element
    ends into the middle element (plain Newton stalls: the straight wire gives no stiffness along
    it). Inside the middle element the cubic cannot kink under the load, which leaves the
    discrete energy nearly flat there: the point stops at 4.70 m, not exactly at 5 m."""
    force, tension, ea = 200.0, 1000.0, 1e6
    model = mass_on_wire(9, 2.2, force, tension, ea)
    eq = solve_equilibrium(model)
    assert 40 / 9 < eq.s_m[0] < 50 / 9 and eq.residual_N < 1e-6
    sag = -(eq.q[model.rigid_offset["mass"] + 2] + 0.1)
    assert sag == pytest.approx(elastic_string_sag(force, tension, ea, 5.0), rel=0.03)
    assert eq.iterations < 100


@pytest.mark.parametrize("element", ["beam3d", "cable3d"])
def test_seo2005_scene_is_in_equilibrium_for_both_contact_models(element):
    static = {}
    for contact in ("bilateral", "penalty"):
        s = run_model("seo2005_catenary", {"t_end": 0.0, "contact": contact, "element": element}).summary
        assert s["static_residual_N"] < 1e-6
        static[contact] = s
    f_b, f_p = static["bilateral"]["static_contact_force_N"], static["penalty"]["static_contact_force_N"]
    assert 70 < f_b < 120 and f_p == pytest.approx(f_b, rel=0.01)
    # penalty: the pan-head sits above the wire by the penetration f / k
    dz = static["penalty"]["static_panhead_z_m"] - static["bilateral"]["static_panhead_z_m"]
    assert 0 < dz < 3 * f_p / 5e4
