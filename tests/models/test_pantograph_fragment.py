"""The seed pantograph as a scene fragment (symcat.pantograph.seo2005.add_seo2005_pantograph): one
call under a wire of any name, its static equilibrium, the names it returns, bad input."""
from __future__ import annotations

import numpy as np
import pytest

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary.seed import add_seed_catenary
from symcat.errors import ParameterError
from symcat.model import run_model
from symcat.pantograph.seo2005 import MASSES, add_seo2005_pantograph, static_contact_force
from symcat.scene import AncfBody, Material, Scene, Section

G = 9.81
ROLES = {"lower_arm", "upper_arm", "plunger", "panhead", "base_hinge", "elbow", "apex", "guide", "primary_k1",
         "damper_k2", "leveller_k3", "coupling_rod", "uplift", "contact", "base"}


def _scene_names(scene):
    return set(scene.body_names()) | {x.name for x in scene.joints + scene.force_elements}


def test_under_the_seed_wire_named_otherwise_it_holds_the_models_static_force():
    """Same catenary as seo2005_catenary, its wire named "contact_wire": one call, and the static
    contact force is the model's (uplift minus the weights through the linkage)."""
    scene = add_seed_catenary(Scene(gravity=(0.0, 0.0, -G)), name="contact_wire")
    names = add_seo2005_pantograph(scene, "contact_wire", 5.0, speed=17.0)   # wire height, arc length: from the mesh
    assert set(names) == ROLES | {"carrier", "track", "drive"}
    assert names["base"] == names["carrier"] == "carrier"
    assert set(names.values()) <= _scene_names(scene)
    eq = solve_equilibrium(MultibodyModel(scene))
    model = run_model("seo2005_catenary", {"t_end": 0.0}).summary
    force = static_contact_force(eq, names["contact"])
    assert force == pytest.approx(model["static_contact_force_N"], rel=1e-9)
    assert 80.0 < force < 100.0


def test_under_a_lone_wire_the_base_carries_the_weights_minus_the_uplift_plus_the_push():
    """A wire of another name, place and height (no droppers), a fixed carrier, penalty contact:
    the pantograph pushes the wire up, and the carrier's support carries the pantograph's weight
    minus the uplift plus the wire's push."""
    scene = Scene(gravity=(0.0, 0.0, -G))
    wire = AncfBody.straight("contact_wire", "cable3d", [-10.0, 0, 5.3], [30.0, 0, 5.3], 8,
                             Material(1.2e11, 8900.0), Section.circle(0.012), prestrain=15000 / (1.2e11 * 1.13e-4))
    scene.add(wire.pin(0).pin(-1))
    names = add_seo2005_pantograph(scene, "contact_wire", 12.5, contact="penalty", carrier_fixed=True,
                                   uplift=300.0, prefix="front_")
    assert set(names) == ROLES | {"carrier", "carrier_fixed"}
    assert all(v.startswith("front_") for v in names.values())
    model = MultibodyModel(scene)
    eq = solve_equilibrium(model)
    force = static_contact_force(eq, names["contact"])
    assert 80.0 < force < 150.0
    # The wire (taut string, 15 kN) sags under its weight and is lifted by the push, at a = 22.5 m
    # from the left end of L = 40 m: the pan-head is there (within the penalty penetration, 2.4 mm).
    a, b, tension, w = 22.5, 17.5, 15000.0, 8900.0 * np.pi * 0.006**2 * G
    wire_z = 5.3 - w * a * b / (2 * tension) + force * a * b / ((a + b) * tension)
    head_z = eq.q[model.rigid_offset[names["panhead"]] + 2]
    assert abs(head_z - wire_z) < 3e-3, (head_z, wire_z)
    # The carrier's support carries the weights minus the uplift plus the push (the push leans
    # with the wire's slope, ~1e-3: 1e-4 N horizontal difference).
    support = np.asarray(eq.reactions_N[names["carrier_fixed"]])
    weights = (50.0 + sum(MASSES.values())) * G
    assert abs(abs(support[2]) - (weights - 300.0 + force)) < 1e-3
    assert abs(support[0]) < 2e-3 * force


def test_under_a_form_found_catenary_scene():
    """Any catenary: the fragment under the contact wire ("contact") of a form-found, staggered
    two-span catenary scene, penalty contact, in one call."""
    from symcat.catenary import benchmark2015, catenary_scene, find_form

    scene = catenary_scene(find_form(benchmark2015(2), 10, progress=False))
    names = add_seo2005_pantograph(scene, "contact", 60.0, contact="penalty", carrier_fixed=True)
    eq = solve_equilibrium(MultibodyModel(scene))
    assert eq.residual_N < 1e-5
    assert 80.0 < static_contact_force(eq, names["contact"]) < 130.0


def test_bad_input_is_refused_in_one_line_and_adds_nothing():
    scene = add_seed_catenary(Scene(gravity=(0.0, 0.0, -G)), name="contact_wire")
    before = _scene_names(scene)
    cases = [
        (dict(wire="wire", x0=5.0), r"^wire='wire': not an ANCF body of the scene; must be one of contact_wire$"),
        (dict(wire="contact_wire", x0=1.0),
         r"^x0=1 m: the pantograph must start on wire 'contact_wire', in \[2, 58\] m$"),
        (dict(wire="contact_wire", x0=59.0),
         r"^x0=59 m: the pantograph must start on wire 'contact_wire', in \[2, 58\] m$"),
        (dict(wire="contact_wire", x0=5.0, contact="rigid"), r"^contact='rigid': must be one of bilateral, penalty$"),
        (dict(wire="contact_wire", x0=5.0, base="car_body"), r"^base='car_body': not a rigid body of the scene"),
    ]
    for kwargs, message in cases:
        with pytest.raises(ParameterError, match=message) as info:
            add_seo2005_pantograph(scene, **kwargs)
        assert "\n" not in str(info.value)
        assert _scene_names(scene) == before
    with pytest.raises(ParameterError, match="wire='contact_wire': not an ANCF body of the scene; must be one of "
                                             "none: add the catenary first"):
        add_seo2005_pantograph(Scene(), "contact_wire", 5.0)
    # A second pantograph needs a prefix; with one it goes in.
    add_seo2005_pantograph(scene, "contact_wire", 5.0)
    with pytest.raises(ParameterError, match=r"^prefix='': the names .*carrier.* are already used in the scene; "
                                             r"give another prefix$"):
        add_seo2005_pantograph(scene, "contact_wire", 30.0)
    rear = add_seo2005_pantograph(scene, "contact_wire", 30.0, prefix="rear_")
    assert rear["panhead"] == "rear_panhead" and "rear_contact" in _scene_names(scene)
