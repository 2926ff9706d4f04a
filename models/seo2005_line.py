"""The seed paper's complete scene on a real line: the seed vehicle (``models/vehicle.py``) on
tangent track carrying the seed's four-body pantograph (``models/seo2005_catenary.py``) on its
car-body roof, under the 2015 benchmark catenary (``models/benchmark2015.py``: ``spans`` spans,
form-found, staggered, Rayleigh-damped), all three starting from their joint static
equilibrium, at ``speed_ms`` (17 m/s, as in the paper).

How it is built (:mod:`symcat.interaction.scene_vehicle`): the catenary is form-found
(:func:`symcat.catenary.find_form`) and made a scene (:func:`symcat.catenary.catenary_scene`);
the pantograph is the scene passage's fragment :func:`~symcat.interaction.scene_pantographs.seo2005_fragment`
(penalty contact: the wire is staggered), first on its driven carrier, where its plunger uplift
is trimmed so that the static contact force is ``static_force_N``
(:func:`~symcat.interaction.scene_pantographs.trim_uplifts`), then on the car body, with the
equilibrium coordinates of wires and pantograph copied by name; the vehicle's suspensions are
preloaded with the weights and the pantograph's roof load (its weight plus the wire's push),
so it starts in its own static equilibrium. The uplift acts between the car body and the
plunger (a force of the pantograph's own drive, which the vehicle carries). The start, the
analysis section and the duration are the line passage's (:func:`~symcat.interaction.passage.passage_plan`:
one span of lead-in before the central ``analysis_spans`` spans); the vehicle's centre starts
under the pan-head.

Heights (the choice): the seed's roof is 3.8 m above the rail top (``ROOF_HEIGHT_M``, assumed
in ``models/seo2005.py``) and its pantograph works with the base hinge ``B_DEPTH`` = 2.5 m below
the contact wire, so the benchmark catenary is built with its contact wire 6.3 m above the rail
at the supports (``WIRE_HEIGHT_M``) instead of the benchmark's 5.3 m, a free choice of that
design ("only relative heights matter"); the track stays at z = 0. The pantograph is built in
its one working geometry, with the pan-head on the static wire at its start: it reaches the
wire from the roof only where the wire is at 6.3 m, at a support (the passage starts there when
``spans >= analysis_spans + 2``; mid-span the wire hangs up to the 55 mm presag lower). Other
starts are refused with one line naming ``spans`` and ``analysis_spans``.

``elements_per_span`` defaults to 10: the mesh is rounded per dropper interval, and the
benchmark's span has ten intervals (nine droppers), so 10 is the coarsest mesh with a node at
every dropper and support (fewer is rounded up to it), and the cheapest line to integrate. At
the seed's 17 m/s it is enough: on the default passage (generalized-alpha, 1 ms) 10 and 28
elements per span give the statistics within 1 % (mean 0.05 %, standard deviation 0.7 %,
statistical extremes 0.6 %; the raw extremes within 3 %). At line speeds raise it (the
benchmark at 320 km/h needs about 60 for 0.5 %, docs/user_guide/catenary.md).

Integrators (:func:`symcat.simulation.integrate_model`): ``generalized_alpha`` (default;
``dt``, ``rho_inf``; the wheel/rail contacts' events decided between its steps) or ``idas``,
which resolves the wires' fast modes with thousands of steps per simulated second, each
factorizing the whole line's matrix: on IDAS give a short ``t_end``.

Summary: the EN 50318 statistics of the 20 Hz filtered contact force over the analysis section
(:func:`symcat.interaction.passage.pantograph_statistics`; None with ``analysis_complete: false``
when ``t_end`` stops before the section's end) and the line passage's other keys
(:func:`symcat.interaction.model_support.passage_output`), the static state (``uplift_N``,
``static_contact_force_N``, ``base_hinge_height_m``, ``car_body_load_N``,
``static_wheel_load_sum_N`` against ``static_weight_and_push_N``,
``static_vertical_momentum_rate_N``), the raw contact force's mean and standard deviation over
the whole run (``contact_force_run_mean_N``, ``contact_force_run_std_N``), the wheel/rail keys of
``models/seo2005.py`` (``wheel_names``, ``wheel_normal_force_static_N``, ``_min_N``, ``_max_N``,
``wheelset_lateral_displacement_max_m``) and wall times (``build_wall_s``, ``integration_wall_s``).
"""
from __future__ import annotations

import time
from functools import partial

import numpy as np

from symcat.catenary import benchmark2015
from symcat.errors import ParameterError, SolverError
from symcat.integrate import IdasSettings
from symcat.integrate.choice import integrator_parameters
from symcat.interaction.model_support import passage_output
from symcat.interaction.passage import passage_plan, spans_needed
from symcat.interaction.scene_pantographs import seo2005_fragment
from symcat.interaction.scene_vehicle import build_vehicle_line, vehicle_passage_result, wire_height_at
from symcat.model import Model, Parameter
from symcat.pantograph import en50367_mean_force
from symcat.pantograph.seo2005 import B_DEPTH, wire_atol
from symcat.simulation import integrate_model
from symcat.vehicle import momentum_rate_N, wheel_forces, wheel_summary
from symcat.vehicle.model_parameters import CREEP_LAWS, running_parameters
from symcat.wheelrail import profile_pair

ROOF_HEIGHT_M = 3.8                          # the seed scene's roof above the rail top (models/seo2005.py)
WIRE_HEIGHT_M = ROOF_HEIGHT_M + B_DEPTH      # contact wire at the supports
REACH_TOLERANCE_M = 0.005                    # base hinge on the roof to within this
#: EN 50119's limit: at most 70 % of the contact wire's transverse wave speed.
SPEED_LIMIT_MS = 0.7 * benchmark2015().contact_wire.wave_speed

PARAMETERS = [
    Parameter("t_end", -1.0, "s", "simulated time; -1: the passage plan (until the pan-head has left the analysis "
              "section, 0.2 s more for the filter)", minimum=-1.0),
    Parameter("speed_ms", 17.0, "m/s", f"train speed (the seed's 17 m/s; at most 70 % of the contact wire's wave "
              f"speed, {SPEED_LIMIT_MS:.1f} m/s)", minimum=0.0, exclusive_minimum=True, maximum=SPEED_LIMIT_MS),
    Parameter("spans", 10, "-", "spans of the benchmark line (one tension section)", minimum=3, maximum=60),
    Parameter("elements_per_span", 10, "-", "contact/messenger-wire elements per span, rounded per dropper "
              "interval: 10 is one per interval, the coarsest", minimum=1, maximum=400),
    Parameter("analysis_spans", 0, "-", "spans of the analysis section (central ones); 0: 2, or 1 on a line of 3 "
              "spans", minimum=0, maximum=58),
    Parameter("static_force_N", -1.0, "N", "static contact force the uplift is trimmed to; -1: EN 50367's AC mean "
              "0.00097 v^2 + 70 N (v in km/h)", minimum=-1.0),
    Parameter("formulation", "augmented", "", "equations of motion: augmented (eq. 25) or embedded (eq. 26)",
              choices=("augmented", "embedded")),
    Parameter("index", "ggl", "", "constraint stabilization: ggl (stabilized index 2) or 1 (Baumgarte)",
              choices=("ggl", "1")),
    *integrator_parameters(default="generalized_alpha", tol_m=1e-7),
    Parameter("rtol", 1e-6, "-", "IDAS relative tolerance (absolute: rtol / 100)", minimum=1e-12, maximum=1e-2),
    Parameter("n_out", 200, "-", "outputs per simulated second (the contact force's samples; 200 resolve the 20 Hz "
              "filter's band)", minimum=10, maximum=100000),
    Parameter("contact_stiffness", 5.0e4, "N/m", "penalty contact stiffness", minimum=0.0, exclusive_minimum=True),
    Parameter("contact_damping", 0.0, "N s/m", "penalty contact damping (only while in contact)", minimum=0.0),
    Parameter("contact_smoothing", 1e-5, "m", "depth over which the penalty law is smoothed", minimum=0.0,
              exclusive_minimum=True),
    Parameter("rod_stiffness", 5e5, "N/m", "stiffness of the pantograph's coupling rod", minimum=0.0,
              exclusive_minimum=True),
    *running_parameters(),
    Parameter("progress", True, "", "show progress"),
]


def design_from(p: dict):
    """The benchmark line with its contact wire where the pantograph on the roof reaches it."""
    return benchmark2015(p["spans"]).with_(contact_wire_height=WIRE_HEIGHT_M)


def analysis_spans(p: dict) -> int:
    return p["analysis_spans"] or (2 if p["spans"] >= 4 else 1)


def check(p: dict, design) -> tuple:
    """Refuse, before any work, what cannot run; the passage plan."""
    a = analysis_spans(p)
    if p["t_end"] != -1.0 and not p["t_end"] > 0:
        raise ParameterError(f"t_end={p['t_end']:g} s: must be > 0, or -1 (the passage plan)")
    if a > p["spans"]:
        raise ParameterError(f"analysis_spans={a}: must be at most spans={p['spans']}")
    if p["static_force_N"] != -1.0 and not p["static_force_N"] > 0:
        raise ParameterError(f"static_force_N={p['static_force_N']:g} N: must be > 0, or -1 (EN 50367)")
    need = spans_needed(design.span_length, 1, 200.0, a)
    if p["t_end"] == -1.0 and p["spans"] < need:
        raise ParameterError(f"spans={p['spans']}: the passage over {a} analysis span(s) after a one-span lead-in needs "
                             f"spans >= {need}; or give t_end > 0")
    section, x0, duration = passage_plan(design, 1, p["speed_ms"], 200.0, a, None, None if p["t_end"] < 0 else p["t_end"])
    z = wire_height_at(design, x0)
    if abs(z - B_DEPTH - ROOF_HEIGHT_M) > REACH_TOLERANCE_M:
        raise ParameterError(f"spans={p['spans']}, analysis_spans={a}: the pantograph would start at x={x0:g} m, where "
                             f"the contact wire hangs at {z:.3f} m; on the roof ({ROOF_HEIGHT_M:g} m) it reaches the "
                             f"wire only at {WIRE_HEIGHT_M:g} m (+-{1e3 * REACH_TOLERANCE_M:g} mm), at a support: "
                             "allowed are spans >= analysis_spans + 2")
    return section, x0, duration


def run(p: dict):
    design = design_from(p)
    _, _, duration = check(p, design)
    speed = p["speed_ms"]
    target = en50367_mean_force(3.6 * speed) if p["static_force_N"] == -1.0 else p["static_force_N"]
    t0 = time.perf_counter()
    pantograph_on = partial(seo2005_fragment, "penalty", p["contact_stiffness"], p["contact_damping"],
                            p["contact_smoothing"], rod_stiffness=p["rod_stiffness"])
    line = build_vehicle_line(design, lambda base: pantograph_on(base=base), speed, target,
                              profile_pair(p["profile"], 0.05), elements_per_span=p["elements_per_span"],
                              analysis_spans=analysis_spans(p), t_end=duration,
                              creep=CREEP_LAWS[p["creep"]],
                              friction_coefficient=p["friction_coefficient"], lateral_offset_m=p["lateral_offset_m"],
                              progress=p["progress"])
    build_wall = time.perf_counter() - t0
    model, layout = line.model, line.layout
    settings = IdasSettings(rtol=p["rtol"], atol=wire_atol(model, p["rtol"] * 1e-2),
                            n_out=max(10, round(p["n_out"] * duration)), progress=p["progress"])
    t1 = time.perf_counter()
    try:
        res = integrate_model(model, p, duration, p["formulation"], p["index"], settings)
    except SolverError as err:
        raise SolverError(f"{err} (seo2005_line: vehicle, pantograph and benchmark line; try a tighter rtol on idas, "
                          "a shorter dt on generalized_alpha)",
                          partial=err.partial) from err
    run_wall = time.perf_counter() - t1
    result = vehicle_passage_result(line, res, speed, "penalty", wall_s=build_wall + run_wall)
    wheels = wheel_forces(res, layout)
    names = layout.contact_names
    q0 = [float(wheels[n]["Q_N"][0]) for n in names]
    weight = (layout.parameters.total_mass_kg + line.pantograph_mass_kg) * -model.scene.gravity_vector()[2]
    extra = {
        "speed_ms": speed, "spans": p["spans"], "wire_height_m": WIRE_HEIGHT_M, "roof_height_m": ROOF_HEIGHT_M,
        "uplift_N": line.uplift_N, "static_contact_force_N": line.static_contact_force_N,
        "target_static_contact_force_N": line.target_force_N, "uplift_static_solves": line.static_solves,
        "static_residual_N": line.equilibrium.residual_N,
        "static_constraint_residual_m": line.equilibrium.constraint_residual,
        "base_hinge_height_m": line.base_hinge_height_m, "pantograph_mass_kg": line.pantograph_mass_kg,
        "car_body_load_N": line.car_body_load_N,
        "static_wheel_load_sum_N": float(np.sum(q0)),
        "static_weight_and_push_N": float(weight + line.static_contact_force_N),
        "static_vertical_momentum_rate_N": float(momentum_rate_N(res, layout)[0, 2]),
        "contact_force_run_mean_N": float(np.mean(result.record.contact_force_N[:, 0])),
        "contact_force_run_std_N": float(np.std(result.record.contact_force_N[:, 0])),
        **wheel_summary(res, layout, wheels),
        "build_wall_s": build_wall, "integration_wall_s": run_wall, "integrator": p["integrator"],
    }
    out = passage_output(result, p, "seo2005_line", extra)
    out.stats.update({f"{k}_wall_s": v for k, v in line.wall_s.items()})
    out.arrays.update(line=line, simulation=res, layout=layout)
    return out


MODEL = Model("seo2005_line", "the seed's vehicle and four-body pantograph under the 2015 benchmark line (form-found "
              "catenary), from their joint static equilibrium", PARAMETERS, run)
