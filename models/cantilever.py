"""Cantilever under a dead tip load: the linear limit and the large-deflection elastica.

A clamped straight beam along +x from the origin, square section, loaded at the tip in -y by
P = alpha E I / L^2. References: P L^3 / (3 E I) for small alpha, the inextensible elastica
(Bisshopp and Drucker 1945) and the extensible elastica that the elements discretize.
"""
from __future__ import annotations

import numpy as np

from symcat.analysis import solve_static
from symcat.analytic import cantilever_tip_load
from symcat.analytic.extensible import extensible_cantilever_tip_load
from symcat.assembly import assemble
from symcat.model import Model, ModelOutput, Parameter
from symcat.results import centerlines, plot_centerlines, write_centerlines_vtu
from symcat.scene import AncfBody, Material, NodalForce, Scene, Section

PARAMETERS = [
    Parameter("alpha", 3.0, "-", "tip load factor P L^2 / (E I)", minimum=0.0, maximum=20.0),
    Parameter("element", "beam3d", "", "element type", choices=("beam3d", "cable3d", "cable2d")),
    Parameter("n_elements", 8, "-", "number of elements", minimum=1, maximum=5000),
    Parameter("length", 2.0, "m", "beam length L", minimum=0.0, exclusive_minimum=True),
    Parameter("width", 0.1, "m", "side of the square cross-section", minimum=0.0, exclusive_minimum=True),
    Parameter("E", 2.07e11, "Pa", "Young's modulus", minimum=0.0, exclusive_minimum=True),
    Parameter("nu", 0.3, "-", "Poisson's ratio", minimum=-0.99, maximum=0.49),
    Parameter("load_steps", 2, "-", "initial number of load increments (adaptive)", minimum=1, maximum=1000),
]


def build(p: dict):
    """Scene and body of the cantilever for parameters ``p``."""
    dim = 2 if p["element"] == "cable2d" else 3
    section = Section.rectangle(p["width"], p["width"])
    material = Material(E=p["E"], rho=7850.0, nu=p["nu"])
    end = np.zeros(dim)
    end[0] = p["length"]
    body = AncfBody.straight("beam", p["element"], np.zeros(dim), end, p["n_elements"], material, section)
    body.clamp(0)
    load = p["alpha"] * p["E"] * section.Iz / p["length"] ** 2
    force = np.zeros(dim)
    force[1] = -load
    scene = Scene()
    scene.add(body)
    scene.add(NodalForce("beam", -1, tuple(force)))
    return scene, body


def run(p: dict) -> ModelOutput:
    scene, body = build(p)
    system = assemble(scene)
    result = solve_static(system, load_steps=p["load_steps"])
    tip = result.q[system.dofs.node_indices(body, -1)][:2]
    length = p["length"]
    ux_ref, uy_ref = cantilever_tip_load(p["alpha"]) if p["alpha"] > 0 else (0.0, 0.0)
    ext_ux, ext_uy = extensible_cantilever_tip_load(p["alpha"], p["width"] ** 2 / (12 * length**2))
    summary = {
        "tip_ux_m": float(tip[0] - length),
        "tip_uy_m": float(tip[1]),
        "reference_elastica_tip_ux_m": ux_ref * length,
        "reference_elastica_tip_uy_m": uy_ref * length,
        "reference_extensible_tip_ux_m": ext_ux * length,
        "reference_extensible_tip_uy_m": ext_uy * length,
        "reference_linear_tip_uy_m": -p["alpha"] * length / 3,
    }

    def write(out):
        curves = centerlines(system, result.q)
        return [
            write_centerlines_vtu(system, result.q, out / "cantilever.vtu"),
            plot_centerlines({f"{p['element']}, {p['n_elements']} elements": curves["beam"]}, out / "cantilever.png",
                             title=f"cantilever, alpha = {p['alpha']:g}"),
        ]

    return ModelOutput(summary, result.stats(), {"q": result.q}, write)


MODEL = Model("cantilever", "clamped beam under a dead tip load (elastica)", PARAMETERS, run)
