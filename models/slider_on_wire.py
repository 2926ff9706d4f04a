"""A rigid body hanging from a sliding joint on a flexible ANCF wire, released under gravity.

The wire (2 m, pinned at both ends, pretensioned) starts straight; the body hangs 0.1 m below
the joint point and is released off-centre, so it slides towards the sagging middle while the
wire deflects under it (seed paper, Section 3).
"""
from __future__ import annotations

import numpy as np

from symcat.assembly.multibody import MultibodyModel
from symcat.integrate import IdasSettings
from symcat.model import Model, ModelOutput, Parameter
from symcat.scene import AncfBody, Material, RigidBody, Scene, Section, SlidingJoint
from symcat.simulation import integrate_model, integrator_parameters

_POS = dict(minimum=0.0, exclusive_minimum=True)

PARAMETERS = [
    Parameter("n_elements", 8, "-", "wire elements", minimum=1, maximum=2000),
    Parameter("element", "cable3d", "", "wire element type", choices=("cable3d", "beam3d")),
    Parameter("length", 2.0, "m", "wire length between the pins", **_POS),
    Parameter("mass_per_length", 0.5, "kg/m", "wire mass per unit length", **_POS),
    Parameter("EA", 1.0e6, "N", "axial stiffness", **_POS),
    Parameter("EI", 1.0, "N m^2", "bending stiffness", **_POS),
    Parameter("tension", 500.0, "N", "initial wire tension", minimum=0.0),
    Parameter("damping", 1e-4, "s", "Kelvin-Voigt time constant of axial and bending strain rates", minimum=0.0),
    Parameter("body_mass", 1.0, "kg", "mass of the hanging body", **_POS),
    Parameter("s0", 0.5, "m", "initial arc length of the joint along the wire", minimum=0.0),
    Parameter("formulation", "augmented", "", "equations of motion", choices=("augmented", "embedded")),
    Parameter("index", "1", "", "index-1 with Baumgarte or stabilized index 2", choices=("1", "ggl")),
    Parameter("t_end", 1.0, "s", "simulated time", minimum=0.0),
    Parameter("rtol", 1e-6, "-", "IDAS relative tolerance", minimum=1e-12, maximum=1e-2),
    Parameter("window", 16, "-", "elements in the moving window of the sliding joint", minimum=2, maximum=100000),
    Parameter("cholesky", False, "", "Cholesky coordinates for the wire (identity mass matrix)"),
] + integrator_parameters()


def build(p: dict) -> Scene:
    modulus = 1.0e11
    section = Section.from_stiffness(p["EA"], p["EI"], modulus)
    prestrain = p["tension"] / p["EA"]
    material = Material(E=modulus, rho=p["mass_per_length"] * (1 + prestrain) / section.A)
    wire = AncfBody.straight("wire", p["element"], [0, 0, 0], [p["length"], 0, 0], p["n_elements"], material, section,
                             prestrain=prestrain, damping_axial=p["damping"], damping_bending=p["damping"])
    wire.pin(0).pin(-1)
    if p["element"] == "beam3d":
        wire.fix(0, ["z_y", "y_z"])
    scene = Scene(gravity=(0.0, 0.0, -9.81))
    scene.add(wire)
    joint = np.array([p["s0"], 0.0, 0.0])
    body = RigidBody("body", p["body_mass"], (0.01, 0.01, 0.01), joint - [0.0, 0.0, 0.1])
    scene.add(body)
    scene.add(SlidingJoint("slider", "wire", "body", s0=p["s0"], at=tuple(joint), reference_direction=(0, 1, 0)))
    return scene


def run(p: dict) -> ModelOutput:
    if not p["s0"] < p["length"]:
        from symcat.errors import ParameterError

        raise ParameterError(f"s0={p['s0']:g} m: must be less than length={p['length']:g} m")
    scene = build(p)
    model = MultibodyModel(scene, window=p["window"])
    if p["t_end"] == 0:
        return ModelOutput({"s_final_m": p["s0"], "body_position_m": list(scene.rigid_bodies[0].position),
                            "max_position_drift_m": 0.0, "simulated_s": 0.0, "steps": 0})
    settings = IdasSettings(rtol=p["rtol"], atol=p["rtol"] * 1e-2, cholesky=p["cholesky"],
                            n_out=max(20, int(200 * p["t_end"])))
    res = integrate_model(model, p, p["t_end"], p["formulation"], p["index"], settings)
    off = model.rigid_offset["body"]
    summary = {
        "s_final_m": float(res.s_m[-1, 0]),
        "body_position_m": res.q[-1, off : off + 3].tolist(),
        "max_position_drift_m": float(res.position_drift.max()),
        "max_velocity_drift_m_s": float(res.velocity_drift.max()),
        "contact_force_final_N": res.reactions_N["slider"][-1].tolist(),
        "wall_s": res.stats["wall_s"],
        "simulated_s": p["t_end"],
        "steps": res.stats["steps"],
    }
    def write(out):
        from symcat.results.paraview import write_multibody_series
        from symcat.results.timeseries import plot_histories

        res.save(out / "slider_on_wire.npz")
        force = res.reactions_N["slider"]
        plot = plot_histories(res.t_s, {"s [m]": res.s_m[:, 0], "contact force z [N]": force[:, 2],
                                        "position drift [m]": res.position_drift}, out / "slider_on_wire.png",
                              title=f"{p['formulation']}, index {p['index']}")
        pvd = write_multibody_series(model, res.t_s, res.q, out / "paraview", "slider_on_wire")
        return [out / "slider_on_wire.npz", plot, pvd]

    return ModelOutput(summary, res.stats, {"result": res}, write)


MODEL = Model("slider_on_wire", "a body hanging from a sliding joint on a flexible wire", PARAMETERS, run)
