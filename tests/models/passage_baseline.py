"""The passage statistics of the line-scale catenary models before their move onto the shared
multibody pipeline (issue 28): saved once, by ``python -m tests.models.passage_baseline``, into
``passage_baseline.json`` beside this file, so that the new path is tested against them (mean and
standard deviation of the contact force within 0.5 %, the other statistics within 2 %).

Regenerating the file is a deliberate act (a commit of its own, saying why): it is the reference.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

PATH = Path(__file__).with_name("passage_baseline.json")

#: name -> (model, parameters): the cases the issue names, at each model's default settings.
CASES = {
    "benchmark2015_320kmh": ("benchmark2015", {"speed_kmh": 320.0}),
    "benchmark2015_275kmh": ("benchmark2015", {"speed_kmh": 275.0}),
    "benchmark2015_two_pantographs_275kmh": ("benchmark2015", {"speed_kmh": 275.0, "n_pantographs": 2}),
    "en50318_250kmh": ("en50318", {"speed_kmh": 250.0}),
    "en50318_300kmh": ("en50318", {"speed_kmh": 300.0}),
}

#: Within 0.5 %; every other statistic within 2 %.
TIGHT = ("contact_force_mean_N", "contact_force_std_N")


def statistics(summary: dict) -> dict:
    """The EN 50318 statistics of a passage summary: ``{pantograph: {key: value}}`` (one
    pantograph: ``"pantograph_1"``)."""
    from symcat.interaction.statistics import STAT_KEYS

    nested = {k: v for k, v in summary.items() if k.startswith("pantograph_") and isinstance(v, dict)}
    if nested:
        return {name: {k: stats.get(k) for k in STAT_KEYS} for name, stats in sorted(nested.items())}
    return {"pantograph_1": {k: summary.get(k) for k in STAT_KEYS}}


def main() -> int:
    from symcat.model import run_model

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=PATH.parent).stdout.strip()
    data = {"source": f"symcat {commit}, generalized-alpha passage path (symcat/interaction), model defaults",
            "cases": {}}
    for name, (model, params) in CASES.items():
        summary = run_model(model, {**params, "pantograph": "lumped_interaction", "progress": False}).summary
        data["cases"][name] = {"model": model, "parameters": params, "statistics": statistics(summary)}
        print(name, data["cases"][name]["statistics"], flush=True)
    PATH.write_text(json.dumps(data, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
