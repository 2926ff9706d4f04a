"""Lines of several tension sections: overlap geometry, form finding and the pan-head handover."""
from dataclasses import replace

import numpy as np
import pytest

from symcat.catenary import benchmark2015, find_form
from symcat.errors import ParameterError
from symcat.interaction.coupled import CoupledLine, PantographRun
from symcat.interaction.passage import run_passage
from symcat.interaction.statistics import lowpass
from symcat.pantograph import benchmark2015_pantograph

L = 55.0


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


def test_quasi_static_handover_matches_statics(two_sections):
    """A slow passage through the overlap shares the force between the wires as a sequence of
    static equilibria does (two independent computations: Newton statics against generalized-
    alpha dynamics filtered at 2 Hz)."""
    form = two_sections
    # dampers on the stages: without them the frame's 0.4 Hz bounce passes any low-pass filter
    panto = replace(benchmark2015_pantograph(100), damping=(100.0, 0.0, 45.0))
    run = run_passage(form.structure.design, [panto], 10.0, analysis_spans=1, lead_in=20.0, form=form,
                      t_end=75.0 / 10.0, progress=False)
    rec = run.record
    x = rec.x_contact_m[:, 0]
    xs = np.arange(226.0, 274.0, 4.0)
    shares = np.stack([lowpass(rec.t_s, rec.contact_force_wire_N[:, 0, w], 2.0) for w in range(2)], axis=1)
    dynamic = np.array([shares[np.argmin(np.abs(x - xi))] for xi in xs])
    assert rec.stats["halvings"] == 0

    static = []  # the same pantograph (same reference height) standing at each position
    for xi in xs:
        line = CoupledLine(form, [PantographRun(panto, xi)], 10.0)
        y, fc = line.static_state(z_ref=run.line.z_ref)
        static.append(line.per_wire(line.contact_states(y, np.zeros(line.n), 0.0), fc)[0])
    static = np.array(static)
    total = static.sum(axis=1)
    assert total == pytest.approx(panto.static_force(10.0).sum(), rel=0.1)  # the frame spring (160 N/m) acts
    both = (static > 5.0).all(axis=1)
    assert both.sum() >= 4  # the pan-head presses on both wires over several metres
    assert np.all(np.diff(static[:, 1]) >= -1e-6)  # the new wire takes over monotonically
    # measured 4.6 N where the share changes fastest (17 N over 4 m: the 2 Hz filter smears it)
    assert np.abs(dynamic - static).max() < 0.08 * total.max()
    assert rec.stats["halvings"] == 0


def test_overlap_bad_inputs(two_sections):
    panto = benchmark2015_pantograph(100)
    with pytest.raises(ParameterError, match="bilateral"):
        CoupledLine(two_sections, [PantographRun(panto, 100.0)], 10.0, contact="bilateral")
    with pytest.raises(ParameterError, match="n_spans"):
        benchmark2015(5).with_(n_sections=2)
    with pytest.raises(ParameterError, match="overlap_raise"):
        benchmark2015(6).with_(n_sections=2, overlap_raise=0.5)
    with pytest.raises(ParameterError, match="overlap_raise"):  # lift too steep: droppers would push
        find_form(benchmark2015(6).with_(n_sections=2, overlap_raise=0.235), 10)
    with pytest.raises(ParameterError, match="n_sections"):
        benchmark2015(6).with_(n_sections=0)


def test_overlap_on_the_multibody_path_matches_the_interaction_path(two_sections):
    """The lumped pantograph as scene bodies through the overlap (the shared multibody path: a
    penalty contact on each section's contact wire, the one off its wire on the wire's straight
    continuation past the anchor) against the interaction path: the same statistics over the
    three overlap spans, and the same share of the force between the two wires through the
    transition span. Measured at these settings (275 km/h, 20 elements per span): mean 0.029 N,
    std 0.028 N, max 0.12 N, min 0.14 N, contact loss 0.05 points apart; the shares 0.40 N rms
    and 3.1 N max apart in the transition span (the force there is up to 330 N): the bounds
    are about twice these, a wrong handover moves the shares by tens of newtons."""
    from symcat.interaction.scene_passage import lumped_fragment, run_scene_passage

    form = two_sections
    design = form.structure.design
    panto = benchmark2015_pantograph(275.0)
    speed = 275.0 / 3.6
    ip = run_passage(design, [panto], speed, elements_per_span=20, analysis_spans=3, form=form, progress=False)
    target = float(panto.static_force(speed).sum())
    mb = run_scene_passage(design, lumped_fragment(panto, form=form), speed, target, elements_per_span=20,
                           analysis_spans=3, form=form, progress=False)
    a, b = ip.statistics[0], mb.statistics[0]
    assert a["contact_force_std_N"] > 20.0  # a passage
    assert b["contact_force_mean_N"] == pytest.approx(a["contact_force_mean_N"], abs=0.06)
    assert b["contact_force_std_N"] == pytest.approx(a["contact_force_std_N"], abs=0.06)
    for key in ("contact_force_max_N", "contact_force_min_N"):
        assert b[key] == pytest.approx(a[key], abs=0.3)
    assert b["contact_loss_percent"] == pytest.approx(a["contact_loss_percent"], abs=0.1)
    # the handover: both wires carry force in the transition span, as on the interaction path
    ra, rb = ip.record, mb.record
    shares_b = np.stack([np.interp(ra.t_s, rb.t_s, rb.contact_force_wire_N[:, 0, w]) for w in range(2)], axis=1)
    shares_a = ra.contact_force_wire_N[:, 0, :]
    x = ra.x_contact_m[:, 0]
    transition = (x > 4 * L) & (x < 5 * L)
    assert np.all(shares_b[transition].max(axis=0) > 20.0)  # each wire takes part
    assert np.sqrt(np.mean((shares_b - shares_a)[transition] ** 2)) < 0.8
    assert np.abs(shares_b - shares_a)[transition].max() < 6.0
    before, after = x < 4 * L - 10.0, x > 5 * L + 10.0
    assert np.all(shares_b[before, 1] == 0.0) and np.all(shares_b[after, 0] == 0.0)
