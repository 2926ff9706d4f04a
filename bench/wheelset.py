"""Wheelset on straight track (constraint wheel/rail contact): work-precision and wall time per
simulated second. ``python -m bench.wheelset`` prints the section and writes it to
``bench/report/wheelset.md``; ``make bench`` adds it to the report."""
from __future__ import annotations

import statistics
import sys
from pathlib import Path

import numpy as np

from symcat.errors import SolverError
from symcat.model import load_model

NAN = float("nan")

T_END = 4.0


def _run(params):
    model = load_model("wheelset")
    resolved = model.resolve(params)
    resolved["progress"] = False  # not a model parameter: the bench prints no progress bars
    return model.run(resolved)


def work_precision(profile="conical", speed=10.0, creep="linear"):
    """Lateral displacement error (max over the run) against rtol 1e-10, both formulations; a
    run that fails is a row with its failure (the time and IDAS's reason)."""
    base = {"profile": profile, "speed_ms": speed, "creep": creep, "t_end": T_END, "n_out": 200}
    try:
        ref = _run({**base, "rtol": 1e-10}).arrays["result"].coordinate("wheelset.y")
    except SolverError as err:
        return [(profile, "augmented", 1e-10, NAN, NAN, 0, 0, NAN, "reference: " + _reason(err))]
    rows = []
    for form in ("augmented", "embedded"):
        for rtol in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
            walls, out, failed = [], None, ""
            for _ in range(3):
                try:
                    out = _run({**base, "rtol": rtol, "formulation": form})
                except SolverError as err:
                    failed = _reason(err)
                    break
                walls.append(out.summary["wall_s"])
            if failed:
                rows.append((profile, form, rtol, NAN, NAN, 0, 0, NAN, failed))
                continue
            res = out.arrays["result"]
            err = float(np.abs(res.coordinate("wheelset.y") - ref).max())
            rows.append((profile, form, rtol, err, statistics.median(walls) / T_END, res.stats["nsteps"],
                         res.stats.get("contact_jumps", 0), float(res.position_drift.max()), ""))
    return rows


def _reason(err) -> str:
    """``failed at t = ... s (IDA_...)`` from a SolverError."""
    text = str(err)
    code = next((w.strip('".') for w in text.split() if w.strip('"').startswith("IDA_")), "")
    time = text.split("after t = ")[1].split(" s")[0] if "after t = " in text else "?"
    return f"failed at t = {time} s {code}".strip()


def section(report_dir=None) -> list[str]:
    rows = work_precision() + work_precision("s1002_uic60")
    return [
        "## Wheelset with constraint wheel/rail contact (`wheelset`)",
        "",
        f"10 m/s, linear creep, 3 mm initial offset, {T_END:g} s. Error: largest difference of the "
        "lateral displacement from the same model at rtol 1e-10. Wall time per simulated second is the "
        "median of 3 runs (including the post-processing of 200 outputs).",
        "",
        "| profiles | formulation | rtol | error [m] | wall per simulated s | steps | contact jumps | max drift [m] "
        "| failure |",
        "|---|---|---:|---:|---:|---:|---:|---:|---|",
        *[f"| {p} | {f} | {r:g} | {e:.2e} | {w:.3f} | {s} | {j} | {d:.1e} | {x} |" for p, f, r, e, w, s, j, d, x in rows],
    ]


if __name__ == "__main__":
    lines = section()
    (Path(__file__).resolve().parent / "report" / "wheelset.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    sys.exit(0)
