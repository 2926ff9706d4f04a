"""Natural frequencies of a taut wire pinned at both ends (contact-wire-like properties).

Reference: the pinned-pinned tensioned Euler-Bernoulli beam,
f_n = n / (2 L) sqrt(T / mu) sqrt(1 + (EI / T) (n pi / L)^2). Gravity is off, so the static
state is straight and in-plane (xy) and out-of-plane motions decouple; the in-plane transverse
modes are computed on the in-plane coordinates.
"""
from __future__ import annotations

import numpy as np

from symcat.analysis import modes, solve_static
from symcat.analytic import taut_wire_frequencies
from symcat.assembly import assemble
from symcat.model import Model, ModelOutput, Parameter
from symcat.results import write_modes_vtu
from symcat.scene import AncfBody, Material, Scene, Section

IN_PLANE = {"x", "y", "x_x", "y_x", "x_y", "y_y"}
_POS = dict(minimum=0.0, exclusive_minimum=True)

PARAMETERS = [
    Parameter("element", "cable2d", "", "element type", choices=("cable2d", "cable3d", "beam3d")),
    Parameter("n_elements", 60, "-", "number of elements", minimum=1, maximum=5000),
    Parameter("length", 60.0, "m", "distance between the pins", **_POS),
    Parameter("tension", 20e3, "N", "wire tension", **_POS),
    Parameter("mass_per_length", 1.35, "kg/m", "mass per unit length of the tensioned wire", **_POS),
    Parameter("EI", 195.0, "N m^2", "bending stiffness", **_POS),
    Parameter("EA", 1.8e7, "N", "axial stiffness", **_POS),
    Parameter("n_modes", 10, "-", "number of transverse in-plane modes", minimum=1, maximum=200),
]


def run(p: dict) -> ModelOutput:
    element = p["element"]
    dim = 2 if element == "cable2d" else 3
    modulus = 1.0e11  # any modulus: the section is chosen to give EA and EI
    section = Section.from_stiffness(p["EA"], p["EI"], modulus)
    prestrain = p["tension"] / p["EA"]
    # rho is of the stress-free material: the wire stretched by `prestrain` has mass_per_length.
    material = Material(E=modulus, rho=p["mass_per_length"] * (1 + prestrain) / section.A, nu=0.3)
    end = np.zeros(dim)
    end[0] = p["length"]
    wire = AncfBody.straight("wire", element, np.zeros(dim), end, p["n_elements"], material, section, prestrain=prestrain)
    wire.pin(0).pin(-1)
    if element == "beam3d":
        wire.fix(0, ["z_y", "y_z"])  # no rigid spin about the wire axis
    scene = Scene()
    scene.add(wire)
    system = assemble(scene)
    static = solve_static(system)
    names = system.dofs.names()
    mask = np.array([n.split(".")[-1] in IN_PLANE for n in names])
    modal = modes(system, static.q, p["n_modes"], dof_mask=mask)
    reference = taut_wire_frequencies(p["length"], p["tension"], p["mass_per_length"], p["EI"], p["n_modes"])
    rel = np.abs(modal.frequencies_hz - reference) / reference
    summary = {
        "frequencies_hz": modal.frequencies_hz.tolist(),
        "reference_frequencies_hz": reference.tolist(),
        "max_relative_error": float(rel.max()),
    }

    def write(out):
        files = write_modes_vtu(system, static.q, modal.shapes, modal.frequencies_hz, out)
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        n = np.arange(1, p["n_modes"] + 1)
        ax.plot(n, reference, "ko", mfc="none", label="analytic")
        ax.plot(n, modal.frequencies_hz, "r+", ms=10, label=f"{element}, {p['n_elements']} elements")
        ax.set_xlabel("mode number")
        ax.set_ylabel("frequency [Hz]")
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(out / "frequencies.png", dpi=110)
        plt.close(fig)
        return files + [out / "frequencies.png"]

    return ModelOutput(summary, static.stats(), {"frequencies_hz": modal.frequencies_hz, "mode_shapes": modal.shapes}, write)


MODEL = Model("taut_wire", "natural frequencies of a pinned-pinned taut wire", PARAMETERS, run)
