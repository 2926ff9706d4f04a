"""The catenary as built: sampled dropper, support and contact-wire height errors on a form-found line."""
from __future__ import annotations

import numpy as np
import pytest

from symcat.catenary import benchmark2015, find_form
from symcat.catenary.deviations import Deviations, build_as_built, irregularity_profile, sample_errors
from symcat.errors import ParameterError
from symcat.model import run_model

#: A short, coarse benchmark line, static state only: the deviations, not the dynamics, are tested.
SMALL = dict(elements_per_span=10, n_spans=4, analysis_spans=1, t_end=0, progress=False)


@pytest.fixture(scope="module")
def design():
    return benchmark2015(4)


def test_irregularity_has_the_variance_and_correlation_of_its_spectrum():
    """The exponential autocorrelation R(s) = sigma^2 exp(-s/L) of the first-order PSD."""
    x = np.arange(0.0, 200000.0, 2.0)
    e = irregularity_profile(x, 0.004, 10.0, np.random.default_rng(1))
    assert np.std(e) == pytest.approx(0.004, rel=0.03)
    lag = 5  # 10 m = L
    r = np.mean(e[:-lag] * e[lag:]) / np.var(e)
    assert r == pytest.approx(np.exp(-1.0), abs=0.02)
    # positions given twice (an overlap's two wires) get one value; zero RMS gives none
    twice = irregularity_profile(np.array([3.0, 1.0, 3.0]), 0.01, 10.0, np.random.default_rng(2))
    assert twice[0] == twice[2] != twice[1]
    assert not np.any(irregularity_profile(x[:10], 0.0, 10.0, np.random.default_rng(3)))


def test_errors_come_from_the_seed_and_each_kind_from_its_own_stream(design):
    st = find_form(design, 10, progress=False).structure
    a = sample_errors(st, Deviations(0.005, 0.003, 0.0, seed=7))
    b = sample_errors(st, Deviations(0.005, 0.003, 0.0, seed=7))
    c = sample_errors(st, Deviations(0.005, 0.003, 0.0, seed=8))
    np.testing.assert_array_equal(a.dropper_length, b.dropper_length)
    assert not np.allclose(a.dropper_length, c.dropper_length)
    assert a.dropper_length.shape == st.dropper_nodes.shape
    assert a.steady_arm_height.shape == a.messenger_support_height.shape == st.cw_supports.nodes.shape
    # doubling the dropper error leaves the support errors as they were
    d = sample_errors(st, Deviations(0.010, 0.003, 0.0, seed=7))
    np.testing.assert_allclose(d.dropper_length, 2 * a.dropper_length)
    np.testing.assert_array_equal(d.steady_arm_height, a.steady_arm_height)
    # the irregularity shortens the droppers where it raises the wire
    e = sample_errors(st, Deviations(0.0, 0.0, 0.004, seed=7))
    np.testing.assert_allclose(e.dropper_length, -e.irregularity_at_droppers)


def test_built_line_moves_the_contact_wire_by_about_the_dropper_errors(design):
    form = find_form(design, 10, progress=False)
    z_design = form.structure.contact_wire_z(form.q)[form.structure.dropper_nodes].copy()
    length_design = form.dropper_length_m.copy()
    built, summary = build_as_built(form, Deviations(dropper_length_sd=0.005, seed=1))
    st = built.structure
    dl = built.dropper_length_m - length_design
    assert np.std(dl) == pytest.approx(0.005, rel=0.4)
    dz = st.contact_wire_z(built.q)[st.dropper_nodes] - z_design
    # a longer dropper lowers the wire: the height changes follow the length errors
    assert np.corrcoef(dl, -dz)[0, 1] > 0.5
    assert summary["as_built_height_rms_m"] == pytest.approx(np.sqrt(np.mean(dz**2)))
    np.testing.assert_allclose(st.forces(built.q)[st.free], 0.0, atol=1e-5 * np.abs(st._f_ext).max())


def test_model_runs_are_reproducible_and_unchanged_without_deviations():
    plain = run_model("benchmark2015", SMALL).summary
    assert "as_built_height_rms_m" not in plain
    errs = {"dropper_length_sd_m": 0.005, "support_height_sd_m": 0.003, "contact_wire_irregularity_m": 0.004}
    a = run_model("benchmark2015", {**SMALL, **errs, "deviation_seed": 3}).summary
    b = run_model("benchmark2015", {**SMALL, **errs, "deviation_seed": 3}).summary
    c = run_model("benchmark2015", {**SMALL, **errs, "deviation_seed": 4}).summary
    assert a["dropper_lengths_m"] == b["dropper_lengths_m"] != c["dropper_lengths_m"]
    assert a["dropper_lengths_m"] != plain["dropper_lengths_m"]
    assert 0 < a["as_built_height_rms_m"] < 0.05


def test_the_multibody_path_runs_on_the_same_as_built_catenary():
    """The lumped and the four-body pantograph as scene bodies, the same deviations and seed:
    the same built line (its realized errors and dropper lengths), whatever runs on it, and
    each pantograph pressing with the static contact force on it."""
    errs = {"dropper_length_sd_m": 0.005, "support_height_sd_m": 0.003, "deviation_seed": 5, "t_end": 0.0,
            "elements_per_span": 10, "n_spans": 5, "progress": False, "paraview": False}
    a = run_model("en50318", {**errs, "pantograph": "seo2005"}).summary
    b = run_model("en50318", {**errs, "pantograph": "lumped"}).summary
    for key in ("as_built_height_rms_m", "as_built_height_max_m", "as_built_dropper_error_rms_m", "dropper_lengths_m"):
        assert a[key] == b[key], key
    assert a["as_built_height_rms_m"] > 0
    for s in (a, b):
        assert s["static_contact_force_N"] == pytest.approx(120.0, rel=1e-5)


def test_deviations_refused_where_they_cannot_be_built(design):
    with pytest.raises(ParameterError, match=r"dropper_length_sd_m=-0.001 m: must be a number >= 0 and <= 0.1"):
        run_model("benchmark2015", {"dropper_length_sd_m": -0.001})
    with pytest.raises(ParameterError, match=r"dropper_length_sd_m=1 m, .* make a dropper length <= 0"):
        build_as_built(find_form(design, 10, progress=False), Deviations(dropper_length_sd=1.0, seed=1))
