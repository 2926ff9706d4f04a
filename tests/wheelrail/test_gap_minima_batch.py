"""The vectorised search for gap minima (all wheels at once, the profiles' lean piecewise cubic,
a screened three-angle search) against the straightforward one, wheel by wheel: mixed
profiles, yawed wheelsets, flange contact and curved track in one batch."""
from __future__ import annotations

import math

import numpy as np
import pytest

from symcat.scene.rigid import euler_parameters
from symcat.vehicle import wheelset_on_track
from symcat.wheelrail import profile_pair
from symcat.wheelrail.constraint_contact import WheelRailContact, _rotation
from symcat.wheelrail.gap_minima import gap_minima, gap_minima_batch
from symcat.wheelrail.track import Curve, TrackLayout, rail_offset_for

BAND_M = 5e-4


def _reference_minima(contact, q, band_m, grid_m=2.5e-4, near=None, known=None):
    """Every circle (scipy's spline for the wheel, the contact's own vertical gap) at its bottom
    and, by a parabola through three angles, off it, without screening; local minima within the
    band refined by Newton."""
    a = _rotation(q[3:7])
    s_axle = contact.frames.project(q[None, :3])
    w = a.T @ contact.frames.up(s_axle)
    bottom = math.atan2(-w[0], w[2])
    lo, hi = contact.wheel.s_min, contact.wheel.s_max
    grid = np.linspace(lo, hi, max(int(math.ceil((hi - lo) / grid_m)), 8) + 1)
    if near is not None:
        grid = np.union1d(grid, np.clip(near + np.arange(-1.5e-3, 1.5e-3 + 1e-9, 2e-5), lo, hi))
    pw = contact.wheel.position(grid)

    def clearance(angle):
        g, s2r, s1r = contact._vertical_gap(q, a, np.broadcast_to(angle, grid.shape), grid, s_axle, pw)
        return np.nan_to_num(g, nan=np.inf), s2r, s1r

    gap, s2r, s1r = clearance(bottom)
    step = 0.05
    g_minus, g_plus = clearance(bottom - step)[0], clearance(bottom + step)[0]
    with np.errstate(invalid="ignore", divide="ignore"):
        curv = g_minus + g_plus - 2 * gap
        shift = np.where(curv > 0, 0.5 * step * (g_minus - g_plus) / curv, 0.0)
    angle = bottom + np.clip(np.nan_to_num(shift), -3 * step, 3 * step)
    g_off, r2_off, r1_off = clearance(angle)
    lower = np.isfinite(g_off) & (g_off < gap)
    gap, s2r, s1r = np.where(lower, g_off, gap), np.where(lower, r2_off, s2r), np.where(lower, r1_off, s1r)
    s2w = np.where(lower, angle, bottom)
    points = []
    for j in range(len(grid)):
        left = gap[j - 1] if j else np.inf
        right = gap[j + 1] if j + 1 < len(grid) else np.inf
        if not (gap[j] <= left and gap[j] <= right and gap[j] <= gap.min() + band_m):
            continue
        if known is not None and abs(grid[j] - known) <= 1.5 * 2e-5:
            continue
        try:
            p = contact.solve(q, np.array([grid[j], s2w[j], s1r[j], s2r[j]]), local=True)
        except Exception:
            continue
        if all(abs(p.s[0] - o.s[0]) > 1e-6 for o in points):
            points.append(p)
    return sorted(points, key=lambda p: p.gap_m)


def _yawed(placed, yaw_rad):
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ placed.rotation
    return np.r_[placed.position_m, euler_parameters(rotation)]


@pytest.fixture(scope="module")
def wheels():
    """(contact, q, near, known) of eight wheels: S1002 at its conformal centre (two minima on the
    left) and on its flange, EN 15302 lifted by 1 mm (each wheel's band is its own), and S1002 in a
    canted curve, each yawed."""
    out = []
    s1002, en15302 = profile_pair("s1002_uic60", 0.05), profile_pair("en15302_a", 0.05)
    layout = TrackLayout([Curve(60.0, 300.0, "left", 0.1)], rail_offset_m=rail_offset_for(s1002.rail))
    cases = [(s1002, None, 0.0003, 0.004, 0.0), (s1002, None, 0.0075, -0.02, 0.0), (en15302, None, 0.004, 0.01, 1e-3),
             (s1002, layout, 0.002, 0.003, 0.0)]
    for pair, track, shift, yaw, lift in cases:
        kw = {"track": track, "x_m": 30.0} if track is not None else {}
        placed = wheelset_on_track(pair.wheel, pair.rail, shift, **kw)
        q = _yawed(placed, yaw)
        q[2] += lift
        for side in ("left", "right"):
            contact = WheelRailContact(pair.wheel, pair.rail, side, track=track)
            near = placed.contacts[side].s[0]
            out.append((contact, q, near, near if side == "right" and track is None else None))
    return out


def test_the_batch_finds_the_straightforward_minima(wheels):
    found = gap_minima_batch([w[0] for w in wheels], [w[1] for w in wheels], BAND_M,
                             nears=[w[2] for w in wheels], knowns=[w[3] for w in wheels])
    counts = []
    for (contact, q, near, known), points in zip(wheels, found):
        ref = _reference_minima(contact, q, BAND_M, near=near, known=known)
        counts.append(len(points))
        assert len(points) == len(ref)
        for a, b in zip(points, ref):
            np.testing.assert_allclose(a.s[[0, 2, 3]], b.s[[0, 2, 3]], rtol=0, atol=1e-10)
            assert math.remainder(a.s[1] - b.s[1], 2 * math.pi) == pytest.approx(0.0, abs=1e-10)
            assert a.gap_m == pytest.approx(b.gap_m, abs=1e-12)
    assert max(counts) >= 2 and sum(counts) > len(wheels) - 4  # rivals, and the known points left out


def test_one_wheel_alone_is_its_part_of_the_batch(wheels):
    """The wheels of a batch do not interact: each alone gives the same bits."""
    args = ([w[0] for w in wheels], [w[1] for w in wheels])
    nears = [w[2] for w in wheels]
    found = gap_minima_batch(*args, BAND_M, nears=nears)
    for (contact, q, near, _), points in zip(wheels, found):
        alone = gap_minima(contact, q, BAND_M, near=near)
        assert [p.s.tolist() for p in alone] == [p.s.tolist() for p in points]
        assert [p.gap_m for p in alone] == [p.gap_m for p in points]


def test_a_wheel_off_its_rail_fails_alone(wheels):
    """A wheel with no circle above its rail gets its SolverError; the others their minima."""
    contact, q, near, _ = wheels[0]
    lifted = q.copy()
    lifted[1] += 0.5  # half a metre to the side: off the rail
    found = gap_minima_batch([contact, contact], [lifted, q], BAND_M, nears=[None, near])
    assert type(found[0]).__name__ == "SolverError" and len(found[1]) >= 1
