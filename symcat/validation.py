"""``symcat validate en50318``: run the reference model at both speeds and check the ranges.

The acceptance ranges are those of EN 50318:2002 Annex A (``symcat/reference_data/en50318.md``).
The reference catenary's presag and dropper layout of Annex A are not in the public record
(issue 30): the presag is an assumption, and the output always says so and which value it used.
When quantities fail at the default presag, lines under the table name the presag as the
parameter they hinge on and the command that passes, read from the presag table of
``models/en50318.py`` (:func:`presag_hint`); otherwise one line states the presag used
(:func:`presag_statement`).
"""
from __future__ import annotations

import math
import re

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


def passing_presags(doc: str) -> list[float]:
    """Presags (mm) of the rows of the presag table in ``models/en50318.py``'s docstring
    (``| presag | 250 km/h | 300 km/h |``) that read "all in range" at both speeds."""
    found = []
    for line in doc.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        match = re.match(r"([0-9.]+) mm", cells[0]) if len(cells) == 3 else None
        if match and cells[1] == cells[2] == "all in range":
            found.append(float(match.group(1)))
    return found


def presag_hint(results: dict[int, list], presag_mm: float, default_mm: float, passing_mm: list[float],
                changed: list[str] = ()) -> str:
    """Lines printed under the table when quantities with a value fail at the default presag:
    what they hinge on and the documented command that passes (``passing_mm``, from
    :func:`passing_presags`); ``changed`` names the other parameters the user set. Empty
    otherwise."""
    failing = any(not r[4] and r[1] is not None for rows in results.values() for r in rows)
    if not failing or presag_mm != default_mm:
        return ""
    text = (f"the failing quantities hinge on presag_mm ({presag_mm:g} mm here, an assumption: public data give "
            f"{default_mm:g} mm as a maximum); {ANNEX_A_PRESAG}")
    if passing_mm:
        text += (f";\n`symcat validate en50318 --set presag_mm={passing_mm[0]:g}` passes every quantity at both speeds "
                 "(table in models/en50318.py")
        text += f", with the other parameters at their defaults; set here: {', '.join(changed)})" if changed else ")"
    return text


#: What the public record holds of the reference catenary's presag (issue 30's search).
ANNEX_A_PRESAG = "the standard's own presag and dropper layout (Annex A) are not in the public record"


def presag_statement(presag_mm: float, default_mm: float) -> str:
    """The line under the table when :func:`presag_hint` has nothing to say: the presag this
    validation used (mm at mid-span) is an assumption."""
    which = "the model's default" if presag_mm == default_mm else f"set here; the default is {default_mm:g} mm"
    return (f"presag_mm = {presag_mm:g} mm ({which}) is an assumption: {ANNEX_A_PRESAG}; public data give "
            f"{default_mm:g} mm as a maximum, and the statistics depend on it (models/en50318.py)")


def closing_lines(results: dict[int, list], presag_mm: float, default_mm: float, passing_mm: list[float],
                  changed: list[str] = ()) -> str:
    """What follows the table: the presag hint when quantities fail at the default presag
    (:func:`presag_hint`), else the presag statement (:func:`presag_statement`)."""
    return presag_hint(results, presag_mm, default_mm, passing_mm, changed) or presag_statement(presag_mm, default_mm)


def validate_en50318(params: dict | None = None, out=None, progress: bool = True) -> tuple[str, bool, dict]:
    """Run ``en50318`` at 250 and 300 km/h; returns (table, all passed, summaries). Under the
    table: when quantities fail at the default presag, the presag as the parameter they hinge
    on and the documented command that passes (:func:`presag_hint`); otherwise the presag used
    and that it is an assumption (:func:`presag_statement`)."""
    from pathlib import Path

    from .model import load_model, run_model

    model = load_model("en50318")
    results, summaries = {}, {}
    for speed in (250, 300):
        values = {"paraview": False, "progress": progress, **(params or {}), "speed_kmh": float(speed)}
        folder = None if out is None else Path(out) / f"{speed}kmh"
        summary = run_model(model, values, out=folder).summary
        summaries[speed] = summary
        results[speed] = check(summary, speed)
    passed = all(r[4] for rows in results.values() for r in rows)
    table = format_table(results)
    changed = [k for k in (params or {}) if k not in ("presag_mm", "paraview", "progress", "speed_kmh")]
    lines = closing_lines(results, model.resolve(params)["presag_mm"], model.parameter("presag_mm").default,
                          passing_presags(model.run.__globals__.get("__doc__") or ""), changed)
    return table + "\n" + lines, passed, summaries
