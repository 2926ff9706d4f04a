"""The reading of bench/peers' ratios off two work-precision curves (no Exudyn needed)."""
import numpy as np
import pytest

from bench.peers.common import Point, pareto, ratios, wall_at_error


def _curve(code, walls, errors):
    return [Point(code, f"p{k}", e, [w]) for k, (w, e) in enumerate(zip(walls, errors))]


def test_pareto_front_drops_points_beaten_in_time_and_error():
    points = _curve("a", [1.0, 2.0, 3.0, 4.0], [1e-2, 1e-3, 5e-3, 1e-4])
    points.append(Point("a", "failed", np.nan, [0.5]))
    np.testing.assert_allclose(pareto(points), [[1.0, 1e-2], [2.0, 1e-3], [4.0, 1e-4]])


def test_wall_at_error_interpolates_in_log_log_and_not_beyond_the_curve():
    front = np.array([[1.0, 1e-2], [4.0, 1e-4]])  # wall ~ error^(-1/3.32...): a straight line in log-log
    assert wall_at_error(front, 1e-3) == pytest.approx(2.0)
    assert np.isnan(wall_at_error(front, 1e-1)) and np.isnan(wall_at_error(front, 1e-5))


def test_ratio_of_a_curve_twice_as_slow_is_two_where_the_errors_overlap():
    fast = _curve("Exudyn", [1.0, 2.0, 4.0], [1e-2, 1e-3, 1e-4])
    slow = _curve("symcat", [2.0, 4.0, 8.0, 16.0], [1e-2, 1e-3, 1e-4, 1e-5])
    rows = ratios(slow, fast)
    assert [r[0] for r in rows] == pytest.approx([1e-2, 1e-3, 1e-4])  # 1e-5: beyond Exudyn's curve
    assert [r[3] for r in rows] == pytest.approx([2.0, 2.0, 2.0])
