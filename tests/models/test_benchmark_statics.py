"""The benchmark2015 model's statics against the benchmark's published dropper lengths (issue 30)."""
import numpy as np
import pytest

from symcat.catenary import benchmark2015, benchmark2015_dropper_lengths, find_form, span_statics
from symcat.model import run_model

PUBLISHED = benchmark2015_dropper_lengths()


@pytest.fixture(scope="module")
def statics():
    """The model's static state at its defaults and in the earlier convention (form finding only)."""
    out = {}
    for name, params in (("default", {}), ("held_wires", {"steady_arm": "held", "dropper_statics": "wires"})):
        res = run_model("benchmark2015", {"t_end": 0.0, "progress": False, **params})
        out[name] = res
    return out


def test_published_data_are_the_benchmark_span():
    d = benchmark2015()
    np.testing.assert_allclose(PUBLISHED["position_m"], d.dropper_positions)
    np.testing.assert_allclose(PUBLISHED["presag_m"], d.presag)


def test_default_dropper_lengths_match_the_published_ones(statics):
    """Within 2 mm (1.4 mm at worst): the published values are in 1 mm steps and their own
    spread about any smooth statics is about 1 mm, so 1 mm cannot be asked for."""
    lengths = np.array(statics["default"].summary["dropper_lengths_m"])
    assert np.abs(lengths - PUBLISHED["length_m"]).max() < 2e-3
    assert abs(np.mean(lengths - PUBLISHED["length_m"])) < 1e-3


def test_earlier_convention_is_13_to_15_mm_longer(statics):
    lengths = np.array(statics["held_wires"].summary["dropper_lengths_m"])
    diff = lengths - PUBLISHED["length_m"]
    assert 12e-3 < diff.min() and diff.max() < 16e-3


def test_independent_statics_explains_the_published_lengths():
    """Flexible wires, free steady arms: the benchmark's convention, without the form finding."""
    s = span_statics(benchmark2015(), steady_arm="free", bending=False)
    assert np.abs(s.dropper_length_m - PUBLISHED["length_m"]).max() < 1.5e-3
    held = span_statics(benchmark2015(), steady_arm="held", bending=True)
    assert np.abs(held.dropper_length_m - PUBLISHED["length_m"]).min() > 10e-3


@pytest.fixture(scope="module")
def central_heights():
    """Contact-wire height minus design height at the droppers of the central spans (5 and 6
    of 10, the analysis section) at the model's mesh (m), per convention."""
    out = {}
    for steady_arm, dropper_statics in (("free", "strings"), ("held", "wires")):
        form = find_form(benchmark2015(10, steady_arm, dropper_statics), 60, progress=False)
        st = form.structure
        dz = (st.contact_wire_z(form.q) - st.target_z)[st.dropper_nodes]
        out[steady_arm] = dz.reshape(10, 9)[4:6].ravel()
    return out


def test_contact_wire_keeps_the_presag(central_heights):
    """Strings droppers on the model's wires, stiff in bending, lift the contact wire as a whole
    (about 7 mm at 60 elements per span); the presag, its height below the end droppers, stays
    within 1 mm of the target. The earlier convention holds the design heights themselves."""
    lift = central_heights["free"]
    assert 2e-3 < lift.mean() < 10e-3
    assert np.abs(lift - lift.mean()).max() < 1e-3
    assert np.abs(central_heights["held"]).max() < 1e-6
