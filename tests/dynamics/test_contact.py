"""Penalty wire contact in motion: loss of contact and landing, and agreement with the
bilateral sliding joint while in contact."""
from __future__ import annotations

import numpy as np
import pytest

from symcat.analysis import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError
from symcat.integrate import simulate
from symcat.scene import (AncfBody, Material, PenaltyContact, PointLoad, Prismatic, RigidBody, Scene, Section,
                          SlidingJoint)

G, UPLIFT, MASS = 9.81, 60.0, 1.0


def head_under_wire(contact="penalty", v0=0.0, stiffness=5e4, damping=20.0, shake=0.0):
    """A 1 kg head on a vertical guide pushed up by 60 N (plus ``shake`` N at 8 Hz) against a
    4 m pretensioned cable (1 kN), launched with vertical velocity ``v0``, starting from static
    equilibrium."""
    sec = Section.from_stiffness(1e6, 1.0, 1e11)
    wire = AncfBody.straight("wire", "cable3d", [0, 0, 0], [4, 0, 0], 4, Material(1e11, 0.5 / sec.A), sec,
                             prestrain=1e-3, damping_axial=1e-4, damping_bending=1e-4)
    wire.pin(0).pin(-1)
    scene = Scene(gravity=(0, 0, -G))
    scene.add(wire)
    scene.add(RigidBody("head", MASS, (0.01, 0.01, 0.01), (1.5, 0, 0), velocity=(0, 0, v0)))
    scene.add(Prismatic("guide", "head", "ground", at=(1.5, 0, 0), axis=(0, 0, 1)))
    scene.add(PointLoad("uplift", "head", force=(0, 0, UPLIFT), force_amplitude=(0, 0, shake), frequency=8.0))
    if contact == "penalty":
        scene.add(PenaltyContact("contact", "wire", "head", s0=1.5, stiffness=stiffness, damping=damping))
    else:
        scene.add(SlidingJoint("contact", "wire", "head", s0=1.5))
    model = MultibodyModel(scene)
    eq = solve_equilibrium(model)
    eq.apply(model)
    return model, eq


def test_launched_head_separates_flies_and_lands_without_step_collapse():
    model, eq = head_under_wire(v0=-2.0)
    assert eq.contact_force_N["contact"] == pytest.approx(UPLIFT - MASS * G, rel=1e-4)  # normal tilts with the wire
    res = simulate(model, 0.3, rtol=1e-6, atol=1e-8, n_out=300, progress=False)
    c = res.contacts["contact"]
    lost = c["gap_m"] > 0
    transitions = int(np.sum(np.diff(lost.astype(int)) != 0))
    assert transitions >= 4 and 5 < 100 * lost.mean() < 60       # separates and lands, more than once
    assert np.all(c["force_N"] >= 0) and np.all(c["force_N"][c["gap_m"] > 0] == 0)
    flying = c["gap_m"] > 1e-3
    a_z = res.a[:, model.rigid_offset["head"] + 2]
    np.testing.assert_allclose(a_z[flying], (UPLIFT - MASS * G) / MASS, rtol=1e-6)  # free flight
    # Smooth (C1) force law: a few error-test failures per transition, no step collapse.
    assert res.stats["nsteps"] < 6000 and res.stats["netfails"] < 30 * transitions


def test_stiff_penalty_agrees_with_the_bilateral_joint_while_in_contact():
    runs = {}
    for contact in ("bilateral", "penalty"):
        model, _ = head_under_wire(contact, stiffness=2e6, damping=200.0, shake=30.0)
        res = simulate(model, 0.1, rtol=1e-7, atol=1e-9, n_out=100, progress=False)
        force = -res.reactions_N["contact"][:, 2] if contact == "bilateral" else res.contacts["contact"]["force_N"]
        runs[contact] = (res.coordinate("head.z"), force)
    (z_b, f_b), (z_p, f_p) = runs["bilateral"], runs["penalty"]
    assert np.abs(z_p - z_b).max() < 0.02 * np.ptp(z_b) + 5e-5    # penetration ~ 50 N / 2e6 N/m = 25 um
    assert f_p.mean() == pytest.approx(f_b.mean(), rel=0.01)
    assert np.abs(f_p - f_b).max() < 0.05 * np.ptp(f_b)


def test_bad_contact_parameters_are_named():
    with pytest.raises(ParameterError, match="stiffness=-1 N/m"):
        PenaltyContact("c", "wire", "head", s0=0.0, stiffness=-1.0)
    scene = Scene()
    scene.add(RigidBody("a", 1.0, (1, 1, 1)))
    scene.add(RigidBody("b", 1.0, (1, 1, 1)))
    with pytest.raises(ParameterError, match="contact 'c': wire='a' is not an ANCF body"):
        scene.add(PenaltyContact("c", "a", "b", s0=0.0))


@pytest.mark.parametrize("x_head", [5.5, -1.5])
def test_a_contact_past_the_wire_end_is_on_its_straight_continuation(x_head):
    """Past a wire's end a contact point follows the wire's straight continuation along the end
    tangent (the tangency stays solvable for a pan-head that has left a tension section's
    wire) and exerts no force: on a straight inclined wire the closest point and the normal gap
    are those of the line, beyond either end (the gap positive below the line, where a pan-head
    is clear of its wire), and the force is zero even when the point is 30 cm into the line."""
    import casadi as ca

    from symcat.dae.formulation import Formulation
    from symcat.dae.initial import locate_contacts

    slope = 0.1
    sec = Section.from_stiffness(1e6, 1.0, 1e11)
    wire = AncfBody.straight("wire", "cable3d", [0, 0, 0], [4, 0, 4 * slope], 4, Material(1e11, 0.5 / sec.A), sec)
    wire.pin(0).pin(-1)
    scene = Scene(gravity=(0, 0, -G))
    scene.add(wire)
    t = np.array([1.0, 0.0, slope]) / np.hypot(1.0, slope)
    for dz in (0.3, -0.02):  # into the line (above it), and 2 cm clear below it
        scene = Scene(gravity=(0, 0, -G))
        scene.add(wire)
        point = np.array([x_head, 0.0, slope * x_head + dz])
        scene.add(RigidBody("head", MASS, (0.01, 0.01, 0.01), tuple(point)))
        scene.add(PenaltyContact("contact", "wire", "head", s0=float(point @ t) + 0.3, stiffness=5e4))
        model = MultibodyModel(scene)
        form = Formulation(model)
        q, v, s, w, ts = (ca.MX.sym(n, k) for n, k in (("q", form.n_f), ("v", form.n_f), ("s", 0), ("w", 0), ("t", 1)))
        sc = ca.MX.sym("sc", 1)
        k = form.terms(q, v, s, w, ts, sc)
        names = ["C", "Cq", "Cs", "Ct", "Qd", "M", "Q", "T"]
        no_contacts = form.terms(q, v, s, w, ts, sc, contacts=False)["Q"]
        outs = [k[n] for n in names] + [ca.diag(ca.jacobian(k["T"], sc)), k["gap"], k["fc"], k["Q"] - no_contacts]
        fn = ca.Function("terms", [q, v, s, w, ts, sc], outs)
        q0 = form.to_internal(model.q0[model.free])
        sc0 = locate_contacts(fn, q0, np.zeros(form.n_f), [], [], 0.0, [float(point @ t) + 0.3])
        gap, force, generalized = (np.asarray(x).ravel() for x in fn(q0, np.zeros(form.n_f), [], [], 0.0, sc0)[9:])
        assert sc0[0] == pytest.approx(point @ t, abs=1e-9)  # the foot of the normal on the line
        assert not 0 <= sc0[0] <= 4 * np.hypot(1.0, slope)  # off the wire
        assert gap[0] == pytest.approx(-dz / np.hypot(1.0, slope), abs=1e-9)  # distance to the line
        assert force[0] == 0.0
        assert np.abs(generalized).max() == 0.0  # no force on the wire nor on the head
