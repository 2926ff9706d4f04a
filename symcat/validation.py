"""``symcat validate en50318``: run the reference model at both speeds and check the ranges.

The acceptance ranges are those of EN 50318:2002 Annex A (``symcat/reference_data/en50318.md``).
"""
from __future__ import annotations

import math

#: quantity -> {speed_kmh: (low, high)}, from EN 50318:2002 Annex A (public transcriptions).
EN50318_RANGES = {
    "contact_force_mean_N": {250: (110.0, 120.0), 300: (110.0, 120.0)},
    "contact_force_std_N": {250: (26.0, 31.0), 300: (32.0, 40.0)},
    "contact_force_stat_max_N": {250: (190.0, 210.0), 300: (210.0, 230.0)},
    "contact_force_stat_min_N": {250: (20.0, 40.0), 300: (-5.0, 20.0)},
    "contact_force_max_N": {250: (175.0, 210.0), 300: (190.0, 225.0)},
    "contact_force_min_N": {250: (50.0, 75.0), 300: (30.0, 55.0)},
    "support_uplift_max_m": {250: (0.048, 0.055), 300: (0.055, 0.065)},
    "contact_loss_percent": {250: (0.0, 0.0), 300: (0.0, 0.0)},
}


def check(summary: dict, speed_kmh: int) -> list[tuple[str, float, float, float, bool]]:
    """Rows ``(quantity, value, low, high, passed)`` of one run."""
    rows = []
    for key, ranges in EN50318_RANGES.items():
        low, high = ranges[speed_kmh]
        value = summary.get(key)
        ok = value is not None and not math.isnan(value) and low - 1e-9 <= value <= high + 1e-9
        rows.append((key, value, low, high, ok))
    return rows


def format_table(results: dict[int, list]) -> str:
    """A plain-text table of every quantity at every speed with pass/fail."""
    lines = [f"{'quantity':28s} {'speed':>6s} {'value':>10s} {'range':>19s}  result"]
    for speed, rows in results.items():
        for key, value, low, high, ok in rows:
            shown = "n/a" if value is None else f"{value:10.4g}"
            lines.append(f"{key:28s} {speed:6d} {shown:>10s} {f'{low:g} .. {high:g}':>19s}  {'pass' if ok else 'FAIL'}")
    n_fail = sum(not r[4] for rows in results.values() for r in rows)
    lines.append(f"{'all pass' if n_fail == 0 else f'{n_fail} quantities outside their range'}")
    return "\n".join(lines)


def validate_en50318(params: dict | None = None, out=None, progress: bool = True) -> tuple[str, bool, dict]:
    """Run ``en50318`` at 250 and 300 km/h; returns (table, all passed, summaries)."""
    from pathlib import Path

    from .model import run_model

    results, summaries = {}, {}
    for speed in (250, 300):
        values = {"paraview": False, "progress": progress, **(params or {}), "speed_kmh": float(speed)}
        folder = None if out is None else Path(out) / f"{speed}kmh"
        summary = run_model("en50318", values, out=folder).summary
        summaries[speed] = summary
        results[speed] = check(summary, speed)
    passed = all(r[4] for rows in results.values() for r in rows)
    return format_table(results), passed, summaries
