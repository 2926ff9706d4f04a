"""The seed paper's complete scene (Seo, Sugiyama and Shabana 2005, Figures 6-9): the railroad
vehicle with wheel/rail contacts carrying the four-body pantograph on its roof, under the
8-element ANCF contact wire, at 17 m/s.

The vehicle is :mod:`symcat.vehicle` (as ``models/vehicle.py``: car body, two bogies with frames,
bolsters, equalizer bars and wheelsets; constraint wheel/rail contact, seed eq. 22, with creep
forces; the leading wheelset of each bogie driven at ``speed``, as in the paper). The catenary,
the pantograph and the pan-head/wire contact are those of ``models/seo2005_catenary.py``, built
from the same library pieces (:func:`symcat.catenary.seed.add_seed_catenary` and the scene fragment
:func:`symcat.pantograph.seo2005.add_seo2005_pantograph`, whose modules list every dimension
chosen there), with two changes: the pantograph's base hinge
and its damper and coupling rod attach to the car body's roof (which also carries the uplift's
reaction: the uplift acts between the pantograph's base and frame), above the vehicle's centre, at
``ROOF_HEIGHT_M`` = 3.8 m above the rail top (assumed), and the wire is therefore at 6.3 m (the
pantograph geometry puts the base 2.5 m below the wire).

Start: the catenary and the pantograph are first put in static equilibrium on a fixed base (as
in ``seo2005_catenary``); their coordinates are then carried into the full scene, whose vehicle
starts in its own static equilibrium (suspension preloads), so the run starts without the
paper's 2 s of start-up oscillation.

Summary: the keys of ``seo2005_catenary`` plus ``wheel_names``, ``wheel_normal_force_static_N``,
``wheel_normal_force_min_N``, ``wheel_normal_force_max_N`` (N, per wheel),
``wheelset_lateral_displacement_max_m`` and ``wall_s``.
"""
from __future__ import annotations

import numpy as np

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary.seed import PARAMETERS as CATENARY_PARAMETERS
from symcat.catenary.seed import add_seed_catenary_from
from symcat.errors import SolverError
from symcat.integrate import IdasSettings
from symcat.model import Model, ModelOutput, Parameter
from symcat.pantograph.seo2005 import PARAMETERS as PANTOGRAPH_PARAMETERS
from symcat.pantograph.seo2005 import (B_DEPTH, G, MASSES, add_seo2005_pantograph_from, check_run, contact_history,
                                       static_contact_force, wire_atol)
from symcat.scene import Scene
from symcat.simulation import integrate_model, integrator_parameters
from symcat.vehicle import VehicleParameters, add_vehicle, wheel_forces, wheel_summary
from symcat.vehicle.model_parameters import CREEP_LAWS, running_parameters
from symcat.wheelrail import profile_pair


ROOF_HEIGHT_M = 3.8
WIRE_HEIGHT_M = ROOF_HEIGHT_M + B_DEPTH
PANTOGRAPH = tuple(MASSES)          # lower_arm, upper_arm, plunger, panhead

_CATENARY = {**CATENARY_PARAMETERS, **PANTOGRAPH_PARAMETERS}
PARAMETERS = [
    Parameter("t_end", 1.0, "s", "simulated time", minimum=0.0, exclusive_minimum=True),
    *(_CATENARY[n] for n in ("contact", "element", "n_elements")),
    Parameter("speed", 17.0, "m/s", "vehicle speed", minimum=0.0, maximum=100.0, exclusive_minimum=True),
    *(_CATENARY[n] for n in ("wire_length", "tension", "wire_damping", "start", "uplift", "rod_stiffness",
                             "contact_stiffness", "contact_damping", "contact_smoothing")),
    *running_parameters(),
    Parameter("rtol", 1e-6, "-", "IDAS relative tolerance", minimum=1e-12, maximum=1e-2),
    Parameter("n_out", 200, "-", "output intervals per simulated second", minimum=10, maximum=100000),
    *integrator_parameters(tol_m=1e-8),
]


def build(p: dict):
    """Static equilibrium of catenary and pantograph, then the full scene starting from it.
    Returns the full model, the vehicle layout and the equilibrium."""
    sub = MultibodyModel(_catenary_and_pantograph(p))
    eq = solve_equilibrium(sub)
    scene = Scene(gravity=(0.0, 0.0, -G))
    layout = add_vehicle(scene, profile_pair(p["profile"], 0.05), speed_ms=p["speed"],
                         creep=CREEP_LAWS[p["creep"]],
                         friction_coefficient=p["friction_coefficient"], lateral_offset_m=p["lateral_offset_m"],
                         x_m=p["start"], parameters=VehicleParameters(), car_body_load_N=_roof_load_N(sub, eq))
    add_seed_catenary_from(scene, p, WIRE_HEIGHT_M)
    add_seo2005_pantograph_from(scene, p, "wire", WIRE_HEIGHT_M, base=layout.car_body)
    model = MultibodyModel(scene)
    _start_from(model, sub, eq)
    return model, layout, eq


def _catenary_and_pantograph(p: dict) -> Scene:
    """The catenary and the pantograph on a fixed carrier (the static start)."""
    scene = add_seed_catenary_from(Scene(gravity=(0.0, 0.0, -G)), p, WIRE_HEIGHT_M)
    add_seo2005_pantograph_from(scene, p, "wire", WIRE_HEIGHT_M, carrier_fixed=True)
    return scene


def _roof_load_N(sub, eq) -> float:
    """What the pantograph puts on the roof at equilibrium: its weight plus the wire's push."""
    mass = sum(b.mass for b in sub.scene.rigid_bodies if b.name in PANTOGRAPH)
    return mass * G + static_contact_force(eq)


def _start_from(model, sub, eq) -> None:
    """Carry the wire's and the pantograph's equilibrium coordinates and the contact's arc
    length into ``model``."""
    index = {name: k for k, name in enumerate(model.coordinate_names())}
    for k, name in enumerate(sub.coordinate_names()):
        if name.startswith("wire[") or name.split(".")[0] in PANTOGRAPH:
            model.q0[index[name]] = eq.q[k]
    n_sliding = len(eq.s_m)
    model.s0[:n_sliding] = eq.s_m
    model.sc0 = eq.sc_m.copy()
    for sl, s in zip(model.windowed(), np.r_[eq.s_m, eq.sc_m]):
        model.set_window(sl, s)


def run(p: dict) -> ModelOutput:
    check_run(p)
    model, layout, eq = build(p)
    off = model.rigid_offset["panhead"]
    n_out = max(10, int(round(p["n_out"] * p["t_end"])))
    try:
        settings = IdasSettings(rtol=p["rtol"], atol=wire_atol(model, p["rtol"] * 1e-2), n_out=n_out,
                                progress=p.get("progress", True))
        res = integrate_model(model, p, p["t_end"], "augmented", "ggl", settings)
    except SolverError as err:
        raise SolverError(f"{err} (seo2005: vehicle, pantograph and catenary; try a tighter rtol)",
                          partial=err.partial) from err
    z = res.q[:, off + 2] - WIRE_HEIGHT_M
    acc = res.a[:, off + 2]
    force, lost, s_hist = contact_history(res, p["contact"])
    wheels = wheel_forces(res, layout)
    names = layout.contact_names
    static_force = static_contact_force(eq)
    summary = {
        "panhead_z_mean_m": float(z.mean()), "panhead_z_std_m": float(z.std()),
        "contact_force_mean_N": float(force.mean()), "contact_force_std_N": float(force.std()),
        "contact_force_max_N": float(force.max()), "contact_force_min_N": float(force.min()),
        "panhead_acceleration_max_m_s2": float(np.abs(acc).max()),
        "contact_loss_percent": float(100.0 * lost.mean()),
        "max_position_drift_m": float(res.position_drift.max()),
        "max_velocity_drift_m_s": float(res.velocity_drift.max()),
        "energy_change_J": float(res.energy_J["total"][-1] - res.energy_J["total"][0]),
        "contact_s_final_m": float(s_hist[-1]),
        "simulated_s": p["t_end"], "steps": res.stats["steps"], "wall_s": float(res.stats["wall_s"]),
        "wall_per_simulated_s": res.stats["wall_s"] / p["t_end"],
        "static_panhead_z_m": float(z[0]),
        "static_contact_force_N": static_force, "static_residual_N": eq.residual_N,
        "static_iterations": eq.iterations,
        **wheel_summary(res, layout, wheels),
    }

    def write(out):
        from symcat.results.paraview import write_multibody_series
        from symcat.results.timeseries import plot_histories

        npz = out / "seo2005.npz"
        res.save(npz)
        with np.load(npz) as data:
            arrays = dict(data)
        np.savez_compressed(npz, **arrays, panhead_z_m=z, panhead_acceleration_m_s2=acc, contact_force_N=force)
        series = {"pan-head z [m]": z, "contact force [N]": force,
                  "wheel normal forces b1_ws1 [N]": wheels[names[0]]["normal_N"]}
        plot = plot_histories(res.t_s, series, out / "seo2005.png",
                              title=f"seo2005: vehicle + pantograph + catenary, {p['speed']:g} m/s")
        pvd = write_multibody_series(model, res.t_s, res.q, out / "paraview", "seo2005")
        return [npz, plot, pvd]

    return ModelOutput(summary, {**{k: res.stats.get(k) for k in ("nsteps", "netfails", "nncfails", "newton_iterations")},
                                 "equilibrium": eq.stats()}, {"result": res, "equilibrium": eq, "layout": layout}, write)


MODEL = Model("seo2005", "the seed paper's complete scene: vehicle with wheel/rail contact, pantograph and ANCF "
              "contact wire", PARAMETERS, run)
