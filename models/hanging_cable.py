"""A cable hanging under gravity between two supports at equal height (elastic catenary).

Reference: Irvine's elastic catenary. Give either the unstretched length or the horizontal
tension; the other follows. The cable is meshed on the chord with the stress-free length as
its reference (prestrain = span / unstretched length - 1) and started from a parabola whose
sag is deliberately off, so the static solver has to find the shape.
"""
from __future__ import annotations

import numpy as np

from symcat.analysis import solve_static
from symcat.analytic import elastic_catenary
from symcat.assembly import assemble
from symcat.errors import ParameterError
from symcat.model import Model, ModelOutput, Parameter
from symcat.results import centerlines, plot_centerlines, write_centerlines_vtu
from symcat.scene import AncfBody, Material, Scene, Section

GRAVITY = 9.81
_POS = dict(minimum=0.0, exclusive_minimum=True)

PARAMETERS = [
    Parameter("element", "cable2d", "", "element type", choices=("cable2d", "cable3d", "beam3d")),
    Parameter("n_elements", 20, "-", "number of elements", minimum=1, maximum=5000),
    Parameter("span", 100.0, "m", "horizontal distance between the supports", **_POS),
    Parameter("unstretched_length", 0.0, "m", "stress-free cable length (0: use horizontal_tension)", minimum=0.0),
    Parameter("horizontal_tension", 10e3, "N", "horizontal tension (used when unstretched_length = 0)", **_POS),
    Parameter("mass_per_length", 1.35, "kg/m", "mass per unit unstretched length", **_POS),
    Parameter("EA", 1.8e7, "N", "axial stiffness", **_POS),
    Parameter("EI", 1.0, "N m^2", "bending stiffness (small: the reference has none)", **_POS),
]


def run(p: dict) -> ModelOutput:
    w = p["mass_per_length"] * GRAVITY
    if p["unstretched_length"] > 0:
        if p["unstretched_length"] <= p["span"] * (1 - 0.5):
            raise ParameterError(f"unstretched_length={p['unstretched_length']:g} m: must exceed half the span")
        ref = elastic_catenary(p["span"], w, p["EA"], unstretched_length=p["unstretched_length"])
    else:
        ref = elastic_catenary(p["span"], w, p["EA"], horizontal_tension=p["horizontal_tension"])
    length0 = ref.unstretched_length_m
    element = p["element"]
    dim = 2 if element == "cable2d" else 3
    modulus = 1.0e11
    section = Section.from_stiffness(p["EA"], p["EI"], modulus)
    prestrain = p["span"] / length0 - 1  # chord mesh whose stress-free length is length0
    material = Material(E=modulus, rho=p["mass_per_length"] / section.A, nu=0.3)
    end = np.zeros(dim)
    end[0] = p["span"]
    cable = AncfBody.straight("cable", element, np.zeros(dim), end, p["n_elements"], material, section, prestrain=prestrain)
    # Start with 30 % too much sag: the guess is then stretched (in tension), never a slack
    # compressed curve, from which Newton could wander to a buckled branch.
    _parabola_guess(cable, p["span"], 1.3 * _inextensible_sag(p["span"], length0))
    cable.pin(0).pin(-1)
    if element == "beam3d":
        cable.fix(0, ["z_y", "y_z"])
    scene = Scene(gravity=(0.0, -GRAVITY, 0.0))
    scene.add(cable)
    system = assemble(scene)
    result = solve_static(system, load_steps=1)
    line = centerlines(system, result.q, 32)["cable"]
    sag = -float(np.interp(p["span"] / 2, line[:, 0], line[:, 1]))
    support = result.q[system.dofs.node_indices(cable, 0)]
    summary = {
        "sag_m": sag,
        "reference_sag_m": ref.sag_m,
        "unstretched_length_m": length0,
        "horizontal_tension_N": ref.horizontal_tension_N,
        "support_slope_deg": float(np.degrees(np.arctan2(-support[dim + 1], support[dim]))),
    }

    def write(out):
        return [
            write_centerlines_vtu(system, result.q, out / "hanging_cable.vtu"),
            plot_centerlines({f"{element}, {p['n_elements']} elements": line}, out / "hanging_cable.png",
                             title=f"hanging cable, sag {sag:.4f} m (Irvine {ref.sag_m:.4f} m)"),
        ]

    return ModelOutput(summary, result.stats(), {"q": result.q}, write)


def _inextensible_sag(span: float, length0: float) -> float:
    """Parabolic estimate from the arc length of a shallow parabola, L0 = l + 8 d^2 / (3 l)."""
    return float(np.sqrt(max(length0 - span, 1e-9 * span) * 3 * span / 8))


def _parabola_guess(body: AncfBody, span: float, sag: float) -> None:
    """Move the nodes onto y = -4 d x (l - x) / l^2 with slopes scaled to the mesh length."""
    q = body.q0
    dim = body.element.dim
    x = q[:, 0]
    q[:, 1] = -4 * sag * x * (span - x) / span**2
    dydx = -4 * sag * (span - 2 * x) / span**2
    # Slope = d r / d x_mesh; the mesh coordinate runs along the chord, so the x-part is 1.
    q[:, dim] = 1.0
    q[:, dim + 1] = dydx
    if body.element.name == "beam3d":
        norm = np.sqrt(1 + dydx**2)
        q[:, 6], q[:, 7] = -dydx / norm, 1 / norm


MODEL = Model("hanging_cable", "elastic catenary: a cable sagging under gravity between two supports", PARAMETERS, run)
