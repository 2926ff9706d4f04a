"""The wire statics apart from the form finding: closed forms, consistency, and the form finding
of both steady-arm conventions reproduced within 0.1 mm."""
import math

import numpy as np
import pytest

from symcat.catenary import benchmark2015, find_form, section_statics, span_statics
from symcat.catenary.span_statics import solve_line
from symcat.errors import ParameterError

H, Q, L = 16000.0, 10.6, 55.0


def _single_span(EI):
    """A wire pinned (no moment) at both ends of one span under its weight alone."""
    line = solve_line(np.array([0.0, L]), np.array([True]), np.array([0.0, 0.0]), np.zeros(1), np.array([Q]), H, EI,
                      periodic=False)
    return line.height(0, L / 2), line.node_force_jumps(False)[0], line.end_force()


def test_flexible_wire_sags_as_a_parabola():
    sag, start, end = _single_span(H * 1e-12)
    assert sag == pytest.approx(-Q * L**2 / (8 * H), rel=1e-9)
    assert start == pytest.approx(-Q * L / 2, rel=1e-9) and end == pytest.approx(Q * L / 2, rel=1e-9)


def test_tensioned_beam_matches_its_closed_form():
    """Mid-span deflection of a pinned tensioned beam, w = -q/H (L^2/8 - lam^2 (1 - 1/cosh(L/(2 lam))))."""
    EI = 131.7
    lam = math.sqrt(EI / H)
    sag, _, _ = _single_span(EI)
    assert sag == pytest.approx(-Q / H * (L**2 / 8 - lam**2 * (1 - 1 / math.cosh(L / (2 * lam)))), rel=1e-10)


def test_point_load_on_a_string():
    """A point load P at a on a flexible wire: deflection P a (L - a) / (H L) under it."""
    a, P = 20.0, 300.0
    line = solve_line(np.array([0.0, a, L]), np.array([True, False]), np.zeros(3), np.array([0.0, P]), np.zeros(2), H,
                      H * 1e-12, periodic=False)
    # the bending length 1e-6 m left to the string rounds the kink by (P / H) * 1e-6 m
    assert line.height(1, 0.0) == pytest.approx(-P * a * (L - a) / (H * L), abs=1e-7)


@pytest.mark.parametrize("steady_arm", ["held", "free"])
def test_an_interior_span_of_a_long_section_is_the_periodic_span(steady_arm):
    d = benchmark2015(9)
    span = span_statics(d, steady_arm)
    section = section_statics(d, steady_arm=steady_arm)
    np.testing.assert_allclose(section.dropper_length_m.reshape(9, 9)[4], span.dropper_length_m, atol=1e-9)
    np.testing.assert_allclose(section.dropper_tension_N.reshape(9, 9)[4], span.dropper_tension_N, atol=1e-6)


def test_weight_is_carried_by_the_supports():
    """Per span, the messenger support carries both wires, the clamps and the droppers less what
    the steady arm carries."""
    d = benchmark2015()
    g = d.gravity
    for steady_arm in ("held", "free"):
        s = span_statics(d, steady_arm)
        weight = (g * L * (d.contact_wire.mass_per_length + d.messenger_wire.mass_per_length)
                  + g * s.dropper_x_m.size * (d.clamp_mass_contact + d.clamp_mass_messenger)
                  + g * d.dropper_mass_per_length * s.dropper_length_m.sum())
        carried = s.messenger_support_force_N[0] + s.steady_arm_force_N[0]
        assert carried == pytest.approx(weight, rel=1e-3)  # the wires' slopes add 0.03 %
    assert span_statics(d, "free").steady_arm_force_N[0] == 0.0


@pytest.mark.parametrize("steady_arm", ["held", "free"])
def test_form_finding_matches_the_independent_statics(steady_arm):
    """Same assumptions (the model's wires with their bending stiffness): the middle span of a
    three-span section within 0.1 mm at 240 elements per span (2 mm at 60: the C1 elements round
    the messenger's kinks)."""
    d = benchmark2015(3, steady_arm=steady_arm)
    form = find_form(d, 240, progress=False)
    expected = span_statics(d)
    np.testing.assert_allclose(form.dropper_length_m.reshape(3, 9)[1], expected.dropper_length_m, atol=1e-4)
    np.testing.assert_allclose(form.dropper_tension_N.reshape(3, 9)[1], expected.dropper_tension_N, atol=0.1)
    assert form.height_error_m < 1e-8
    st = form.structure
    support_z = st.contact_wire_z(form.q)[st.cw_supports.nodes]
    assert support_z[1] == pytest.approx(expected.contact_wire_support_z_m[0], abs=1e-4)
    if steady_arm == "held":
        assert st.cw_supports.preload[1] == pytest.approx(expected.steady_arm_force_N[0], abs=0.1)


def test_free_steady_arms_carry_nothing_in_the_static_state():
    form = find_form(benchmark2015(4, steady_arm="free", dropper_statics="strings"), 20, progress=False)
    st = form.structure
    z = st.contact_wire_z(form.q)[st.cw_supports.nodes]
    np.testing.assert_array_equal(st.cw_supports.preload, 0.0)
    np.testing.assert_allclose(z, st.cw_supports.height, atol=1e-12)  # springs unloaded
    assert np.all(st.dropper_state(form.q)[2] > 0)
    np.testing.assert_allclose(form.dropper_length_m, section_statics(st.design, bending=False).dropper_length_m,
                               atol=1e-12)


def test_unknown_conventions_name_the_parameter():
    with pytest.raises(ParameterError, match="steady_arm='hung'"):
        benchmark2015(steady_arm="hung")
    with pytest.raises(ParameterError, match="dropper_statics='rods'"):
        benchmark2015(dropper_statics="rods")
    with pytest.raises(ParameterError, match="steady_arm"):
        span_statics(benchmark2015(), steady_arm="hung")
    with pytest.raises(ParameterError, match="section=3"):
        section_statics(benchmark2015(), section=3)
