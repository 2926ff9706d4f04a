"""The retired interaction path's numbers that tests/interaction/test_unified_passage.py and
test_overlap.py hold the multibody path to: saved once into ``interaction_reference.json``
beside this file.

The interaction path (``symcat.interaction.passage.run_passage`` on ``CoupledLine``, with its
own contact model and generalized-alpha integrator) was retired after commit fe59032, so this
script runs only against a checkout of that commit::

    git worktree add /tmp/symcat-fe59032 fe59032
    cd /tmp/symcat-fe59032 && PYTHONPATH=/tmp/symcat-fe59032 python <this worktree>/tests/interaction/interaction_reference.py <this worktree>/tests/interaction/interaction_reference.json

Regenerating the file is a deliberate act (a commit of its own, saying why): it is the reference.
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

PATH = Path(__file__).with_name("interaction_reference.json")

#: The short line of test_unified_passage.py: benchmark2015, 4 spans, 10 elements per span,
#: 200 km/h, penalty 5e4 N/m, dt 1 ms, rho_inf 0.8, 0.6 s from the static state at 55 m.
UNIFIED = dict(spans=4, elements=10, speed_kmh=200.0, x0=55.0, dt=1e-3, rho_inf=0.8, t_end=0.6)
#: The overlap of test_overlap.py: benchmark2015 (6 spans per section) with two sections, 20
#: elements per span, 275 km/h, three analysis spans, the passage's defaults otherwise.
OVERLAP = dict(spans=6, n_sections=2, elements=20, speed_kmh=275.0, analysis_spans=3)


def _unified() -> dict:
    from symcat.catenary import benchmark2015, find_form
    from symcat.interaction.coupled import CoupledLine, PantographRun
    from symcat.interaction.passage import run_passage
    from symcat.pantograph import benchmark2015_pantograph, en50318_pantograph

    c = UNIFIED
    speed = c["speed_kmh"] / 3.6
    form = find_form(benchmark2015(c["spans"]), c["elements"], progress=False)
    panto = benchmark2015_pantograph(c["speed_kmh"])
    out = {"parameters": c}
    for wires in ("nonlinear", "linear"):
        ip = run_passage(benchmark2015(c["spans"]), [panto], speed, elements_per_span=c["elements"],
                         contact="penalty", dt=c["dt"], rho_inf=c["rho_inf"], t_end=c["t_end"], record_every=c["dt"],
                         progress=False, form=form, wires=wires)
        form.structure.linearize_wires(None)
        assert ip.line.runs[0].x_start == c["x0"]
        out[f"{wires}_t_s"] = [round(float(t), 9) for t in ip.record.t_s]
        out[f"{wires}_contact_force_N"] = [round(float(f), 6) for f in ip.record.contact_force_N[:, 0]]
    # EN 50318 two-mass pantograph, aerodynamic uplift 0.002 N s^2/m^2, bilateral contact: statics
    base = en50318_pantograph(120.0)
    aero = type(base)(base.masses, base.stiffness, base.damping, base.uplift, aero_coefficient=0.002)
    line = CoupledLine(form, [PantographRun(aero, c["x0"])], speed, "bilateral")
    y, fc = line.static_state()
    out["en50318_aero_bilateral"] = {"contact_force_N": float(fc[0]),
                                     "panhead_z_m": float(line.z_ref[0] + y[line.head_index[0]])}
    return out


def _overlap() -> dict:
    import numpy as np

    from symcat.catenary import benchmark2015, find_form
    from symcat.interaction.passage import run_passage
    from symcat.pantograph import benchmark2015_pantograph

    c = OVERLAP
    form = find_form(benchmark2015(c["spans"]).with_(n_sections=c["n_sections"]), c["elements"], progress=False)
    panto = benchmark2015_pantograph(c["speed_kmh"])
    ip = run_passage(form.structure.design, [panto], c["speed_kmh"] / 3.6, elements_per_span=c["elements"],
                     analysis_spans=c["analysis_spans"], form=form, progress=False)
    rec = ip.record
    x = rec.x_contact_m[:, 0]
    L = form.structure.design.span_length
    keep = np.flatnonzero((x > 4 * L) & (x < 5 * L))[::4]  # the transition span, every 4th step
    return {"parameters": c, "statistics": ip.statistics[0],
            "transition_t_s": [round(float(t), 9) for t in rec.t_s[keep]],
            "transition_x_m": [round(float(v), 6) for v in x[keep]],
            "transition_contact_force_wire_N": [[round(float(f), 6) for f in row]
                                                for row in rec.contact_force_wire_N[keep, 0, :]]}


def dump(data: dict) -> str:
    """``data`` as indented JSON with each list of numbers on one line."""
    text = json.dumps(data, indent=1)
    return re.sub(r"\[[-0-9.e,\s]*\]", lambda m: "[" + ", ".join(m.group(0)[1:-1].split()).replace(",,", ",") + "]",
                  text) + "\n"


def main(path: Path = PATH) -> int:
    try:
        import symcat.interaction.passage as passage
        passage.run_passage  # noqa: B018  (exists at fe59032 only)
    except (ImportError, AttributeError):
        print("the interaction path is retired: run this script against a checkout of fe59032 (module docstring)",
              file=sys.stderr)
        return 2
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(passage.__file__).parent).stdout.strip()
    data = {"source": f"symcat {commit}, interaction path (run_passage / CoupledLine), "
                      "tests/interaction/interaction_reference.py",
            "unified": _unified(), "overlap": _overlap()}
    path.write_text(dump(data))
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else PATH))
