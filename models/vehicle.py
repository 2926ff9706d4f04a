"""The seed paper's railroad vehicle (Figures 8 and 9) on tangent track or into a curve, with
constraint wheel/rail contact.

Measured irregularities on tangent track: ``irregularity_file`` names a CSV file with a header
row, ``s_m`` (distance along the track from the vehicle centre's start, m) and any of
``alignment_m``, ``level_m``, ``cross_level_m``, ``gauge_m`` (m;
:func:`symcat.wheelrail.track.read_irregularities`); the track is then a tangent
:class:`symcat.wheelrail.track.TrackLayout` carrying them (slower: its DAE is not compiled).

A car body on two bogies; each bogie has a frame, a bolster, two equalizer bars and two
wheelsets (:mod:`symcat.vehicle`: Manchester benchmark vehicle 1 with documented, assumed values
for the bolsters and equalizer bars), eight wheel/rail contacts by the constraint formulation
(seed eq. 22) with creep forces, and the leading wheelset of each bogie driven at ``speed_ms``
(a driving constraint, as in the seed paper, or a traction servo). The vehicle starts in static
equilibrium, displaced ``lateral_offset_m`` toward the left rail, and runs for ``t_end``.

With ``curve_radius_m > 0`` the track (:func:`symcat.vehicle.curve_track`) is a tangent lead-in
holding the whole vehicle (its outermost wheelsets 1 m from its ends), a clothoid transition of
``transition_length_m`` that ramps the curvature and the cant (``cant_m``, the outer rail's
superelevation), and a circular curve of ``curve_radius_m`` to the ``curve_direction``, long
enough for the run (``speed_ms * t_end + 10`` m). The driving constraint cannot follow a curve:
``drive="auto"`` (default) is the seed paper's constraint on tangent track and the traction
servo in a curve. A cant needs the index-1 form (``index="1"``): the ends of a cant ramp are
kinks of the rails, crossed as impacts, which the GGL form does not carry over.

Summary
-------
``weight_N``
    Weight of the vehicle (N).
``wheel_names``
    Contact names, in the order of the lists below (bogie ``b1`` leads; ``ws1`` is the leading
    wheelset of a bogie).
``normal_force_static_N``
    Normal force of each wheel at t = 0 (N).
``vertical_force_static_sum_N``, ``vertical_momentum_rate_static_N``
    At t = 0: the sum of the wheels' vertical forces (normal and creep forces along the track's
    up axis, N) and the rate of change of the vehicle's vertical momentum, the sum of ``m a_z``
    over its bodies (N). By Newton's second law the sum is ``weight_N +
    vertical_momentum_rate_static_N`` (to rounding, on level track). Centred, the vehicle starts
    at rest and the sum is the weight (to 1e-9 N). Displaced, it does not start in equilibrium:
    the suspensions start undeflected with the centred vehicle's vertical preloads, so nothing
    holds the wheelsets against the net lateral rail force (normal forces tilted by the unequal
    contact angles, lateral creep) and they accelerate toward the track centre; a wheelset's
    height on its rails changes with its lateral position, so they also fall. S1002 at the
    default 2 mm: 0.463 m/s^2 lateral, dz/dy = 0.0357, 0.0165 m/s^2 down each, -120 N for the
    four (the sum 452729 N against the weight 452849 N); the conical 1:20 pair's dz/dy is
    0.00028.
``normal_force_min_N``, ``normal_force_max_N``
    Extremes of each wheel's normal force over the run (N).
``lateral_displacement_max_m``
    Largest lateral displacement of each wheelset from the track centre line (m, in the track
    frame at its chainage).
``derailment_quotient_max``
    Largest Y/Q of each wheel (lateral force toward the track centre over vertical force, in
    the track frame at the contact).
``lateral_force_sum_N``
    Net track-lateral force of the rails on the vehicle at the end of the run (N, toward the
    left rail; each wheel's in the track frame at its contact).
``lateral_force_quasi_static_N``
    The same for steady curving, ``M (kappa v^2 cos phi + g sin phi)``, with the curvature and
    cant angle at the rear wheelset and the car body's speed at the end (N; meaningful once the
    whole vehicle is in the circular curve and settled; 0 on tangent track).
``wall_s``, ``simulated_s``, ``wall_per_simulated_s``, ``max_position_drift_m``
"""
from __future__ import annotations

import numpy as np

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError, SolverError
from symcat.integrate import IdasSettings
from symcat.integrate.settings import VELOCITY_ATOL_FACTOR
from symcat.model import Model, ModelOutput, Parameter, existing_file
from symcat.scene import Scene
from symcat.simulation import integrate_model, integrator_parameters
from symcat.vehicle import (DRIVES, VehicleParameters, add_vehicle, curve_track, lateral_displacement_m,
                            lateral_force_sum_N, momentum_rate_N, steady_curving_forces_N, wheel_forces)
from symcat.wheelrail import PAIR_NAMES, profile_pair
from symcat.wheelrail.track import Tangent, TrackLayout, rail_offset_for, read_irregularities

G = 9.81

PARAMETERS = [
    Parameter("profile", "s1002_uic60", "", "wheel/rail profiles", choices=PAIR_NAMES),
    Parameter("conicity", 0.05, "-", "tread conicity of the conical profile", minimum=0.0, maximum=0.5,
              exclusive_minimum=True),
    Parameter("speed_ms", 17.0, "m/s", "forward speed", minimum=0.0, maximum=100.0, exclusive_minimum=True),
    Parameter("creep", "linear", "", "creep forces", choices=("none", "linear", "nonlinear")),
    Parameter("friction_coefficient", 0.3, "-", "friction coefficient of the nonlinear law", minimum=0.0, maximum=1.0,
              exclusive_minimum=True),
    Parameter("drive", "auto", "", "leading wheelsets: driving constraint or traction servo (auto: the constraint on "
              "tangent track, the servo in a curve)", choices=("auto",) + DRIVES),
    Parameter("lateral_offset_m", 0.002, "m", "initial lateral displacement toward the left rail", minimum=-0.008,
              maximum=0.008),
    Parameter("curve_radius_m", 0.0, "m", "radius of the circular curve after the lead-in; 0: tangent track",
              minimum=0.0),
    Parameter("curve_direction", "left", "", "side of the curve centre", choices=("left", "right")),
    Parameter("cant_m", 0.0, "m", "superelevation of the outer rail in the curve (needs a transition)", minimum=0.0,
              maximum=0.2),
    Parameter("transition_length_m", 20.0, "m", "clothoid transition ramping curvature and cant into the curve",
              minimum=0.0),
    Parameter("cant_ramp", "smooth", "", "superelevation ramp of the transition: smooth (Bloss's cubic, no kinks "
              "of the rails) or linear (its ends are kinks, impacts the vehicle's rigid contacts do not get past)",
              choices=("smooth", "linear")),
    Parameter("t_end", 1.0, "s", "simulated time", minimum=0.0, exclusive_minimum=True),
    Parameter("index", "ggl", "", "constraint stabilization: GGL (positions held) or index 1 with Baumgarte (on "
              "the vehicle its drift grows until IDAS fails, about 0.1 s at 17 m/s; in a curve it crawls)",
              choices=("ggl", "1")),
    Parameter("rtol", 1e-7, "-", "IDAS relative tolerance", minimum=0.0, maximum=0.1, exclusive_minimum=True),
    Parameter("atol", 0.0, "m", "IDAS absolute tolerance of positions (m, rad) and velocities (m/s, rad/s); 0: rtol/10",
              minimum=0.0, maximum=0.1),
    Parameter("atol_velocity", 0.0, "m/s", "IDAS absolute tolerance of the velocities (m/s, rad/s); 0: 10 x atol "
              "(positions accurate to atol over motions up to 10 rad/s). Against atol itself: a quarter to a half "
              "fewer steps at similar errors, and none of the error-test failures of the stiff creep modes at "
              "rtol 1e-5 (bench/report/vehicle.md)", minimum=0.0, maximum=1.0),
    Parameter("n_out", 100, "-", "output intervals", minimum=10, maximum=100000),
    Parameter("irregularity_file", "", "", "CSV of measured track irregularities on tangent track: header s_m (from "
              "the vehicle centre's start, m) and any of alignment_m, level_m, cross_level_m, gauge_m (m); empty: "
              "ideal track",
              text="the path of a CSV file, or nothing", check=existing_file),
    *integrator_parameters(),
]

#: Track beyond the outermost wheelsets on a tangent layout with irregularities (m).
TRACK_MARGIN_M = 5.0


def track_for(p: dict, pair, parameters: VehicleParameters):
    """The track layout and the vehicle's start chainage (m) for parameters ``p``: ``(None,
    0.0)`` (tangent track) unless ``curve_radius_m > 0``."""
    if p.get("curve_radius_m", 0.0) <= 0:
        if p.get("cant_m", 0.0) > 0:
            raise ParameterError(f"cant_m={p['cant_m']:g}: a cant needs a curve (curve_radius_m > 0)")
        return irregular_track(p, pair, parameters)
    if p.get("irregularity_file"):
        raise ParameterError(f"irregularity_file={p['irregularity_file']!r}: irregularities need tangent track "
                             "(curve_radius_m = 0)")
    return curve_track(pair, p["curve_radius_m"], cant_m=p["cant_m"], transition_length_m=p["transition_length_m"],
                       curve_length_m=p["speed_ms"] * p["t_end"] + 10.0, direction=p["curve_direction"],
                       parameters=parameters, cant_ramp=p.get("cant_ramp", "smooth"))


def irregular_track(p: dict, pair, parameters: VehicleParameters):
    """``(track, x_m)``: tangent track along global ``x`` carrying the irregularities of
    ``p["irregularity_file"]`` and the chainage of the vehicle centre's start (global ``x = 0``,
    the file's ``s_m = 0``), or ``(None, 0.0)`` without a file."""
    path = p.get("irregularity_file", "")
    if not path:
        return None, 0.0
    lead = parameters.bogie_semi_distance_m + parameters.semi_wheelbase_m + TRACK_MARGIN_M
    try:
        irregularities = read_irregularities(path, start_m=lead)
    except ParameterError as err:
        raise ParameterError(f"irregularity_file={path!r}: {err}") from None
    track = TrackLayout([Tangent(2 * lead + p["speed_ms"] * p["t_end"])], rail_offset_m=rail_offset_for(pair.rail),
                        irregularities=irregularities, start_position_m=(-lead, 0.0, 0.0))
    return track, lead


def build(p: dict):
    """Scene, layout and assembled model for parameters ``p``."""
    scene = Scene(gravity=(0.0, 0.0, -G))
    pair = profile_pair(p["profile"], p["conicity"])
    parameters = VehicleParameters()
    track, x_m = track_for(p, pair, parameters)
    curved = p.get("curve_radius_m", 0.0) > 0
    drive = p["drive"] if p["drive"] != "auto" else ("torque" if curved else "constraint")
    layout = add_vehicle(scene, pair, speed_ms=p["speed_ms"], creep={"nonlinear": "polach"}.get(p["creep"], p["creep"]),
                         friction_coefficient=p["friction_coefficient"], drive=drive,
                         lateral_offset_m=p["lateral_offset_m"], parameters=parameters, track=track, x_m=x_m)
    return scene, layout, MultibodyModel(scene)


def quasi_static_lateral_force_N(res, layout) -> float:
    """Steady-curving lateral force sum (N) at the end of the run: curvature and cant angle at
    the rear wheelset's chainage, the car body's speed (:func:`steady_curving_forces_N`)."""
    if layout.track is None:
        return 0.0
    rear = layout.contacts[layout.wheelsets[-1]]
    s = float(np.mean([res.wheelrail[rear[side]]["s"][-1, 2] for side in rear]))
    i = res.coordinate_names.index(f"{layout.car_body}.x")
    speed = float(np.linalg.norm(res.v[-1, i : i + 3]))
    kappa, phi = float(layout.track.curvature(s)[0]), float(layout.track.cant_angle(s)[0])
    return steady_curving_forces_N(layout.parameters.total_mass_kg, speed, kappa, phi)[0]


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
        "vertical_momentum_rate_static_N": float(momentum_rate_N(res, layout)[0, 2]),
        "normal_force_min_N": [float(forces[n]["normal_N"].min()) for n in names],
        "normal_force_max_N": [float(forces[n]["normal_N"].max()) for n in names],
        "lateral_displacement_max_m": [float(np.abs(y).max()) for y in lateral_displacement_m(res, layout).values()],
        "derailment_quotient_max": yq,
        "lateral_force_sum_N": float(lateral_force_sum_N(forces)[-1]),
        "lateral_force_quasi_static_N": quasi_static_lateral_force_N(res, layout),
        "wall_s": float(res.stats["wall_s"]),
        "simulated_s": float(res.t_s[-1]),
        "wall_per_simulated_s": float(res.stats["wall_s"] / max(res.t_s[-1], 1e-12)),
        "max_position_drift_m": float(res.position_drift.max()),
    }


def run(p: dict) -> ModelOutput:
    _, layout, model = build(p)
    try:
        atol = p.get("atol") or 0.1 * p["rtol"]
        settings = IdasSettings(rtol=p["rtol"], atol=atol,
                                velocity_atol=p.get("atol_velocity") or VELOCITY_ATOL_FACTOR * atol,
                                n_out=int(p["n_out"]), progress=p.get("progress", True))
        res = integrate_model(model, p, p["t_end"], "augmented", p["index"], settings)
    except SolverError as err:
        hint = ("; cant_ramp=smooth (the ends of a linear cant ramp are kinks of the rails, impacts the rigid "
                "contacts do not get past)") if p.get("cant_m", 0.0) > 0 and p.get("cant_ramp") == "linear" else ""
        raise SolverError(f"{err} (vehicle model: try index=ggl or a tighter rtol{hint}; a flange contact or a contact "
                          "jump may have been reached)", partial=err.partial) from err
    summary = summarize(res, layout)
    stats = {k: res.stats.get(k) for k in ("nsteps", "nfevals", "nlinsetups", "netfails", "nncfails", "restarts",
                                       "contact_calls", "contact_jumps")}

    def write(out):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from symcat.results.paraview import write_multibody_series
        from symcat.results.timeseries import plot_merged, repeats

        res.save(out / "vehicle.npz")
        forces = wheel_forces(res, layout)
        fig, axes = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
        # curves equal to within 0.2 % of a panel's range share one line and one legend entry
        # ("b1_ws1 = b2_ws1"): on tangent track bogie 2 often repeats bogie 1 exactly
        panels = [{w: y * 1e3 for w, y in lateral_displacement_m(res, layout).items()},
                  {n: forces[n]["normal_N"] / 1e3 for n in layout.contact_names},
                  {n: forces[n]["Y_over_Q"] for n in layout.contact_names}]
        groups = [plot_merged(ax, res.t_s, curves, lw=1) for ax, curves in zip(axes, panels)]
        hidden = sum(len(group) - 1 for panel in groups for group in panel)
        note = ("\nbogie 2's curves lie on bogie 1's (to 0.2 % of each panel's range): one line each, b1_... = b2_..."
                if all(repeats(panel, "b1", "b2") for panel in groups) else
                f"\n{hidden} curves lie on others (to 0.2 % of the panel's range): one line each, labels joined by ="
                if hidden else "")
        axes[0].set_ylabel("wheelset lateral [mm]")
        where = f", curve R {p['curve_radius_m']:g} m, cant {p['cant_m'] * 1e3:g} mm" if p["curve_radius_m"] > 0 else ""
        axes[0].set_title(f"vehicle, {p['profile']}, {p['speed_ms']:g} m/s, creep {p['creep']}{where}{note}",
                          fontsize=9)
        axes[1].set_ylabel("normal force [kN]")
        axes[2].set_ylabel("Y/Q [-]")
        axes[2].set_xlabel("time [s]")
        for ax in axes:
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
            ax.grid(alpha=0.3)
        fig.tight_layout()
        path = out / "vehicle.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        pvd = write_multibody_series(model, res.t_s, res.q, out / "paraview", "vehicle")
        return [path, out / "vehicle.npz", pvd]

    return ModelOutput(summary, stats, {"result": res, "layout": layout}, write)


MODEL = Model("vehicle", "the seed paper's railroad vehicle (car body, two bogies with frames, bolsters, equalizer "
              "bars and wheelsets) with constraint wheel/rail contact", PARAMETERS, run)
