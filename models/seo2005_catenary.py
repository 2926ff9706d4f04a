"""The seed paper's numerical example (Seo, Sugiyama and Shabana 2005, Section 7): a four-body
pantograph running at 17 m/s under an 8-element ANCF contact wire held by droppers, with the
bilateral sliding joint of the paper or a unilateral penalty contact (its Section 8), started
from static equilibrium (the paper's first 2 s of oscillation came from not doing this).

The scene is built from the library: the catenary is :func:`symcat.catenary.seed.add_seed_catenary`
(the paper's wire and droppers; every value the paper omits is listed in
:mod:`symcat.catenary.seed`), the pantograph and its contact the scene fragment
:func:`symcat.pantograph.seo2005.add_seo2005_pantograph` (dimensions in
:mod:`symcat.pantograph.seo2005`). Coordinates: x along the track, y lateral, z up; the undeformed
contact wire is the line y = z = 0, so the pan-head's z is its vertical displacement from the
wire's design height.

Contact wire
    ``wire_length`` = 60 m (8 elements of 7.5 m), pinned at both ends (positions fixed; a
    beam3d wire also has its torsion fixed at node 0). Cross-section 3 mm x 3 mm square
    (A = 9 mm^2 as in the paper; I = 6.75e-12 m^4, EI = 0.61 N m^2). The end tension enters
    as the prestrain T / (EA) = 5000 / 810000 of the mesh. Kelvin-Voigt damping ``wire_damping``
    (1e-4 s, not in the paper; it only calms the highest element modes).
Droppers
    One at each of the 7 interior nodes (x = 7.5, 15, ..., 52.5 m), vertical, hanging from
    fixed points 1.0 m above the wire; free length 1.0 m minus the stretch that carries the
    weight of 7.5 m of wire (9.3e-6 m), so the unloaded wire hangs straight.
Pantograph
    The seed pantograph on a 50 kg carrier driven along x at ``speed``, its base hinge 2.5 m
    below the wire under ``start``; ``uplift`` N on the plunger (265 N: about 90 N static
    contact force); coupling rod ``rod_stiffness``.
Contact
    bilateral: the seed's sliding joint (pan-head centre of mass on the wire centre line).
    penalty: tangency condition for s and a normal penalty force (``contact_stiffness``,
    ``contact_damping``, ``contact_smoothing``); contact loss is a positive gap.
Integrator
    ``integrator`` = ``idas`` (default; index 1 with Baumgarte, ``rtol``) or
    ``generalized_alpha`` (fixed step ``dt``, numerical dissipation ``rho_inf``; the stabilized
    index-2 form). Either contact model runs on both.
"""
from __future__ import annotations

import numpy as np

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary.seed import PARAMETERS as CATENARY_PARAMETERS
from symcat.catenary.seed import add_seed_catenary_from
from symcat.integrate import IdasSettings
from symcat.model import Model, ModelOutput, Parameter
from symcat.pantograph.seo2005 import PARAMETERS as PANTOGRAPH_PARAMETERS
from symcat.pantograph.seo2005 import (G, add_seo2005_pantograph_from, check_run, contact_history,
                                       static_contact_force, wire_atol)
from symcat.scene import Scene
from symcat.simulation import integrate_model, integrator_parameters

_SHARED = {**CATENARY_PARAMETERS, **PANTOGRAPH_PARAMETERS}

PARAMETERS = [
    Parameter("t_end", 2.0, "s", "simulated time (0: static equilibrium only)", minimum=0.0),
    *(_SHARED[n] for n in ("contact", "element", "n_elements")),
    Parameter("speed", 17.0, "m/s", "carrier speed along the wire", minimum=0.0),
    *(_SHARED[n] for n in ("wire_length", "tension", "wire_damping", "start", "uplift", "rod_stiffness",
                           "contact_stiffness", "contact_damping", "contact_smoothing")),
    Parameter("formulation", "augmented", "", "equations of motion", choices=("augmented", "embedded")),
    Parameter("rtol", 1e-5, "-", "IDAS relative tolerance", minimum=1e-12, maximum=1e-2),
    Parameter("n_out", 400, "-", "output intervals per simulated second", minimum=10, maximum=100000),
] + integrator_parameters()


def build(p: dict, z0: float = 0.0, base: str | None = None, scene: Scene | None = None,
          carrier_fixed: bool = False) -> Scene:
    """The catenary and the pantograph with the wire at height ``z0`` (m). The pantograph's base
    is a 50 kg carrier driven along the wire (``base=None``; held fixed with ``carrier_fixed``)
    or the rigid body ``base`` already in ``scene`` (a car body)."""
    scene = add_seed_catenary_from(Scene(gravity=(0.0, 0.0, -G)) if scene is None else scene, p, z0)
    add_seo2005_pantograph_from(scene, p, "wire", z0, base, carrier_fixed)
    return scene


check = check_run


def _panhead_offset(model) -> int:
    return model.rigid_offset["panhead"]


def run(p: dict) -> ModelOutput:
    check(p)
    scene = build(p)
    model = MultibodyModel(scene)
    eq = solve_equilibrium(model)
    eq.apply(model)
    off = _panhead_offset(model)
    static_force = static_contact_force(eq)
    static = {"static_panhead_z_m": float(eq.q[off + 2]), "static_contact_force_N": static_force,
              "static_residual_N": eq.residual_N, "static_iterations": eq.iterations}
    if p["t_end"] == 0:
        summary = {"panhead_z_mean_m": static["static_panhead_z_m"], "panhead_z_std_m": 0.0,
                   "contact_force_mean_N": static_force, "contact_force_std_N": 0.0, "contact_loss_percent": 0.0,
                   "simulated_s": 0.0, **static}
        return ModelOutput(summary, eq.stats(), {"equilibrium": eq})
    n_out = max(10, int(round(p["n_out"] * p["t_end"])))
    # IDAS: index 1 (Baumgarte); generalized-alpha: the stabilized index-2 form (positions and
    # velocities enforced).
    index = "ggl" if p["integrator"] == "generalized_alpha" else "1"
    settings = IdasSettings(rtol=p["rtol"], atol=wire_atol(model, p["rtol"] * 1e-2), n_out=n_out)
    res = integrate_model(model, p, p["t_end"], p["formulation"], index, settings)
    z = res.q[:, off + 2]
    acc = res.a[:, off + 2]
    force, lost, s_hist = contact_history(res, p["contact"])
    e = res.energy_J["total"]
    summary = {
        "panhead_z_mean_m": float(z.mean()), "panhead_z_std_m": float(z.std()),
        "contact_force_mean_N": float(force.mean()), "contact_force_std_N": float(force.std()),
        "contact_force_max_N": float(force.max()), "contact_force_min_N": float(force.min()),
        "panhead_acceleration_max_m_s2": float(np.abs(acc).max()),
        "contact_loss_percent": float(100.0 * lost.mean()),
        "max_position_drift_m": float(res.position_drift.max()),
        "max_velocity_drift_m_s": float(res.velocity_drift.max()),
        "energy_change_J": float(e[-1] - e[0]),
        "contact_s_final_m": float(s_hist[-1]),
        "simulated_s": p["t_end"], "steps": res.stats["steps"],
        "wall_per_simulated_s": res.stats["wall_s"] / p["t_end"], **static,
    }

    def write(out):
        from symcat.results.paraview import write_multibody_series
        from symcat.results.timeseries import plot_histories

        npz = out / "seo2005_catenary.npz"
        res.save(npz)
        with np.load(npz) as data:
            arrays = dict(data)
        np.savez_compressed(npz, **arrays, panhead_z_m=z, panhead_acceleration_m_s2=acc, contact_force_N=force)
        plot = plot_histories(res.t_s, {"pan-head z [m]": z, "pan-head acceleration z [m/s^2]": acc,
                                        "contact force [N]": force}, out / "seo2005_catenary.png",
                              title=f"seo2005: {p['contact']} contact, {p['element']}, {p['speed']:g} m/s")
        pvd = write_multibody_series(model, res.t_s, res.q, out / "paraview", "seo2005_catenary")
        return [npz, plot, pvd]

    return ModelOutput(summary, {**res.stats, "equilibrium": eq.stats()},
                       {"result": res, "equilibrium": eq, "panhead_z_m": z, "contact_force_N": force}, write)


MODEL = Model("seo2005_catenary", "the seed paper's example: four-body pantograph under an 8-element ANCF contact wire",
              PARAMETERS, run)
