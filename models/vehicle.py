"""The seed paper's railroad vehicle (Figures 8 and 9) on tangent track with constraint
wheel/rail contact.

A car body on two bogies; each bogie has a frame, a bolster, two equalizer bars and two
wheelsets (:mod:`symcat.vehicle`: Manchester benchmark vehicle 1 with documented, assumed values
for the bolsters and equalizer bars), eight wheel/rail contacts by the constraint formulation
(seed eq. 22) with creep forces, and the leading wheelset of each bogie driven at ``speed_ms``
(a driving constraint, as in the seed paper, or a traction servo). The vehicle starts in static
equilibrium, displaced ``lateral_offset_m`` toward the left rail, and runs for ``t_end``.

Summary
-------
``weight_N``
    Weight of the vehicle (N).
``wheel_names``
    Contact names, in the order of the lists below (bogie ``b1`` leads; ``ws1`` is the leading
    wheelset of a bogie).
``normal_force_static_N``, ``vertical_force_static_sum_N``
    Normal force of each wheel at t = 0 (N) and the sum of the vertical wheel forces (equals
    the weight).
``normal_force_min_N``, ``normal_force_max_N``
    Extremes of each wheel's normal force over the run (N).
``lateral_displacement_max_m``
    Largest lateral displacement of each wheelset (m).
``derailment_quotient_max``
    Largest Y/Q of each wheel (lateral force toward the track centre over vertical force).
``wall_s``, ``simulated_s``, ``wall_per_simulated_s``, ``max_position_drift_m``
"""
from __future__ import annotations

import numpy as np

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import SolverError
from symcat.integrate import simulate
from symcat.model import Model, ModelOutput, Parameter
from symcat.scene import Scene
from symcat.vehicle import DRIVES, VehicleParameters, add_vehicle, wheel_forces
from symcat.wheelrail import PAIR_NAMES, profile_pair

G = 9.81

PARAMETERS = [
    Parameter("profile", "s1002_uic60", "", "wheel/rail profiles", choices=PAIR_NAMES),
    Parameter("conicity", 0.05, "-", "tread conicity of the conical profile", minimum=0.0, maximum=0.5,
              exclusive_minimum=True),
    Parameter("speed_ms", 17.0, "m/s", "forward speed", minimum=0.0, maximum=100.0, exclusive_minimum=True),
    Parameter("creep", "linear", "", "creep forces", choices=("none", "linear", "nonlinear")),
    Parameter("friction_coefficient", 0.3, "-", "friction coefficient of the nonlinear law", minimum=0.0, maximum=1.0,
              exclusive_minimum=True),
    Parameter("drive", "constraint", "", "leading wheelsets: driving constraint or traction servo", choices=DRIVES),
    Parameter("lateral_offset_m", 0.002, "m", "initial lateral displacement toward the left rail", minimum=-0.008,
              maximum=0.008),
    Parameter("t_end", 1.0, "s", "simulated time", minimum=0.0, exclusive_minimum=True),
    Parameter("index", "ggl", "", "constraint stabilization: GGL (positions held) or index 1 with Baumgarte",
              choices=("ggl", "1")),
    Parameter("rtol", 1e-7, "-", "IDAS relative tolerance", minimum=0.0, maximum=0.1, exclusive_minimum=True),
    Parameter("n_out", 100, "-", "output intervals", minimum=10, maximum=100000),
]


def build(p: dict):
    """Scene, layout and assembled model for parameters ``p``."""
    scene = Scene(gravity=(0.0, 0.0, -G))
    layout = add_vehicle(scene, profile_pair(p["profile"], p["conicity"]), speed_ms=p["speed_ms"],
                         creep={"nonlinear": "polach"}.get(p["creep"], p["creep"]),
                         friction_coefficient=p["friction_coefficient"], drive=p["drive"],
                         lateral_offset_m=p["lateral_offset_m"], parameters=VehicleParameters())
    return scene, layout, MultibodyModel(scene)


def summarize(res, layout) -> dict:
    """Summary quantities of a vehicle run (see the module docstring)."""
    forces = wheel_forces(res, layout)
    names = layout.contact_names
    weight = layout.parameters.total_mass_kg * G
    yq = [float(np.nanmax(forces[n]["Y_over_Q"])) for n in names]
    return {
        "weight_N": weight,
        "wheel_names": names,
        "normal_force_static_N": [float(forces[n]["normal_N"][0]) for n in names],
        "vertical_force_static_sum_N": float(sum(forces[n]["Q_N"][0] for n in names)),
        "normal_force_min_N": [float(forces[n]["normal_N"].min()) for n in names],
        "normal_force_max_N": [float(forces[n]["normal_N"].max()) for n in names],
        "lateral_displacement_max_m": [float(np.abs(res.coordinate(f"{w}.y")).max()) for w in layout.wheelsets],
        "derailment_quotient_max": yq,
        "wall_s": float(res.stats["wall_s"]),
        "simulated_s": float(res.t_s[-1]),
        "wall_per_simulated_s": float(res.stats["wall_s"] / max(res.t_s[-1], 1e-12)),
        "max_position_drift_m": float(res.position_drift.max()),
    }


def run(p: dict) -> ModelOutput:
    _, layout, model = build(p)
    try:
        res = simulate(model, p["t_end"], index=p["index"], rtol=p["rtol"], n_out=int(p["n_out"]),
                       progress=p.get("progress", True))
    except SolverError as err:
        raise SolverError(f"{err} (vehicle model: try index=ggl or a tighter rtol; a flange contact or a contact "
                          "jump may have been reached)") from err
    summary = summarize(res, layout)
    stats = {k: res.stats[k] for k in ("nsteps", "nfevals", "netfails", "nncfails", "restarts")}

    def write(out):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        res.save(out / "vehicle.npz")
        forces = wheel_forces(res, layout)
        fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
        for w in layout.wheelsets:
            axes[0].plot(res.t_s, res.coordinate(f"{w}.y") * 1e3, lw=1, label=w)
        axes[0].set_ylabel("wheelset lateral [mm]")
        axes[0].set_title(f"vehicle, {p['profile']}, {p['speed_ms']:g} m/s, creep {p['creep']}", fontsize=9)
        for n in layout.contact_names:
            axes[1].plot(res.t_s, forces[n]["normal_N"] / 1e3, lw=1, label=n)
            axes[2].plot(res.t_s, forces[n]["Y_over_Q"], lw=1, label=n)
        axes[1].set_ylabel("normal force [kN]")
        axes[2].set_ylabel("Y/Q [-]")
        axes[2].set_xlabel("time [s]")
        axes[0].legend(fontsize=7, ncol=4)
        axes[2].legend(fontsize=6, ncol=4)
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.tight_layout()
        path = out / "vehicle.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return [path, out / "vehicle.npz"]

    return ModelOutput(summary, stats, {"result": res}, write)


MODEL = Model("vehicle", "the seed paper's railroad vehicle (car body, two bogies with frames, bolsters, equalizer "
              "bars and wheelsets) with constraint wheel/rail contact", PARAMETERS, run)
