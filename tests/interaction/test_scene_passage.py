"""Issue 28 item 4: any pantograph under any catenary. ``benchmark2015`` and ``en50318`` with
``pantograph=seo2005`` run the seed paper's four-body pantograph as scene bodies under the
form-found catenary (symcat.interaction.scene_passage), with the lumped pantograph's section,
start, statistics and outputs; a user's own pantograph fragment plugs in the same way.

Case (kept small for the default run): benchmark2015, 4 spans, 8 elements/span, 1 analysis
span (55 m), 250 km/h, dt = 2 ms, aerodynamic uplift 0: about 900 steps.

Tolerance of the mean contact force (aerodynamic uplift 0, no contact loss). Averaged over the
section, the inertia and damper forces of the pantograph would vanish if its motion were
periodic with the span; what remains are (i) the pantograph's static force-height
characteristic (the lumped pantograph has none; the four-body frame's is about -60 N/m: the
static force at the same uplift is 130.6 N at the support where the trim is made and 132.0 N at
mid-span, where the presag puts the wire 22 mm lower; the pan-head's mean height over the
section is 8 mm below its start, i.e. +0.5 %), and (ii) the part of the frame's slow (1-2 Hz)
oscillation, excited at the start and by the span, that one 55 m span (0.8 s at 250 km/h)
does not average out: with a force standard deviation of 41 N, a few newtons. Measured: the
mean is 3.0 % below the static force on this case (126.7 N against 130.6 N) and 1.7 % above
it at 200 km/h (4 spans, 10 elements, 1 ms); the lumped pantograph on this case: +0.3 %. The
assertion allows 5 %: above these, and well below what a wrong static state gives (an uplift
trimmed wrongly by 10 N moves the mean by 8 %).
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from symcat import cli
from symcat.catenary import benchmark2015
from symcat.interaction import load_passage
from symcat.interaction.scene_passage import ScenePantograph, run_scene_passage
from symcat.interaction.statistics import STAT_KEYS
from symcat.model import run_model

CASE = dict(pantograph="seo2005", n_spans=4, elements_per_span=8, analysis_spans=1, speed_kmh=250.0, dt=2e-3,
            aero_coefficient_N_s2_m2=0.0, progress=False, snapshot_interval=0.2)
TARGET_N = 0.00097 * 250.0**2 + 70.0  # EN 50367 target the lumped benchmark pantograph uses (N)


@pytest.fixture(scope="module")
def passage(tmp_path_factory):
    out = tmp_path_factory.mktemp("seo2005_passage")
    return run_model("benchmark2015", CASE, out=out), out


def test_seo2005_passage_has_the_lumped_summary_keys(passage):
    run, out = passage
    s = run.summary
    assert s["complete"] is True and s["pantograph"] == "seo2005"
    for key in STAT_KEYS:
        assert isinstance(s[key], float), key
    assert np.isfinite([s[k] for k in STAT_KEYS]).all()
    assert s["analysis_section_m"] == [110.0, 165.0]  # the lumped pantograph's section on this line
    for key in ("dropper_lengths_m", "form_finding_height_error_m", "elements_per_span", "n_coordinates",
                "simulated_s", "wall_per_simulated_s", "max_penetration_m", "slack_dropper_events", "uplift_N",
                "static_contact_force_N", "target_static_contact_force_N", "uplift_static_solves"):
        assert key in s, key
    # the energy balance closes: what generalized-alpha's numerical dissipation took, a small
    # part of the driving's work
    assert s["contact_work_J"] > 1.0
    assert s["energy_balance_error_J"] < 0.05 * s["contact_work_J"]
    # what this path does not compute is said, not left out silently
    assert set(s["not_computed"]) == {"newton_iterations_per_step"}
    # the lumped path's outputs, written for this one too
    names = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    assert {"benchmark2015.npz", "benchmark2015_contact_force.png", "benchmark2015_panhead.png",
            "benchmark2015_uplift_droppers.png", "paraview/benchmark2015.pvd"} <= names
    saved = load_passage(out / "benchmark2015.npz")
    assert saved["contact_force_N"].shape == (len(saved["t_s"]), 1)
    # the lumped pantograph's start (the carrier's; the pan-head stands 12 mm ahead once the frame has
    # risen into its static state)
    assert saved["x_contact_m"][0, 0] == pytest.approx(55.0, abs=0.05)
    assert saved["t_s"][-1] == pytest.approx(s["simulated_s"])
    assert json.loads((out / "summary.json").read_text())["pantograph"] == "seo2005"


def test_static_contact_force_is_the_target(passage):
    run, _ = passage
    s = run.summary
    rec = run.arrays["result"].record
    assert s["target_static_contact_force_N"] == pytest.approx(TARGET_N, rel=1e-12)
    assert s["static_contact_force_N"] == pytest.approx(TARGET_N, rel=1e-5)
    assert rec.contact_force_N[0, 0] == pytest.approx(TARGET_N, rel=1e-5)  # the integration starts from it
    assert 150.0 < s["uplift_N"] < 400.0  # the plunger uplift that carries the 22 kg frame and presses 130 N
    assert s["uplift_static_solves"] <= 6


def test_mean_contact_force_is_the_static_force(passage):
    run, _ = passage
    s = run.summary
    assert s["contact_loss_percent"] == 0.0 and s["contact_force_min_N"] > 0  # no loss: the mean argument holds
    assert s["contact_force_std_N"] > 5.0  # a passage, not a static state
    assert s["contact_force_mean_N"] == pytest.approx(TARGET_N, rel=0.05)  # module docstring


def test_en50318_static_bilateral_on_the_unstaggered_wire():
    s = run_model("en50318", dict(pantograph="seo2005", contact="bilateral", n_spans=4, elements_per_span=8,
                                  analysis_spans=1, t_end=0.0, static_force_N=110.0, progress=False)).summary
    assert s["static_contact_force_N"] == pytest.approx(110.0, rel=1e-5)
    assert s["target_static_contact_force_N"] == 110.0 and s["uplift_N"] > 110.0


def test_a_users_own_pantograph_fragment():
    """The module docstring's single-mass pantograph on a carrier: statics only."""
    from symcat.pantograph.lumped_scene import wire_height
    from symcat.scene import (
        Driving,
        PenaltyContact,
        PointLoad,
        Prismatic,
        RigidBody,
        SpringDamper,
    )

    def mine(scene, wire, x0, speed, uplift):
        z, s0, _ = wire_height(scene, wire, x0)
        v = (speed, 0.0, 0.0)
        scene.add(RigidBody("roof", 50.0, (1, 1, 1), (x0, 0, z - 1.0), velocity=v))
        scene.add(Prismatic("track", "roof", "ground", at=(x0, 0, z - 1.0), axis=(1, 0, 0)))
        scene.add(Driving("drive", "roof", direction=(1, 0, 0), velocity=speed))
        scene.add(RigidBody("head", 8.0, (0.1, 0.1, 0.1), (x0, 0, z), velocity=v))
        scene.add(Prismatic("guide", "head", "roof", at=(x0, 0, z), axis=(0, 0, 1)))
        scene.add(SpringDamper("suspension", "roof", "head", at_i=(x0, 0, z - 1.0), at_j=(x0, 0, z),
                               stiffness=500.0, damping=50.0, free_length=1.0))
        scene.add(PointLoad("uplift", "head", force=(0, 0, uplift)))
        scene.add(PenaltyContact("head_contact", wire, "head", s0=s0, stiffness=5e4, damping=0.0))
        return "head_contact"

    res = run_scene_passage(benchmark2015(4), ScenePantograph(mine, uplift=160.0, name="mine"), 200 / 3.6,
                            target_force=90.0, elements_per_span=8, analysis_spans=1, t_end=0.0, progress=False)
    assert res.static_contact_force_N == pytest.approx(90.0, rel=1e-5)
    # a vertical guide: the uplift carries the force, the weight and the suspension stretched by the rise
    model = res.model
    rise = model.q0[model.rigid_offset["head"] + 2] - model.scene.find("head").position[2]
    assert 1e-3 < rise < 0.1  # the wire is pushed up
    assert res.uplift_N == pytest.approx(90.0 + 8.0 * 9.81 + 500.0 * rise, rel=1e-6)
    assert res.record is None and res.section_m == (110.0, 165.0)


@pytest.mark.parametrize("sets, words", [
    (["pantograph=seo2005", "tension_sections=2", "contact=bilateral"],
     ["tension_sections=2", "pantograph=seo2005", "contact=bilateral", "contact=penalty"]),
    (["pantograph=seo2005", "contact=bilateral"], ["contact=bilateral", "pantograph=seo2005", "contact=penalty"]),
    (["pantograph=seo2005", "pantograph_damping_N_s_m=1,2,3"], ["pantograph_damping_N_s_m=1,2,3", "pantograph=lumped"]),
    (["pantograph=foo"], ["pantograph=foo", "lumped, seo2005"]),
    (["pantograph=lumped_interaction"], ["pantograph=lumped_interaction", "lumped, seo2005"]),
])
def test_combinations_that_cannot_run_are_one_line(sets, words, tmp_path, capsys):
    out = tmp_path / "out"
    args = ["run", "benchmark2015", "--out", str(out)]
    for s in sets:
        args += ["--set", s]
    code = cli.main(args)
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("symcat: error: ") and "Traceback" not in err, err
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert not out.exists()


@pytest.mark.parametrize("pantograph, contact", [("lumped", "bilateral"), ("seo2005", "penalty")])
def test_two_multibody_pantographs(pantograph, contact):
    """Two pantographs one span apart on the multibody path, the lumped one in bilateral contact
    on the staggered wire (a shoe across its pan-head follows the stagger), the four-body one
    in penalty contact: each starts at the static force, presses about it on average, and the
    energy balance of the whole scene closes. The leading pantograph is the first."""
    run = run_model("benchmark2015", dict(pantograph=pantograph, contact=contact, n_pantographs=2, n_spans=6,
                                          spacing_m=55.0, elements_per_span=6, analysis_spans=1, speed_kmh=200.0,
                                          dt=2e-3, aero_coefficient_N_s2_m2=0.0, progress=False, paraview=False,
                                          snapshot_interval=0.2))
    s = run.summary
    assert s["complete"] is True
    x = run.arrays["result"].record.x_contact_m
    assert x[0, 0] - x[0, 1] == pytest.approx(55.0, abs=1e-3)  # leading first, spacing_m apart
    target = s["target_static_contact_force_N"]
    assert np.allclose(s["static_contact_force_N"], target, rtol=1e-5)
    for k in (1, 2):
        stats = s[f"pantograph_{k}"]
        assert abs(stats["contact_force_mean_N"] / target - 1) < 0.1, (k, stats["contact_force_mean_N"])
        assert stats["contact_force_std_N"] > 1.0
    assert s["energy_balance_error_J"] < 0.05 * s["contact_work_J"]


def test_lumped_bilateral_is_stable_on_the_default_mesh():
    """contact=bilateral with the lumped pantograph at the model's defaults (60 elements per
    span, 1 ms): the sliding contact stays stable, the force about the static one (the raw force
    of a sliding contact swings widely: its 20 Hz statistics on the whole passage are mean
    167 N, std 76 N, max 359 N; the retired interaction path's sliding contact reached 1e5 N
    within 0.05 s here)."""
    run = run_model("benchmark2015", dict(pantograph="lumped", contact="bilateral", t_end=0.1,
                                          progress=False, paraview=False))
    s = run.summary
    assert s["pantograph"] == "lumped" and s["complete"] is True
    force = run.arrays["result"].record.contact_force_N[:, 0]
    assert np.abs(force).max() < 3 * s["static_contact_force_N"]
    assert abs(force.mean() / s["static_contact_force_N"] - 1) < 0.15
    assert s["max_constraint_violation_m"] < 1e-6
