"""Contact geometry of a wheelset: closed forms, symmetry, an independent brute-force search,
EN 15302 reference results, bad input, and the contact_geometry model."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from symcat.errors import ParameterError
from symcat.model import run_model
from symcat.wheelrail import (
    Profile,
    TrackCrossSection,
    circular_rail,
    circular_wheel,
    coned_wheel,
    contact_geometry,
    en15302_rail_a,
    en15302_wheel_a,
    equivalent_conicity,
    gauge_point,
    profile_pair,
    uic60_canted,
)

HALF_TAPE, R0 = 0.75, 0.46
EN_GAUGE = 1.43516  # EN 15302 reference track

# EN 15302:2021 Annex J.2 (delta r [mm] against shift [mm], wheel A on rail A) and K.2 (equivalent
# conicity against amplitude), as transcribed in github.com/rohrbecka/EN15302
# (Sources/EN15302/ValidationData/WheelARailA.swift). The transcription's value at 1.7 mm repeats
# the one at 1.8 mm (a typo) and is left out.
EN_DELTA_R_MM = {
    0.1: 0.028, 0.2: 0.051, 0.3: 0.071, 0.4: 0.093, 0.5: 0.116, 0.6: 0.142, 0.7: 0.168, 0.8: 0.197, 0.9: 0.227,
    1.0: 0.259, 1.1: 0.292, 1.2: 0.327, 1.3: 0.364, 1.4: 0.402, 1.5: 0.442, 1.6: 0.484, 1.8: 0.572, 1.9: 0.619,
    2.0: 0.667, 2.1: 0.717, 2.2: 0.769, 2.3: 0.822, 2.4: 0.877, 2.5: 0.934, 2.6: 0.993, 2.7: 1.053, 2.8: 1.114,
    2.9: 1.178, 3.0: 1.243, 3.1: 1.294, 3.2: 1.349, 3.3: 1.407, 3.4: 1.469, 3.5: 1.534, 3.6: 1.603, 3.7: 1.675,
    3.8: 1.751, 3.9: 1.830, 4.0: 1.913, 4.1: 1.999, 4.2: 2.089, 4.3: 2.182, 4.4: 2.279, 4.5: 2.379, 4.6: 2.483,
    4.7: 2.591, 4.8: 2.702, 4.9: 2.817, 5.0: 2.936, 5.1: 3.058, 5.2: 3.184, 5.3: 3.314, 5.4: 3.447, 5.5: 3.584,
    5.6: 3.725, 5.7: 3.870, 5.8: 4.018, 5.9: 4.170, 6.0: 4.327, 6.1: 4.486, 6.2: 4.650, 6.3: 5.061, 6.4: 5.688,
    6.5: 6.515, 6.6: 7.590, 6.7: 9.001, 6.8: 10.940,
}
EN_CONICITY = {1.0: 0.125, 2.0: 0.155, 3.0: 0.188, 4.0: 0.216, 5.0: 0.254, 6.0: 0.303, 6.4: 0.332}


def en15302_tolerance(tan_gamma):
    """EN 15302 Annex F: +-min(0.05, 0.5 tan(gamma_e))."""
    return np.minimum(0.05, 0.5 * np.asarray(tan_gamma))


def _arcs(y, zones):
    z = np.full_like(y, np.nan)
    for lo, hi, f in zones:
        m = (y >= lo) & (y <= hi)
        z[m] = f(y[m])
    return z


def en15302_2021_profiles():
    """Wheel A and rail A from the EN 15302:2021 Annex I.2 / I.7 zone equations (mm; same
    transcription), sampled and fitted in symcat's frames: an analytic check of the pipeline."""
    def circ(c, r, yc, sign):
        return lambda y: c + sign * np.sqrt(r * r - (y - yc) ** 2)
    rail = [(-32.634, -23.2401, circ(15.899044, 13.0, -19.63949, -1)),
            (-23.2401, -7.8749, circ(80.277908, 80.0, -1.0825, -1)),
            (-7.8749, 13.0989, circ(299.48349, 300.0, 17.5966, -1)),
            (13.0989, 28.6709, circ(79.508225, 80.0, 14.29829, -1)),
            (28.6709, 39.2705, circ(13.598369, 13.0, 26.33535, -1))]
    wheel = [(-70.0, -62.7647, circ(9.51926, 20.5, -49.5, 1)),
             (-62.7647, -49.6625, circ(16.00065, 12.0, -55.0, 1)),
             (-49.6625, -39.7645, circ(8.83556, 20.0, -58.5583, 1)),
             (-39.7645, -38.7372, lambda y: -93.57685 - 2.7475 * y),
             (-38.7372, -29.4591, circ(17.64215, 14.0, -25.5816, -1)),
             (-29.4591, -10.8749, circ(97.16493, 96.76055, -2.6594, -1)),
             (-10.8749, 18.4173, circ(344.50806, 345.0, 18.4173, -1)),
             (18.4173, 30.0, lambda y: -0.49194 + 0 * y),
             (30.0, 60.0, lambda y: 1.50804 - 0.066666 * y),
             (60.0, 65.0, lambda y: 57.50808 - y)]
    yr = np.linspace(-32.6, 39.27, 3000)
    zr = -_arcs(yr, rail)  # the standard's rail z points down
    yw = np.linspace(-70.0, 65.0, 4000)
    zw = _arcs(yw, wheel)  # the standard's wheel z: toward the flange tip, i.e. the radius
    r = Profile.from_points(yr * 1e-3, (zr - zr.max()) * 1e-3, "rail", "rail A (2021)", smoothing_m=1e-8,
                            inclination_rad=math.atan(1 / 20))
    w = Profile.from_points(yw * 1e-3, zw * 1e-3, "wheel", "wheel A (2021)", smoothing_m=1e-8)
    return w, r


# ---------------------------------------------------------------- an independent brute force
def _brute_side(wpts, rpts, sign, origin, shift, phi):
    """Exact minimum vertical distance between two polylines, every vertex of either against the
    other; wheel at axle height 0. Returns (axle height to touch, rolling radius, contact angle)."""
    yw, zw = sign * (HALF_TAPE + wpts[:, 0]), -(R0 + wpts[:, 1])
    c, s = math.cos(phi), math.sin(phi)
    WY, WZ = shift + c * yw - s * zw, s * yw + c * zw
    o = np.argsort(WY)
    WY, WZ, wz_local = WY[o], WZ[o], wpts[o, 1]
    RY, RZ = sign * (origin + rpts[:, 0]), rpts[:, 1]
    o = np.argsort(RY)
    RY, RZ = RY[o], RZ[o]
    assert np.all(np.diff(WY) > 0) and np.all(np.diff(RY) > 0)  # both graphs over Y here
    zr = np.interp(WY, RY, RZ, left=np.nan, right=np.nan)
    d1 = np.where(np.isfinite(zr), WZ - zr, np.inf)
    zwr = np.interp(RY, WY, WZ, left=np.nan, right=np.nan)
    d2 = np.where(np.isfinite(zwr), zwr - RZ, np.inf)
    i1, i2 = np.argmin(d1), np.argmin(d2)
    if d1[i1] <= d2[i2]:  # a wheel vertex on a rail segment
        j = min(max(np.searchsorted(RY, WY[i1]) - 1, 0), len(RY) - 2)
        slope = (RZ[j + 1] - RZ[j]) / (RY[j + 1] - RY[j])
        return -d1[i1], R0 + wz_local[i1], math.atan(sign * slope)
    j = min(max(np.searchsorted(WY, RY[i2]) - 1, 0), len(WY) - 2)  # a rail vertex under a wheel segment
    t = (RY[i2] - WY[j]) / (WY[j + 1] - WY[j])
    slope = (WZ[j + 1] - WZ[j]) / (WY[j + 1] - WY[j])
    return -d2[i2], R0 + wz_local[j] + t * (wz_local[j + 1] - wz_local[j]), math.atan(sign * slope)


def brute_force(wheel, rail, shifts, gauge, roll, spacing=1e-5):
    """Delta r, contact angles (left, right) by polylines sampled ``spacing`` apart; the roll
    angle by Brent's method on the difference of the two wheels' touching heights."""
    wpts, rpts = wheel.sample(spacing)[1], rail.sample(spacing)[1]
    origin = 0.5 * gauge - gauge_point(rail)[0]
    out = []
    for y in shifts:
        def side(sign, phi):
            return _brute_side(wpts, rpts, sign, origin, y, phi)
        phi = brentq(lambda f: side(1.0, f)[0] - side(-1.0, f)[0], -0.02, 0.02, xtol=1e-13) if roll else 0.0
        left, right = side(1.0, phi), side(-1.0, phi)
        out.append((left[1] - right[1], left[2], right[2]))
    return np.array(out)


# ---------------------------------------------------------------- closed forms and symmetry
@pytest.mark.parametrize("gamma", [0.05, 0.025])
def test_coned_wheelset_delta_r_is_2_gamma_y(gamma):
    shifts = np.linspace(-0.01, 0.01, 41)
    for rail in (uic60_canted(), circular_rail(0.3, (-0.12, 0.05))):
        geo = contact_geometry(coned_wheel(gamma), rail, shifts, roll=False)
        np.testing.assert_allclose(geo.rolling_radius_difference_m, 2 * gamma * shifts, rtol=0, atol=1e-13)
        np.testing.assert_allclose(geo.contact_angle_rad["left"], math.atan(gamma), atol=1e-10)
        np.testing.assert_allclose(geo.contact_angle_rad["right"], math.atan(gamma), atol=1e-10)
        assert not geo.two_point["left"].any()
        c = equivalent_conicity(shifts, geo.rolling_radius_difference_m, [0.002, 0.003, 0.004])
        np.testing.assert_allclose(c, gamma, rtol=1e-6)


def test_coned_wheelset_with_roll_against_first_order_closed_form():
    # Rolling by phi moves both contact points on the rail crowns by R_rail phi toward -Y, and the
    # wheels' lowest points by r0 phi toward +Y: delta_r = 2 gamma (y + (R_rail + r0) phi). The
    # contact heights then differ by 2 gamma R_rail phi, so phi = delta_r / (2 (b + gamma R_rail)),
    # b the half distance of the contact points.
    gamma, rr = 0.05, 0.3
    shifts = np.linspace(-0.006, 0.006, 13)
    geo = contact_geometry(coned_wheel(gamma), circular_rail(rr, (-0.12, 0.05)), shifts, roll=True)
    b = geo.contact_y_m["left"][6]
    closed = 2 * gamma * shifts / (1 - gamma * (rr + R0) / (b + gamma * rr))
    np.testing.assert_allclose(geo.rolling_radius_difference_m, closed, rtol=5e-4, atol=1e-14)
    np.testing.assert_allclose(geo.roll_angle_rad, geo.rolling_radius_difference_m / (2 * (b + gamma * rr)),
                               rtol=5e-4, atol=1e-14)


def test_circular_arcs_against_exact_closed_form():
    # Hollow wheel arc R_w on rail crown R_r (internal tangency), centred contact angle d0: the line
    # of centres turns with the shift, sin(d) = sin(d0) +- y / (R_w - R_r), r = r0 + R_w (1 - cos d) + const.
    rw, rr, d0 = 0.5, 0.3, 0.05
    rail = circular_rail(rr, (-0.12, 0.05))
    gauge = 2 * (HALF_TAPE + rr * math.sin(d0) + gauge_point(rail)[0])  # centred contact at the tape circle
    shifts = np.linspace(-0.008, 0.008, 33)
    geo = contact_geometry(circular_wheel(rw, d0), rail, shifts, track=TrackCrossSection(gauge), roll=False)
    dl = np.arcsin(math.sin(d0) + shifts / (rw - rr))
    dr = np.arcsin(math.sin(d0) - shifts / (rw - rr))
    np.testing.assert_allclose(geo.rolling_radius_difference_m, rw * (np.cos(dr) - np.cos(dl)), atol=1e-11)
    np.testing.assert_allclose(geo.contact_angle_rad["left"], dl, atol=1e-9)
    np.testing.assert_allclose(geo.contact_angle_rad["right"], dr, atol=1e-9)
    # Small shifts: the classical effective conicity d0 R_w / (R_w - R_r).
    c = equivalent_conicity(shifts, geo.rolling_radius_difference_m, [0.001])
    assert c[0] == pytest.approx(d0 * rw / (rw - rr), rel=2e-3)


@pytest.mark.parametrize("pair", ["s1002_uic60", "en15302_a"])
@pytest.mark.parametrize("roll", [False, True])
def test_symmetry(pair, roll):
    p = profile_pair(pair)
    shifts = np.linspace(-0.008, 0.008, 33)
    geo = contact_geometry(p.wheel, p.rail, shifts, roll=roll)
    dr = geo.rolling_radius_difference_m
    assert dr[16] == pytest.approx(0.0, abs=1e-12)
    assert geo.contact_angle_rad["left"][16] == pytest.approx(geo.contact_angle_rad["right"][16], abs=1e-12)
    np.testing.assert_allclose(dr, -dr[::-1], atol=1e-12)
    np.testing.assert_allclose(geo.contact_angle_rad["left"], geo.contact_angle_rad["right"][::-1], atol=1e-10)
    np.testing.assert_allclose(geo.roll_angle_rad, -geo.roll_angle_rad[::-1], atol=1e-14)
    assert np.all(np.diff(dr) >= 0)  # rolling radius difference grows toward either flange


# ---------------------------------------------------------------- against the brute force
@pytest.mark.parametrize("pair, gauge", [("s1002_uic60", 1.435), ("en15302_a", EN_GAUGE)])
@pytest.mark.parametrize("roll", [False, True])
def test_against_brute_force_minimum_distance(pair, gauge, roll):
    """Main method (splines, grid search and local refinement) against the exhaustive polyline
    search at 10 um spacing, shifts -8..+8 mm. Tolerances: 5 um on delta r and 0.5 mrad on the
    contact angles (the polyline's own discretisation: about 3 um and 0.35 mrad at this spacing),
    at shifts where the best two contact candidates differ by more than 0.1 um in height (away
    from an exact contact jump, where either is right)."""
    p = profile_pair(pair)
    shifts = np.linspace(-0.008, 0.008, 33)
    geo = contact_geometry(p.wheel, p.rail, shifts, track=TrackCrossSection(gauge), roll=roll)
    bf = brute_force(p.wheel, p.rail, shifts, gauge, roll)
    clear = np.minimum(geo.gap_difference_m["left"], geo.gap_difference_m["right"]) > 1e-7
    assert clear.sum() >= 30
    assert np.abs(geo.rolling_radius_difference_m - bf[:, 0])[clear].max() < 5e-6
    assert np.abs(geo.contact_angle_rad["left"] - bf[:, 1])[clear].max() < 5e-4
    assert np.abs(geo.contact_angle_rad["right"] - bf[:, 2])[clear].max() < 5e-4


def test_two_point_contact_is_detected():
    p = profile_pair("s1002_uic60")
    shifts = np.arange(0, 13) * 5e-5
    geo = contact_geometry(p.wheel, p.rail, shifts, roll=False)
    dr = geo.rolling_radius_difference_m
    jump = int(np.argmax(np.diff(dr)))
    # S1002 on UIC60 1:40, gauge 1435 mm: the left contact jumps from the tread toward the flange
    # root at about 0.25 mm (delta r by about 0.45 mm), with two-point contact there.
    assert 0.2e-3 <= shifts[jump] <= 0.3e-3 and np.diff(dr)[jump] > 0.3e-3
    assert geo.two_point["left"][jump] and geo.two_point["left"][jump + 1]
    k = jump
    assert geo.gap_difference_m["left"][k] < 1e-5
    assert np.isfinite(geo.second_contact_angle_rad["left"][k])
    assert abs(geo.second_contact_y_m["left"][k] - geo.contact_y_m["left"][k]) > 1e-3
    assert not geo.two_point["left"][-1]


# ---------------------------------------------------------------- EN 15302
def _ref_delta_r():
    y = np.array(sorted(EN_DELTA_R_MM)) * 1e-3
    d = np.array([EN_DELTA_R_MM[k] for k in sorted(EN_DELTA_R_MM)]) * 1e-3
    return np.r_[-y[::-1], 0.0, y], np.r_[-d[::-1], 0.0, d]


def test_integration_method_reproduces_en15302_conicity_from_reference_delta_r():
    y, d = _ref_delta_r()
    amps = np.array(sorted(EN_CONICITY)) * 1e-3
    ref = np.array([EN_CONICITY[k] for k in sorted(EN_CONICITY)])
    np.testing.assert_allclose(equivalent_conicity(y, d, amps, "integration"), ref, atol=1e-3)
    np.testing.assert_allclose(equivalent_conicity(y, d, amps, "regression"), ref, atol=1e-2)


def test_en15302_2021_profiles_reproduce_annex_j_and_k():
    w, r = en15302_2021_profiles()
    y, d = _ref_delta_r()
    keep = (y > 0) & (y <= 6.15e-3)  # beyond, delta r steepens into the flange contact
    geo = contact_geometry(w, r, y[keep], track=TrackCrossSection(EN_GAUGE), roll=False)
    assert np.abs(geo.rolling_radius_difference_m - d[keep]).max() < 1e-5  # within 10 um (measured 6 um)
    shifts = np.arange(-70, 71) * 1e-4
    geo = contact_geometry(w, r, shifts, track=TrackCrossSection(EN_GAUGE), roll=False)
    amps = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]) * 1e-3
    ref = np.array([EN_CONICITY[a] for a in (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)])
    c = equivalent_conicity(shifts, geo.rolling_radius_difference_m, amps)
    np.testing.assert_allclose(c, ref, atol=2e-3)


def test_shipped_en15302_profiles_within_annex_f_tolerance():
    # The shipped data files (EN 15302:2008-era point lists) differ from the 2021 equations by a
    # few micrometres on the tread; in this conformal contact (345 mm hollow on a 300 mm crown)
    # that moves delta r by up to 0.2 mm, and the conicity by about 0.005 - well inside Annex F.
    shifts = np.arange(-70, 71) * 1e-4
    geo = contact_geometry(en15302_wheel_a(), en15302_rail_a(), shifts, track=TrackCrossSection(EN_GAUGE),
                           roll=False)
    amps = np.array([2.0, 3.0, 4.0])
    ref = np.array([EN_CONICITY[a] for a in amps])
    c = equivalent_conicity(shifts, geo.rolling_radius_difference_m, amps * 1e-3)
    assert np.all(np.abs(c - ref) <= en15302_tolerance(ref))
    assert np.abs(c - ref).max() < 0.01


# ---------------------------------------------------------------- bad input
def test_gauge_the_profiles_cannot_span():
    p = profile_pair("s1002_uic60")
    shifts = np.linspace(-0.005, 0.005, 11)
    with pytest.raises(ParameterError, match=r"gauge_m=1\.7 m.*do not meet"):
        contact_geometry(p.wheel, p.rail, shifts, track=TrackCrossSection(1.7))
    with pytest.raises(ParameterError, match=r"gauge_m=1\.4 m: too narrow"):
        contact_geometry(p.wheel, p.rail, shifts, track=TrackCrossSection(1.4))
    with pytest.raises(ParameterError, match=r"gauge_m=1\.6 m, lateral shift \+0\.00 mm.*end of the wheel profile"):
        contact_geometry(p.wheel, p.rail, shifts, track=TrackCrossSection(1.6))
    with pytest.raises(ParameterError, match="left rail: profile 'S1002' is a wheel profile"):
        contact_geometry(p.wheel, p.wheel, shifts)


# ---------------------------------------------------------------- the model
def test_model_summary_and_plot(tmp_path):
    res = run_model("contact_geometry", {"profile": "s1002_uic60"}, out=tmp_path)
    s = res.summary
    for key in ("lateral_shift_m", "rolling_radius_difference_m", "contact_angle_left_rad",
                "contact_angle_right_rad"):
        assert isinstance(s[key], list) and len(s[key]) == 201, key
    assert s["lateral_shift_m"][0] == pytest.approx(-0.01) and s["lateral_shift_m"][-1] == pytest.approx(0.01)
    assert len(s["equivalent_conicity"]) == 3 and all(0.1 < c < 0.3 for c in s["equivalent_conicity"])
    assert "wall_s" in s
    assert (tmp_path / "contact_geometry.png").stat().st_size > 10_000


def test_model_conical_and_roll():
    res = run_model("contact_geometry", {"profile": "conical", "conicity": "0.025", "max_shift_m": "0.005"})
    np.testing.assert_allclose(res.summary["equivalent_conicity"], 0.025, rtol=1e-6)
    np.testing.assert_allclose(res.summary["rolling_radius_difference_m"],
                               0.05 * np.array(res.summary["lateral_shift_m"]), atol=1e-13)
    rolled = run_model("contact_geometry", {"profile": "en15302_a", "gauge_m": "1.43516", "roll": "on"})
    assert len(rolled.summary["roll_angle_rad"]) == 201
    assert rolled.summary["equivalent_conicity"][1] == pytest.approx(0.188, abs=0.05)


def test_model_bad_gauge():
    with pytest.raises(ParameterError, match=r"gauge_m=1\.65 m"):
        run_model("contact_geometry", {"profile": "en15302_a", "gauge_m": "1.65"})
