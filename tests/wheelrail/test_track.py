"""Track layout and rail profile frames (symcat.wheelrail.track)."""
import math

import numpy as np
import pytest
from scipy.special import fresnel

from symcat.errors import ParameterError
from symcat.wheelrail.track_pieces import TrackRailFrames
from symcat.wheelrail.track import (
    UIC60_RAIL_OFFSET_M,
    Curve,
    Irregularities,
    Tangent,
    TrackLayout,
    Transition,
    rail_offset_for,
)


def _scurve(**kw):
    """Tangent, transition, right curve with cant, transition, reverse (left) curve, tangent."""
    return TrackLayout([Tangent(40.0), Transition(60.0), Curve(80.0, 300.0, "right", 0.15), Transition(70.0),
                        Curve(50.0, 500.0, "left", 0.10), Transition(40.0), Tangent(20.0)], **kw)


def _interior(track, n=40, seed=0):
    """Random positions at least 1 cm from any join (derivatives jump there)."""
    rng = np.random.default_rng(seed)
    s = rng.uniform(0.0, track.length_m, 4 * n)
    far = np.min(np.abs(s[:, None] - track.joins_m[None, :]), axis=1) > 0.01
    return s[far][:n]


def test_circle_stays_on_circle():
    track = TrackLayout([Curve(1500.0, 300.0, "left")])
    p = track.track_frame(np.linspace(0.0, 1500.0, 2001)).R
    assert np.abs(np.hypot(p[:, 0], p[:, 1] - 300.0) - 300.0).max() < 1e-9
    right = TrackLayout([Curve(900.0, 300.0, "right")], start_heading_rad=0.3)
    p = right.track_frame(np.linspace(0.0, 900.0, 501)).R
    centre = np.array([300.0 * math.sin(0.3), -300.0 * math.cos(0.3)])
    assert np.abs(np.hypot(*(p[:, :2] - centre).T) - 300.0).max() < 1e-9


def test_clothoid_matches_fresnel_and_curvature_is_linear():
    length, radius = 120.0, 300.0
    track = TrackLayout([Transition(length), Curve(30.0, radius, "left")])
    u = np.linspace(0.0, length, 301)
    a = math.sqrt(math.pi * radius * length)
    fs, fc = fresnel(u / a)
    p = track.track_frame(u).R
    assert np.abs(p[:, 0] - a * fc).max() < 1e-10
    assert np.abs(p[:, 1] - a * fs).max() < 1e-10
    np.testing.assert_allclose(track.curvature(u), u / (radius * length), atol=1e-15)
    np.testing.assert_allclose(track.heading(u), u**2 / (2 * radius * length), atol=1e-14)


def test_joins_are_continuous_in_position_and_tangent():
    track = _scurve(cant_pivot="low_rail")
    for side in ("left", "right"):
        x, pc, oc = track.piece_table(side, 5.0)
        w = np.diff(x)[:, None] ** np.arange(4)
        # Left limits at each piece's end from its Hermite cubic (exact there) against the
        # right-continuous values at the joins. (The rails' slopes kink where a cant ramp starts
        # or ends, as on real track with linear ramps, so only values are continuous.)
        f = track.rail_frame(x[1:], side)
        assert np.abs(np.einsum("nk,nkj->nj", w, pc) - f.R).max() < 1e-12
        assert np.abs(np.einsum("nk,nkij->nij", w, oc) - f.A).max() < 1e-14
    centre = _scurve()
    joins = centre.joins_m[1:-1]
    before, at = centre.track_frame(joins - 1e-7), centre.track_frame(joins)
    assert np.abs(before.R - at.R).max() < 2e-7
    assert np.abs(before.dR_ds - at.dR_ds).max() < 1e-9  # the plan tangent of the centreline
    np.testing.assert_allclose(at.A[:, :2, 0], np.column_stack([np.cos(centre.heading(joins)),
                                                                np.sin(centre.heading(joins))]), atol=1e-14)


def test_frames_are_rotations():
    track = _scurve(gradient=0.02, rail_inclination_rad=math.atan(1 / 20))
    s = np.linspace(0.0, track.length_m, 97)
    for side in ("left", "right"):
        a = track.rail_frame(s, side).A
        assert np.abs(np.einsum("nji,njk->nik", a, a) - np.eye(3)).max() < 1e-14
        np.testing.assert_allclose(np.linalg.det(a), 1.0, atol=1e-14)


def test_cant_angle_and_pivots():
    kw = dict(rail_offset_m=0.75, cant_base_m=1.5)
    s = np.array([10.0, 70.0, 140.0, 215.0, 260.0])
    centre = _scurve(**kw)
    h = centre.superelevation(s)
    np.testing.assert_allclose(h, [0.0, 0.075, 0.15, 0.15 - 0.25 * 35 / 70, -0.10], atol=1e-15)
    np.testing.assert_allclose(centre.cant_angle(s), np.arcsin(h / 1.5), atol=1e-15)
    left, right = centre.rail_frame(s, "left").R, centre.rail_frame(s, "right").R
    np.testing.assert_allclose(left[:, 2] - right[:, 2], h, atol=1e-14)  # rails 1.5 m apart
    np.testing.assert_allclose(left[:, 2] + right[:, 2], 0.0, atol=1e-14)
    low = _scurve(cant_pivot="low_rail", **kw)
    left, right = low.rail_frame(s, "left").R, low.rail_frame(s, "right").R
    np.testing.assert_allclose(np.minimum(left[:, 2], right[:, 2]), 0.0, atol=1e-14)
    np.testing.assert_allclose(left[:, 2] - right[:, 2], h, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(left - right, axis=1), 1.5, atol=1e-13)


def test_rail_frames_geometry_and_inclination():
    track = TrackLayout([Tangent(10.0)], rail_inclination_rad=math.atan(1 / 20))
    beta = math.atan(1 / 20) - math.atan(1 / 40)
    left, right = track.rail_frame(5.0, "left"), track.rail_frame(5.0, "right")
    np.testing.assert_allclose(left.R[0], [5.0, UIC60_RAIL_OFFSET_M, 0.0], atol=1e-15)
    np.testing.assert_allclose(right.R[0], [5.0, -UIC60_RAIL_OFFSET_M, 0.0], atol=1e-15)
    # The up axes lean toward the track centre.
    np.testing.assert_allclose(left.A[0][:, 2], [0.0, -math.sin(beta), math.cos(beta)], atol=1e-15)
    np.testing.assert_allclose(right.A[0][:, 2], [0.0, math.sin(beta), math.cos(beta)], atol=1e-15)
    # Profile y points to the field side on both rails.
    flat = TrackLayout([Tangent(10.0)])
    assert flat.surface_point(5.0, "left", 0.01, 0.0)[0, 1] == pytest.approx(UIC60_RAIL_OFFSET_M + 0.01)
    assert flat.surface_point(5.0, "right", 0.01, 0.0)[0, 1] == pytest.approx(-UIC60_RAIL_OFFSET_M - 0.01)


def test_rail_offset_matches_contact_geometry_convention():
    from symcat.wheelrail import uic60_canted

    assert rail_offset_for(uic60_canted()) == pytest.approx(UIC60_RAIL_OFFSET_M, abs=1e-6)


def _irregular():
    s = np.linspace(20.0, 300.0, 141)
    bump = np.sin(np.pi * (s - 20.0) / 280.0) ** 3  # tapered to zero at both ends
    return Irregularities(s, alignment_m=3e-3 * bump * np.sin(s / 7.0), level_m=2e-3 * bump * np.cos(s / 5.0),
                          cross_level_m=1e-3 * bump * np.sin(s / 11.0), gauge_m=1.5e-3 * bump * np.cos(s / 3.0))


@pytest.mark.parametrize("kw", [{}, {"cant_pivot": "low_rail", "gradient": 0.01,
                                     "rail_inclination_rad": math.atan(1 / 20)}, {"irregularities": "yes"}])
def test_derivatives_against_finite_differences(kw):
    if kw.get("irregularities"):
        kw = {"irregularities": _irregular()}
    track = _scurve(**kw)
    _assert_frame_derivatives(track, _interior(track), ("left", "right", None))


def _assert_frame_derivatives(track, s, sides, step=1e-3):
    """The rail (or, side None, track) frames' derivatives against central differences."""
    for side in sides:
        ev = track.track_frame if side is None else (lambda x: track.rail_frame(x, side))
        f, fp, fm = ev(s), ev(s + step), ev(s - step)
        for name, d in (("R", "dR_ds"), ("dR_ds", "d2R_ds2"), ("A", "dA_ds"), ("dA_ds", "d2A_ds2")):
            fd = (getattr(fp, name) - getattr(fm, name)) / (2 * step)
            exact = getattr(f, d)
            axes = tuple(range(1, exact.ndim))
            scale = np.maximum(np.sqrt((exact**2).sum(axis=axes)), 1e-3)
            err = np.sqrt(((fd - exact) ** 2).sum(axis=axes)) / scale
            assert err.max() < 1e-6, (side, d, err.max())


def test_piece_reproduces_ends_and_approximates():
    track = TrackLayout([Tangent(10.0), Transition(100.0), Curve(100.0, 300.0, "left", 0.15)])
    for s in (5.3, 57.4, 150.2):
        p = track.piece(s, "left", 1.0)
        assert p.s_start_m <= s <= p.s_end_m and p.s_end_m - p.s_start_m <= 1.0 + 1e-12
        for end in (p.s_start_m, p.s_end_m):
            f = track.rail_frame(end, "left")
            for order, (r, a) in ((0, (f.R, f.A)), (1, (f.dR_ds, f.dA_ds))):
                pr, pa = p.evaluate(end, order)
                np.testing.assert_allclose(pr, r[0], atol=1e-12)
                np.testing.assert_allclose(pa, a[0], atol=1e-13)
        inner = np.linspace(p.s_start_m, p.s_end_m, 11)
        f = track.rail_frame(inner, "left")
        pr = np.array([p.evaluate(x)[0] for x in inner])
        pa = np.array([p.evaluate(x)[1] for x in inner])
        assert np.abs(pr - f.R).max() < 1e-9  # h^4 |R''''| / 384 with |R''''| ~ kappa^3
        assert np.abs(pa - f.A).max() < 1e-9


def test_irregularities_shift_rails_as_documented():
    s = np.linspace(0.0, 100.0, 201)
    base = TrackLayout([Tangent(120.0)], rail_offset_m=0.75)
    at = np.array([30.0, 55.5])
    for name, dl, dr in (("alignment_m", (0, 1, 0), (0, 1, 0)), ("level_m", (0, 0, 1), (0, 0, 1)),
                         ("gauge_m", (0, 0.5, 0), (0, -0.5, 0)), ("cross_level_m", (0, 0, 0.5), (0, 0, -0.5))):
        irr = Irregularities(s, **{name: np.full_like(s, 2e-3)})
        track = TrackLayout([Tangent(120.0)], rail_offset_m=0.75, irregularities=irr)
        for side, d in (("left", dl), ("right", dr)):
            shift = track.rail_frame(at, side).R - base.rail_frame(at, side).R
            np.testing.assert_allclose(shift, np.tile(2e-3 * np.array(d, float), (2, 1)), atol=1e-15)
            # Zero beyond the data.
            np.testing.assert_allclose(track.rail_frame(110.0, side).R, base.rail_frame(110.0, side).R, atol=0)
    # In a canted curve they act in the canted track frame.
    irr = Irregularities(s, level_m=np.full_like(s, 1e-3))
    kw = dict(rail_offset_m=0.75)
    curved = TrackLayout([Curve(100.0, 400.0, "right", 0.12)], irregularities=irr, **kw)
    plain = TrackLayout([Curve(100.0, 400.0, "right", 0.12)], **kw)
    shift = curved.rail_frame(at, "left").R - plain.rail_frame(at, "left").R
    np.testing.assert_allclose(shift, 1e-3 * plain.track_frame(at).A[:, :, 2], atol=1e-15)


@pytest.mark.parametrize("segments, kw, words", [
    ([Curve(100.0, -300.0)], {}, "radius_m=-300"),
    ([Tangent(0.0)], {}, "length_m=0"),
    ([Curve(100.0, 300.0, "up")], {}, "direction='up'"),
    ([Tangent(10.0), Transition(10.0), Transition(10.0)], {}, "another transition"),
    ([Tangent(10.0), Curve(100.0, 300.0, "left", 0.1)], {}, "needs a Transition"),
    ([Curve(100.0, 300.0, "left", 1.6)], {}, "cant_m=1.6"),
    ([], {}, "segments=[]"),
    ([Tangent(10.0)], {"cant_pivot": "inner"}, "cant_pivot='inner'"),
    ([Tangent(10.0)], {"rail_offset_m": -0.75}, "rail_offset_m=-0.75"),
    ([Tangent(10.0)], {"gradient": 0.5}, "gradient=0.5"),
])
def test_bad_layouts(segments, kw, words):
    with pytest.raises(ParameterError, match=words.replace("[", r"\[").replace("]", r"\]")):
        TrackLayout(segments, **kw)


def test_bad_queries_and_irregularities():
    track = TrackLayout([Tangent(10.0)])
    with pytest.raises(ParameterError, match="s_m=.*0 <= s <= 10"):
        track.rail_frame(11.0, "left")
    with pytest.raises(ParameterError, match="side='middle'"):
        track.rail_frame(1.0, "middle")
    with pytest.raises(ParameterError, match="piece_length_m=0"):
        track.piece(1.0, "left", 0.0)
    with pytest.raises(ParameterError, match="s_m .irregularities."):
        Irregularities([0.0, 2.0, 1.0, 3.0], level_m=[0, 0, 0, 0])
    with pytest.raises(ParameterError, match="level_m .irregularities.*one per s_m"):
        Irregularities([0.0, 1.0, 2.0, 3.0], level_m=[0, 0, 0])


def test_synthetic_irregularities_follow_the_psd():
    from symcat.wheelrail.track import erri_b176_psd, synthetic_irregularities

    kw = dict(level="high", seed=3, taper_m=0.0, n_waves=400, spacing_m=0.5)
    a, b = synthetic_irregularities(1000.0, **kw), synthetic_irregularities(1000.0, **kw)
    s = np.linspace(0.0, 1000.0, 2001)
    np.testing.assert_array_equal(a.evaluate(s), b.evaluate(s))
    w = np.linspace(2 * np.pi / 120.0, 2 * np.pi / 1.0, 20001)
    rms = math.sqrt(np.trapezoid(erri_b176_psd(w, "high"), w))
    for column in (0, 1):
        assert np.std(a.evaluate(s)[:, column]) == pytest.approx(rms, rel=0.15)
    tapered = synthetic_irregularities(200.0, seed=1)
    np.testing.assert_allclose(tapered.evaluate([0.0, 200.0]), 0.0, atol=1e-15)
    with pytest.raises(ParameterError, match="level='medium'"):
        synthetic_irregularities(100.0, level="medium")


@pytest.mark.parametrize("pivot", ["centre", "low_rail"])
def test_smooth_cant_ramp_has_no_kinks(pivot):
    """Bloss's cubic superelevation ``h0 + (h1 - h0)(3 x^2 - 2 x^3)``: the end values of the
    linear ramp, half the cant mid-way, zero cant rate at both ends (so no kinks for the contact
    driver), and frames whose derivatives match finite differences inside the ramp."""
    segments = [Tangent(40.0), Transition(60.0, "smooth"), Curve(80.0, 300.0, "right", 0.15), Transition(70.0, "smooth"),
                Curve(50.0, 500.0, "left", 0.10), Transition(40.0, "smooth"), Tangent(20.0)]
    track = TrackLayout(segments, cant_pivot=pivot)
    linear = TrackLayout([Tangent(40.0), Transition(60.0), *segments[2:3], Transition(70.0), *segments[4:5],
                          Transition(40.0), Tangent(20.0)], cant_pivot=pivot)
    joins = track.joins_m
    np.testing.assert_allclose(track.superelevation(joins), linear.superelevation(joins), atol=1e-15)
    mid = 0.5 * (joins[1] + joins[2])
    assert track.superelevation(np.array([mid]))[0] == pytest.approx(0.075)
    h = [track.superelevation(joins[1:-1] + d) for d in (-1e-4, 0.0, 1e-4)]
    assert np.abs(h[2] - h[1]).max() < 1e-9 and np.abs(h[1] - h[0]).max() < 1e-9  # zero rate at the ends
    assert len(TrackRailFrames(track, "left").kinks_m) == 0 and len(TrackRailFrames(linear, "left").kinks_m) > 0
    _assert_frame_derivatives(track, _interior(track), ("left", None))
    with pytest.raises(ParameterError, match="cant_ramp='cubic'"):
        TrackLayout([Tangent(10.0), Transition(10.0, "cubic"), Curve(10.0, 300.0, "left", 0.1)])
