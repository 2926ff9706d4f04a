"""Lines of several tension sections: overlap geometry, form finding and the pan-head handover
on the shared multibody path (the lumped pantograph as scene bodies, a penalty contact on each
section's contact wire)."""
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from symcat.catenary import benchmark2015, find_form
from symcat.errors import ParameterError
from symcat.interaction.scene_pantographs import ScenePantograph, _static, lumped_fragment
from symcat.interaction.scene_passage import run_scene_passage
from symcat.interaction.statistics import lowpass
from symcat.pantograph import benchmark2015_pantograph
from symcat.pantograph.lumped_scene import add_lumped_pantograph, loaded_wire_height
from symcat.scene import PenaltyContact

L = 55.0
#: The retired interaction path's passage through the overlap (interaction_reference.py, fe59032).
REFERENCE = json.loads(Path(__file__).with_name("interaction_reference.json").read_text())["overlap"]


@pytest.fixture(scope="module")
def two_sections():
    """Two sections of 6 spans: a 9-span line, overlap over spans 3-5, transition span 220-275 m."""
    return find_form(benchmark2015(6).with_(n_sections=2), 20)


def test_overlap_geometry():
    d = benchmark2015(6).with_(n_sections=3)
    a, b, c = d.sections()
    assert d.line_spans == 12 and d.line_length == pytest.approx(12 * L)
    assert (a.x0, b.x0, c.x0) == (0.0, 3 * L, 6 * L) and c.x_end == pytest.approx(d.line_length)
    assert (a.lift_start, a.lift_end, b.lift_start, b.lift_end, c.lift_start, c.lift_end) == (
        False, True, True, True, True, False)
    mid = a.x0 + 4.5 * L  # middle of the transition span: both wires at working height
    assert a.target_height(mid) == pytest.approx(5.3) and b.target_height(mid) == pytest.approx(5.3)
    h = d.overlap_raise
    assert a.lift(a.x0 + 5 * L) == pytest.approx(h) and a.lift(a.x_end) == pytest.approx(5 * h)
    assert b.lift(b.x0) == pytest.approx(5 * h) and b.lift(b.x0 + L) == pytest.approx(h)
    x = np.linspace(mid - 1.0, a.x_end, 4001)  # lift and its slope are continuous
    z = a.lift(x)
    slope = np.diff(z) / np.diff(x)
    assert np.max(np.abs(np.diff(z))) < 2 * 5 * h / 4000 * 1.01 and np.max(np.abs(np.diff(slope))) < 1e-5
    assert a.y_offset == -b.y_offset == pytest.approx(0.5 * d.overlap_offset)
    # the single-section line is unchanged: no lift, no offset
    single = benchmark2015(6).sections()[0]
    assert single.lift(np.linspace(0, 6 * L, 50)).max() == 0.0 and single.y_offset == 0.0


def test_overlap_form_finding(two_sections):
    form = two_sections
    st = form.structure
    assert form.height_error_m < 1e-6
    assert np.all(form.dropper_tension_N > 10.0)
    per = 9 * 6
    first, second = form.dropper_length_m[:per], form.dropper_length_m[per:]
    # the line is symmetric about the overlap's centre: section 2 mirrors section 1
    assert second == pytest.approx(first[::-1], abs=2e-6)
    # away from the overlap the dropper lengths are those of a line without sections
    plain = find_form(benchmark2015(6), 20).dropper_length_m
    assert first[:9 * 3] == pytest.approx(plain[:9 * 3], abs=1e-4)
    # out-of-running wire at the far support of the transition span sits raised by overlap_raise
    z = st.contact_wire_z(form.q)
    node = st.section_rows[0].start + st._local["support"][5]
    assert z[node] == pytest.approx(5.3 + st.design.overlap_raise, abs=1e-6)


def _wire_forces(model, form, element, forces) -> np.ndarray:
    """Force (N) of the pan-head's penalty contact ``element`` and its copies on each tension
    section's contact wire (in the order of ``form.structure.contacts``), from the contact
    forces ``forces`` (name -> N)."""
    wires = [b.name for b in form.structure.contacts]
    out = np.zeros(len(wires))
    for e in model.scene.force_elements:
        if isinstance(e, PenaltyContact) and (e.name == element.name or e.name.startswith(element.name + "@")):
            out[wires.index(e.wire)] += forces[e.name]
    return out


def test_quasi_static_handover_matches_statics(two_sections):
    """A slow passage through the overlap shares the force between the wires as a sequence of
    static equilibria does (two independent computations: Newton statics of the joint
    equilibrium against generalized-alpha dynamics filtered at 2 Hz)."""
    form = two_sections
    speed = 10.0
    # dampers on the stages: without them the frame's 0.4 Hz bounce passes any low-pass filter
    panto = replace(benchmark2015_pantograph(100), damping=(100.0, 0.0, 45.0))
    run = run_scene_passage(form.structure.design, lumped_fragment(panto, form=form), speed,
                            float(panto.static_force(speed).sum()), analysis_spans=1, lead_in=20.0, form=form,
                            t_end=75.0 / speed, dt=2e-3, progress=False)
    rec = run.record
    assert rec.stats["halvings"] == 0
    x = rec.x_contact_m[:, 0]
    xs = np.arange(226.0, 274.0, 4.0)
    shares = np.stack([lowpass(rec.t_s, rec.contact_force_wire_N[:, 0, w], 2.0) for w in range(2)], axis=1)
    dynamic = np.array([shares[np.argmin(np.abs(x - xi))] for xi in xs])

    # the same pantograph (same uplift, carrier height and springs) standing at each position
    standing = replace(panto, uplift=run.uplift_N)
    x_start = float(run.line.x_start[0])
    head_z = loaded_wire_height(form, x_start, float(standing.static_force(speed).sum()))

    def add(scene, wire, x0, v, uplift):
        return add_lumped_pantograph(scene, replace(standing, uplift=uplift), wire, x0, v, head_z=head_z)["contact"]

    fixed = ScenePantograph(add, uplift=run.uplift_N, name="standing")
    static = []
    for xi in xs:
        _, model, (element,), eq = _static(form, [fixed], "contact", [xi], speed, [run.uplift_N])
        static.append(_wire_forces(model, form, element, eq.contact_force_N))
    static = np.array(static)
    total = static.sum(axis=1)
    assert total == pytest.approx(panto.static_force(speed).sum(), rel=0.1)  # the frame spring (160 N/m) acts
    both = (static > 5.0).all(axis=1)
    assert both.sum() >= 4  # the pan-head presses on both wires over several metres
    assert np.all(np.diff(static[:, 1]) >= -1e-6)  # the new wire takes over monotonically
    # the interaction path measured 4.6 N where the share changes fastest (17 N over 4 m: the
    # 2 Hz filter smears it)
    assert np.abs(dynamic - static).max() < 0.08 * total.max()


def test_overlap_bad_inputs(two_sections):
    panto = benchmark2015_pantograph(100)
    with pytest.raises(ParameterError, match="bilateral"):
        run_scene_passage(two_sections.structure.design, lumped_fragment(panto, "bilateral"), 10.0,
                          float(panto.static_force(10.0).sum()), form=two_sections, t_end=0.0, progress=False)
    with pytest.raises(ParameterError, match="n_spans"):
        benchmark2015(5).with_(n_sections=2)
    with pytest.raises(ParameterError, match="overlap_raise"):
        benchmark2015(6).with_(n_sections=2, overlap_raise=0.5)
    with pytest.raises(ParameterError, match="overlap_raise"):  # lift too steep: droppers would push
        find_form(benchmark2015(6).with_(n_sections=2, overlap_raise=0.235), 10)
    with pytest.raises(ParameterError, match="n_sections"):
        benchmark2015(6).with_(n_sections=0)


def test_overlap_on_the_multibody_path_matches_the_interaction_path(two_sections):
    """The lumped pantograph as scene bodies through the overlap (a penalty contact on each
    section's contact wire, the one off its wire on the wire's straight continuation past the
    anchor) against the retired interaction path (saved: interaction_reference.py): the same
    statistics over the three overlap spans, and the same share of the force between the two
    wires through the transition span. Measured at these settings (275 km/h, 20 elements per
    span): mean 0.029 N, std 0.028 N, max 0.12 N, min 0.14 N, contact loss 0.05 points apart;
    the shares 0.40 N rms and 3.1 N max apart in the transition span (the force there is up to
    330 N): the bounds are about twice these, a wrong handover moves the shares by tens of
    newtons."""
    c = REFERENCE["parameters"]
    assert (c["spans"], c["n_sections"], c["elements"], c["speed_kmh"], c["analysis_spans"]) == (6, 2, 20, 275.0, 3)
    form = two_sections
    design = form.structure.design
    panto = benchmark2015_pantograph(275.0)
    speed = 275.0 / 3.6
    target = float(panto.static_force(speed).sum())
    mb = run_scene_passage(design, lumped_fragment(panto, form=form), speed, target, elements_per_span=20,
                           analysis_spans=3, form=form, progress=False)
    a, b = REFERENCE["statistics"], mb.statistics[0]
    assert a["contact_force_std_N"] > 20.0  # a passage
    assert b["contact_force_mean_N"] == pytest.approx(a["contact_force_mean_N"], abs=0.06)
    assert b["contact_force_std_N"] == pytest.approx(a["contact_force_std_N"], abs=0.06)
    for key in ("contact_force_max_N", "contact_force_min_N"):
        assert b[key] == pytest.approx(a[key], abs=0.3)
    assert b["contact_loss_percent"] == pytest.approx(a["contact_loss_percent"], abs=0.1)
    # the handover: both wires carry force in the transition span, as on the interaction path
    rb = mb.record
    t = np.array(REFERENCE["transition_t_s"])
    assert np.all(np.diff(REFERENCE["transition_x_m"]) > 0) and len(t) > 100
    assert REFERENCE["transition_x_m"][0] == pytest.approx(4 * L, abs=1.0)
    assert REFERENCE["transition_x_m"][-1] == pytest.approx(5 * L, abs=1.0)
    shares_a = np.array(REFERENCE["transition_contact_force_wire_N"])
    shares_b = np.stack([np.interp(t, rb.t_s, rb.contact_force_wire_N[:, 0, w]) for w in range(2)], axis=1)
    assert np.all(shares_b.max(axis=0) > 20.0)  # each wire takes part
    assert np.sqrt(np.mean((shares_b - shares_a) ** 2)) < 0.8
    assert np.abs(shares_b - shares_a).max() < 6.0
    x = rb.x_contact_m[:, 0]
    before, after = x < 4 * L - 10.0, x > 5 * L + 10.0
    assert np.all(rb.contact_force_wire_N[before, 0, 1] == 0.0) and np.all(rb.contact_force_wire_N[after, 0, 0] == 0.0)
