"""Roll-up of a cantilever by an end moment: M = moment_factor * 2 pi E I / L bends the beam
into a circular arc of radius L / (2 pi moment_factor); moment_factor = 1 closes a full circle
and brings the tip back to the clamp.
"""
from __future__ import annotations

import numpy as np

from symcat.analysis import solve_static
from symcat.analytic import rollup_tip_position
from symcat.assembly import assemble
from symcat.model import Model, ModelOutput, Parameter
from symcat.results import centerlines, plot_centerlines, write_centerlines_vtu
from symcat.scene import AncfBody, Material, Scene, Section, SlopeMoment

PARAMETERS = [
    Parameter("moment_factor", 1.0, "-", "end moment over 2 pi E I / L", minimum=-2.0, maximum=2.0),
    Parameter("element", "beam3d", "", "element type", choices=("beam3d", "cable3d", "cable2d")),
    Parameter("n_elements", 16, "-", "number of elements", minimum=1, maximum=5000),
    Parameter("length", 2.0, "m", "beam length L", minimum=0.0, exclusive_minimum=True),
    Parameter("width", 0.1, "m", "side of the square cross-section", minimum=0.0, exclusive_minimum=True),
    Parameter("E", 2.07e11, "Pa", "Young's modulus", minimum=0.0, exclusive_minimum=True),
    Parameter("nu", 0.3, "-", "Poisson's ratio", minimum=-0.99, maximum=0.49),
    Parameter("load_steps", 4, "-", "initial number of load increments (adaptive)", minimum=1, maximum=1000),
]


def run(p: dict) -> ModelOutput:
    dim = 2 if p["element"] == "cable2d" else 3
    section = Section.rectangle(p["width"], p["width"])
    material = Material(E=p["E"], rho=7850.0, nu=p["nu"])
    end = np.zeros(dim)
    end[0] = p["length"]
    body = AncfBody.straight("beam", p["element"], np.zeros(dim), end, p["n_elements"], material, section)
    body.clamp(0)
    moment = p["moment_factor"] * 2 * np.pi * p["E"] * section.Iz / p["length"]
    scene = Scene()
    scene.add(body)
    scene.add(SlopeMoment("beam", -1, moment, (0.0, 0.0, 1.0)))
    system = assemble(scene)
    result = solve_static(system, load_steps=p["load_steps"])
    tip = result.q[system.dofs.node_indices(body, -1)][:2]
    x_ref, y_ref = rollup_tip_position(p["moment_factor"], p["length"])
    summary = {
        "tip_x_m": float(tip[0]),
        "tip_y_m": float(tip[1]),
        "reference_tip_x_m": float(x_ref),
        "reference_tip_y_m": float(y_ref),
    }

    def write(out):
        curves = centerlines(system, result.q)
        k = p["moment_factor"]
        ref = {}
        if k != 0:
            radius = p["length"] / (2 * np.pi * k)
            phi = np.linspace(0, 2 * np.pi * k, 200)
            ref["exact circle"] = np.column_stack([radius * np.sin(phi), radius * (1 - np.cos(phi)), 0 * phi])
        return [
            write_centerlines_vtu(system, result.q, out / "rollup.vtu"),
            plot_centerlines({f"{p['element']}, {p['n_elements']} elements": curves["beam"]}, out / "rollup.png",
                             title=f"roll-up, moment factor {k:g}", reference=ref),
        ]

    return ModelOutput(summary, result.stats(), {"q": result.q}, write)


MODEL = Model("rollup", "cantilever rolled up by an end moment", PARAMETERS, run)
