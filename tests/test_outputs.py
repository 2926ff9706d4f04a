"""What `--out` writes for a user to read: ParaView series (point data, frames that load),
catenary plot titles and legends, merged legends of overlaid curves, the validate hint."""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from symcat.model import run_model

meshio = pytest.importorskip("meshio")


def _frames(pvd: Path) -> list[tuple[float, Path]]:
    """(time, file) of every data set of a .pvd collection (parsed as XML, as ParaView does)."""
    root = ET.parse(pvd).getroot()
    assert root.get("type") == "Collection"
    return [(float(d.get("timestep")), pvd.parent / d.get("file")) for d in root.iter("DataSet")]


# --- catenary passages ---------------------------------------------------------------------

@pytest.fixture(scope="module")
def passage(tmp_path_factory):
    out = tmp_path_factory.mktemp("en50318")
    res = run_model("en50318", {"n_spans": 5, "analysis_spans": 1, "elements_per_span": 10, "t_end": 0.1,
                                "snapshot_interval": 0.05, "progress": False}, out=out)
    return out, res.arrays["result"]


def test_passage_paraview_point_data_displacement_from_static_catenary_and_wire_id(passage):
    out, result = passage
    frames = _frames(out / "paraview" / "en50318.pvd")
    assert [t for t, _ in frames] == pytest.approx([0.0, 0.05, 0.1])
    st, line = result.form.structure, result.line
    static_cw = st.system.body_set(st.contacts[0].name).sample(line.q_static, 4)[0]
    static_mw = st.system.body_set(st.messengers[0].name).sample(line.q_static, 4)[0]
    for k, (_, path) in enumerate(frames):
        mesh = meshio.read(path)
        n = len(mesh.points)
        d, wire = mesh.point_data["displacement_m"], mesh.point_data["wire_id"]
        assert d.shape == (n, 3) and wire.shape == (n,) and np.issubdtype(wire.dtype, np.integer)
        assert set(np.unique(wire)) == {-2, -1, 0, 1}
        # kept: the cell data
        assert {"part_id", "force_N"} <= set(mesh.cell_data)
        # points minus displacement are the static catenary (no pantograph) in every frame
        np.testing.assert_allclose((mesh.points - d)[wire == 0], static_cw, atol=1e-9)
        np.testing.assert_allclose((mesh.points - d)[wire == 1], static_mw, atol=1e-9)
        cw = mesh.points[wire == 0]
        head, lift = mesh.points[wire == -2][0], d[wire == -2][0]
        assert lift[:2] == pytest.approx([0, 0]) and lift[2] > 0
        # the pan-head's displacement is the uplift of the wire it touches (it warps with it)
        assert lift[2] == pytest.approx(np.interp(head[0], cw[:, 0], d[wire == 0][:, 2]), abs=5e-3)
        if k == 0:
            # the static state with the pantograph pressing: the wire is lifted only around it
            far = np.abs(cw[:, 0] - head[0]) > 2 * st.design.span_length
            assert np.abs(d[wire == 0][far]).max() < 2e-3
            assert 5e-3 < lift[2] < 0.1


def test_passage_paraview_wire_ids_number_the_wires_of_every_tension_section(tmp_path):
    run_model("benchmark2015", {"tension_sections": 2, "n_spans": 6, "analysis_spans": 3, "elements_per_span": 6,
                                "t_end": 0.01, "snapshot_interval": 0.01, "progress": False}, out=tmp_path)
    pvd = tmp_path / "paraview" / "benchmark2015.pvd"
    mesh = meshio.read(_frames(pvd)[0][1])
    wire, part = mesh.point_data["wire_id"], mesh.cell_data["part_id"][0]
    assert set(np.unique(wire)) == {-2, -1, 0, 1, 2, 3}
    lines = mesh.cells[0].data
    # contact wires (part 0) are wire_id 0, 1; messengers (part 1) 2, 3
    assert set(wire[lines[part == 0].ravel()]) == {0, 1}
    assert set(wire[lines[part == 1].ravel()]) == {2, 3}
    assert "wire_id: 0..1 contact wires, 2..3 messengers" in pvd.read_text()


def test_catenary_plots_title_the_case_and_legend_the_marks(passage):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from symcat.interaction.output import _marks, case_title

    out, result = passage
    title = case_title(result, "en50318")
    assert "250 km/h" in title and "en50318 pantograph" in title and "penalty contact" in title
    assert "presag 55 mm" in title
    fig, ax = plt.subplots()
    _marks(ax, result, 0.0, 300.0)
    labels = ax.get_legend_handles_labels()[1]
    plt.close(fig)
    assert labels[:2] == ["support", "dropper"] and labels[2].startswith("analysis section")
    fig, ax = plt.subplots()
    _marks(ax, result, 0.0, 10.0)  # section not reached: listed, axis not stretched
    assert ax.get_legend_handles_labels()[1][-1].endswith("(not reached)") and ax.get_xlim()[1] < 20
    plt.close(fig)
    for name in ("contact_force", "panhead", "uplift_droppers"):
        assert (out / f"en50318_{name}.png").stat().st_size > 10000


# --- multibody series ----------------------------------------------------------------------

DYNAMIC = [
    ("pendulum", {"t_end": 0.2}),
    ("slider_on_wire", {"t_end": 0.1, "n_elements": 4}),
    ("seo2005_catenary", {"t_end": 0.05}),
    ("wheelset", {"t_end": 0.1}),
    ("vehicle", {"t_end": 0.05}),
    ("seo2005", {"t_end": 0.05}),
]


@pytest.mark.parametrize("name, values", [pytest.param(name, values, id=name, marks=[pytest.mark.slow] * (name == "vehicle"))
                                          for name, values in DYNAMIC])
def test_dynamic_model_writes_a_paraview_series_whose_frames_load(tmp_path, name, values):
    res = run_model(name, values, out=tmp_path)
    pvd = tmp_path / "paraview" / f"{name}.pvd"
    assert str(pvd) in map(str, res.files)
    frames = _frames(pvd)
    t_out = res.arrays["result"].t_s
    assert 2 <= len(frames) <= 200 and frames[0][0] == 0.0 and frames[-1][0] == pytest.approx(t_out[-1])
    assert np.all(np.diff([t for t, _ in frames]) > 0)
    ids = re.search(r"body_id: (.*?) -->", pvd.read_text()).group(1).split(", ")
    n_points = None
    for k, (_, path) in enumerate(frames):
        mesh = meshio.read(path)
        n_points = n_points or len(mesh.points)
        assert len(mesh.points) == n_points and np.all(np.isfinite(mesh.points))
        d, body = mesh.point_data["displacement_m"], mesh.point_data["body_id"]
        assert d.shape == (n_points, 3) and body.shape == (n_points,)
        assert set(np.unique(body)) == set(range(len(ids)))
        if k == 0:
            assert np.abs(d).max() == 0.0  # from the initial state
    # rigid bodies are boxes, ANCF wires polylines
    types = {c.type for c in mesh.cells}
    assert types <= {"line", "hexahedron"} and types
    assert ("line" in types) == (name in ("slider_on_wire", "seo2005_catenary", "seo2005"))


def test_series_subsamples_to_at_most_200_frames_first_and_last_kept():
    from symcat.results.paraview import frame_indices

    assert list(frame_indices(5)) == [0, 1, 2, 3, 4]
    idx = frame_indices(801)
    assert len(idx) == 200 and idx[0] == 0 and idx[-1] == 800 and np.all(np.diff(idx) > 0)


def test_inertia_box_has_the_body_s_inertia():
    from symcat.results.paraview import inertia_box

    m, a, b, c = 3.0, 2.0, 0.5, 0.1
    j = m / 12 * np.array([b**2 + c**2, a**2 + c**2, a**2 + b**2])
    edges, axes = inertia_box(m, np.diag(j))
    order = np.argmax(np.abs(axes), axis=0)
    assert edges[np.argsort(order)] == pytest.approx([a, b, c])
    assert np.linalg.det(axes) == pytest.approx(1.0)
    rod, _ = inertia_box(1.0, (1e-4 / 12, 1 / 12, 1 / 12))  # slender rod: its length, min 2 % thick
    assert sorted(rod) == pytest.approx([0.02, 0.02, 1.0], rel=1e-3)


# --- overlaid curves (vehicle plots) -------------------------------------------------------

def test_identical_curves_are_grouped_within_a_tolerance_of_their_range():
    from symcat.results.timeseries import identical_groups, repeats

    t = np.linspace(0, 1, 50)
    a = np.sin(6 * t)
    curves = {"b1_ws1": a, "b1_ws2": 0.5 * a, "b2_ws1": a + 1e-4, "b2_ws2": 0.5 * a - 1e-5}
    groups = identical_groups(curves)
    assert groups == [["b1_ws1", "b2_ws1"], ["b1_ws2", "b2_ws2"]]
    assert repeats(groups, "b1", "b2")
    apart = identical_groups({**curves, "b2_ws2": 0.5 * a + 0.05})
    assert apart == [["b1_ws1", "b2_ws1"], ["b1_ws2"], ["b2_ws2"]] and not repeats(apart, "b1", "b2")
    # NaNs in the same places (Y/Q without load) still match; elsewhere they do not
    nan = a.copy()
    nan[3] = np.nan
    assert identical_groups({"x": nan, "y": nan.copy(), "z": a}) == [["x", "y"], ["z"]]
    assert identical_groups({"c": np.ones(3), "d": np.ones(3)}) == [["c", "d"]]  # flat curves
    # a bogie 2 curve on another bogie 1 wheelset's is not bogie 2 repeating bogie 1
    assert not repeats([["b1_ws1", "b2_ws2"], ["b1_ws2", "b2_ws1"]], "b1", "b2")


def test_merged_legend_lists_one_entry_per_visible_line():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from symcat.results.timeseries import plot_merged

    t = np.linspace(0, 1, 20)
    fig, ax = plt.subplots()
    plot_merged(ax, t, {"b1_ws1_left": t, "b1_ws1_right": -t, "b2_ws1_left": t.copy(), "b2_ws1_right": -t})
    assert ax.get_legend_handles_labels()[1] == ["b1_ws1_left = b2_ws1_left", "b1_ws1_right = b2_ws1_right"]
    assert len(ax.lines) == 2
    plt.close(fig)


# --- symcat validate en50318 ---------------------------------------------------------------

def _rows(ok: bool, value=1.0):
    return {250: [("contact_force_std_N", value, 0.0, 2.0, True), ("support_uplift_max_m", value, 0.0, 2.0, ok)]}


def test_validate_hint_names_presag_and_the_documented_passing_command():
    from symcat.model import load_model
    from symcat.validation import passing_presags, presag_hint

    model = load_model("en50318")
    passing = passing_presags(model.run.__globals__["__doc__"])
    assert passing == [20.0]  # the table in models/en50318.py
    hint = presag_hint(_rows(False), 55.0, 55.0, passing)
    assert hint.startswith("the failing quantities hinge on presag_mm (55 mm here, an assumption: public data give "
                           "55 mm as a maximum)")
    assert "`symcat validate en50318 --set presag_mm=20` passes every quantity at both speeds" in hint
    assert "set here" not in hint
    assert "set here: elements_per_span" in presag_hint(_rows(False), 55.0, 55.0, passing, ["elements_per_span"])
    assert presag_hint(_rows(True), 55.0, 55.0, passing) == ""           # all pass
    assert presag_hint(_rows(False), 20.0, 55.0, passing) == ""          # presag set by the user
    assert presag_hint(_rows(False, None), 55.0, 55.0, passing) == ""    # no value (run cut short)


def test_validate_prints_the_hint_under_the_unchanged_table():
    """End to end at coarse settings (two short passages, a few seconds): quantities fail."""
    from symcat.validation import validate_en50318

    params = {"n_spans": 5, "analysis_spans": 1, "elements_per_span": 10, "dt": 0.002}
    text, passed, _ = validate_en50318(params, progress=False)
    lines = text.splitlines()
    assert not passed
    assert lines[0].startswith("quantity") and len(lines) == 1 + 16 + 1 + 2
    assert lines[17].endswith("quantities outside their range")
    assert lines[18].startswith("the failing quantities hinge on presag_mm (55 mm here")
    assert "--set presag_mm=20` passes" in lines[19] and "set here: n_spans, analysis_spans" in lines[19]
