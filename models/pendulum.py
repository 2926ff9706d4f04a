"""Planar double pendulum of two rigid rods joined by revolute joints (3D rigid bodies with
Euler parameters), checked against an independent minimal-coordinate integration.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from symcat.assembly.multibody import MultibodyModel
from symcat.integrate import IdasSettings
from symcat.model import Model, ModelOutput, Parameter
from symcat.scene import Revolute, RigidBody, Scene
from symcat.simulation import integrate_model, integrator_parameters

G = 9.81
_POS = dict(minimum=0.0, exclusive_minimum=True)

PARAMETERS = [
    Parameter("t_end", 2.0, "s", "simulated time", minimum=0.0),
    Parameter("length", 1.0, "m", "length of each rod", **_POS),
    Parameter("mass", 1.0, "kg", "mass of each rod", **_POS),
    Parameter("theta1_deg", 90.0, "deg", "initial angle of rod 1 from the downward vertical", minimum=-180.0, maximum=180.0),
    Parameter("theta2_deg", 45.0, "deg", "initial angle of rod 2 from the downward vertical", minimum=-180.0, maximum=180.0),
    Parameter("formulation", "augmented", "", "equations of motion", choices=("augmented", "embedded")),
    Parameter("index", "1", "", "index-1 with Baumgarte or stabilized index 2", choices=("1", "ggl")),
    Parameter("rtol", 1e-8, "-", "IDAS relative tolerance", minimum=1e-12, maximum=1e-2),
] + integrator_parameters()


def rod(name, mass, length, centre, angle):
    c, s = np.cos(angle), np.sin(angle)
    # Body x axis along the rod, pointing away from the upper joint; the rod hangs along -y at angle 0.
    rotation = np.array([[s, -c, 0.0], [-c, -s, 0.0], [0.0, 0.0, -1.0]])
    j = mass * length**2 / 12
    return RigidBody(name, mass, (1e-4 * j, j, j), centre, rotation)


def build(p):
    l, m = p["length"], p["mass"]
    t1, t2 = np.radians(p["theta1_deg"]), np.radians(p["theta2_deg"])
    d1 = np.array([np.sin(t1), -np.cos(t1), 0.0])
    d2 = np.array([np.sin(t2), -np.cos(t2), 0.0])
    scene = Scene(gravity=(0.0, -G, 0.0))
    scene.add(rod("rod1", m, l, 0.5 * l * d1, t1))
    scene.add(rod("rod2", m, l, l * d1 + 0.5 * l * d2, t2))
    scene.add(Revolute("hinge0", "rod1", "ground", at=(0.0, 0.0, 0.0), axis=(0, 0, 1)))
    scene.add(Revolute("hinge1", "rod2", "rod1", at=tuple(l * d1), axis=(0, 0, 1)))
    return scene


def minimal_reference(p, t_eval):
    """Lagrange equations of the compound double pendulum in the two angles (scipy, rtol 1e-12)."""
    l, m = p["length"], p["mass"]
    i0 = m * l**2 / 12

    def rhs(_t, y):
        a, b, da, db = y
        m11 = i0 + m * l**2 / 4 + m * l**2
        m22 = i0 + m * l**2 / 4
        m12 = m * l * l / 2 * np.cos(a - b)
        f1 = -m * l * l / 2 * np.sin(a - b) * db**2 - (m * G * l / 2 + m * G * l) * np.sin(a)
        f2 = m * l * l / 2 * np.sin(a - b) * da**2 - m * G * l / 2 * np.sin(b)
        acc = np.linalg.solve([[m11, m12], [m12, m22]], [f1, f2])
        return [da, db, *acc]

    y0 = [np.radians(p["theta1_deg"]), np.radians(p["theta2_deg"]), 0.0, 0.0]
    sol = solve_ivp(rhs, (0, t_eval[-1]), y0, t_eval=t_eval, rtol=1e-12, atol=1e-12, method="DOP853")
    a, b = sol.y[0], sol.y[1]
    tip = np.column_stack([l * (np.sin(a) + np.sin(b)), -l * (np.cos(a) + np.cos(b))])
    return tip


def run(p: dict) -> ModelOutput:
    scene = build(p)
    model = MultibodyModel(scene)
    if p["t_end"] == 0:
        tip = np.array(scene.rigid_bodies[1].position) + 0.5 * p["length"] * scene.rigid_bodies[1].rotation[:, 0]
        return ModelOutput({"tip_position_m": tip.tolist(), "energy_drift_rel": 0.0, "simulated_s": 0.0})
    settings = IdasSettings(rtol=p["rtol"], atol=p["rtol"] * 1e-2, n_out=100)
    res = integrate_model(model, p, p["t_end"], p["formulation"], p["index"], settings)
    from symcat.scene.rigid import rotation_matrix

    off = model.rigid_offset["rod2"]
    tips = np.array([q[off : off + 3] + 0.5 * p["length"] * rotation_matrix(q[off + 3 : off + 7])[:, 0] for q in res.q])
    ref = minimal_reference(p, res.t_s)
    e = res.energy_J["total"]
    scale = 2 * p["mass"] * G * p["length"]
    summary = {
        "tip_position_m": tips[-1].tolist(),
        "reference_tip_position_m": [*ref[-1], 0.0],
        "max_tip_error_m": float(np.abs(tips[:, :2] - ref).max()),
        "energy_drift_rel": float(np.abs(e - e[0]).max() / scale),
        "max_position_drift_m": float(res.position_drift.max()),
        "simulated_s": p["t_end"],
        "steps": res.stats["steps"],
    }
    def write(out):
        from symcat.results.paraview import write_multibody_series
        from symcat.results.timeseries import plot_histories

        res.save(out / "pendulum.npz")
        plot = plot_histories(res.t_s, {"tip x [m]": tips[:, 0], "tip y [m]": tips[:, 1],
                                        "tip error [m]": np.abs(tips[:, :2] - ref).max(axis=1),
                                        "energy change [J]": e - e[0]}, out / "pendulum.png")
        pvd = write_multibody_series(model, res.t_s, res.q, out / "paraview", "pendulum")
        return [out / "pendulum.npz", plot, pvd]

    return ModelOutput(summary, res.stats, {"t_s": res.t_s, "tip_m": tips, "result": res}, write)


MODEL = Model("pendulum", "planar double pendulum of rigid rods (revolute joints)", PARAMETERS, run)
