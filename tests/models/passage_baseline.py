"""The passage statistics of the line-scale catenary models before their move onto the shared
multibody pipeline (issue 28): saved once into ``passage_baseline.json`` beside this file, from
the interaction path (``pantograph=lumped_interaction``, its own contact model and integrator),
so that the new path is tested against them (mean and standard deviation of the contact force
within 0.5 %, the other statistics within 2 %).

The interaction path was retired after fe59032: the saved file is frozen as the independent
reference. ``python -m tests.models.passage_baseline`` refuses to overwrite it;
``python -m tests.models.passage_baseline --from-default-path`` regenerates it from the models'
defaults (the multibody path itself, no longer an independent check): a deliberate act, a
commit of its own saying why.
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


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="python -m tests.models.passage_baseline", description=__doc__.split("\n\n")[0])
    parser.add_argument("--from-default-path", action="store_true",
                        help="regenerate the baseline from the models' defaults (the multibody path); the saved one "
                             "came from the retired interaction path and cannot be regenerated")
    args = parser.parse_args(argv)
    if not args.from_default_path:
        print(f"{PATH.name} holds the retired interaction path's statistics (frozen reference, see "
              "tests/models/passage_baseline.py); pass --from-default-path to replace it by the multibody path's",
              file=sys.stderr)
        return 2

    from symcat.model import run_model

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=PATH.parent).stdout.strip()
    data = {"source": f"symcat {commit}, the models' default path (pantograph=lumped, shared multibody path), model "
                      "defaults", "cases": {}}
    for name, (model, params) in CASES.items():
        summary = run_model(model, {**params, "progress": False}).summary
        data["cases"][name] = {"model": model, "parameters": params, "statistics": statistics(summary)}
        print(name, data["cases"][name]["statistics"], flush=True)
    PATH.write_text(json.dumps(data, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
