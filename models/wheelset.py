"""One wheelset on straight track with constraint wheel/rail contact (seed paper, Section 4).

The wheelset (Manchester benchmark vehicle 1: 1813 kg; Ixx, Iyy, Izz = 1120, 112, 1120 kg m^2;
r0 = 0.46 m, tape circles 1.5 m apart) carries a vertical ``axle_load_N`` on its axle centre
(default: its share of the Manchester car body and bogie frames, (32000 + 2 x 2615) kg / 4 x
9.81 m/s^2) and is driven along the track at ``speed_ms`` (a driving constraint on its centre);
it is otherwise free: lateral, yaw, roll, bounce and spin follow from the two contacts. Each
wheel touches its rail by the constraint formulation (four surface parameters, five
constraints, the normal force a Lagrange multiplier); creep forces are Kalker's linear theory
(``creep=linear``) or Polach's saturating law (``nonlinear``, friction ``friction_coefficient``)
with the Hertz ellipse of the static load, or absent (``none``: frictionless wheels, only the
gravitational stiffness of the contact angles acts). The run starts from the wheelset resting
at ``lateral_offset_m`` toward the left rail, rolling without slip.

Measured track irregularities: ``irregularity_file`` names a CSV file with a header row,
``s_m`` (distance along the track from the wheelset's start, m, at least 4 strictly increasing
values) and any of ``alignment_m`` (lateral, toward the left rail), ``level_m`` (up),
``cross_level_m`` (left rail over right), ``gauge_m`` (widening), all in m
(:func:`symcat.wheelrail.track.read_irregularities`; zero outside the file's range: taper the
data to zero at its ends). The track is then a tangent :class:`symcat.wheelrail.track.TrackLayout`
carrying them (the same straight track along global ``x``, evaluated through the layout's rail
frames: slower, the DAE is not compiled). Empty (default): ideal track.

Summary
-------
``lateral_wavelength_m``
    Mean distance travelled between successive upward zero crossings of the lateral
    displacement (NaN with fewer than two crossings).
``klingel_wavelength_m``
    Klingel's ``2 pi sqrt(r0 b / gamma)`` with ``r0`` and ``b`` (half the distance between the
    contact points) of the centred wheelset and ``gamma = Delta r / (2 y0)`` at the offset.
``normal_force_left_N``, ``normal_force_right_N``, ``rolling_radius_difference_m``
    At the static offset (t = 0): normal forces from the multipliers and ``r_left - r_right``.
``normal_force_min_N``
    Smallest normal force of either wheel over the run (0 while a wheel is lifted: the rail-frame
    contacts open and land again, :mod:`symcat.wheelrail_events.contact_switching`; a wheel running off
    its rail ends the run with an error).

The contact point of each wheel jumps where another point of the profiles comes lower (see
:mod:`symcat.wheelrail_events.contact_jumps`; ``contact_jumps`` in the statistics).
"""
from __future__ import annotations

import math

import numpy as np

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError, SolverError
from symcat.integrate import IdasSettings
from symcat.integrate.settings import VELOCITY_ATOL_FACTOR
from symcat.model import Model, ModelOutput, Parameter, existing_file
from symcat.scene import CreepModel, Driving, PointLoad, RigidBody, Scene, WheelRailJoint
from symcat.simulation import integrate_model, integrator_parameters
from symcat.vehicle import wheelset_on_track
from symcat.wheelrail import PAIR_NAMES, WheelsetDimensions, profile_pair
from symcat.wheelrail.track import Tangent, TrackLayout, rail_offset_for, read_irregularities

G = 9.81
MASS_KG = 1813.0
INERTIA_KG_M2 = (1120.0, 112.0, 1120.0)
SPRUNG_SHARE_N = (32000.0 + 2 * 2615.0) / 4 * G

PARAMETERS = [
    Parameter("profile", "conical", "", "wheel/rail profiles", choices=PAIR_NAMES),
    Parameter("conicity", 0.05, "-", "tread conicity of the conical profile", minimum=0.0, maximum=0.5,
              exclusive_minimum=True),
    Parameter("lateral_offset_m", 0.003, "m", "initial lateral displacement toward the left rail", minimum=-0.008,
              maximum=0.008),
    Parameter("speed_ms", 5.0, "m/s", "forward speed", minimum=0.0, maximum=100.0, exclusive_minimum=True),
    Parameter("creep", "linear", "", "creep forces", choices=("none", "linear", "nonlinear")),
    Parameter("friction_coefficient", 0.3, "-", "friction coefficient of the nonlinear law", minimum=0.0, maximum=1.0,
              exclusive_minimum=True),
    Parameter("axle_load_N", SPRUNG_SHARE_N, "N", "vertical load on the axle centre (besides the wheelset's weight)",
              minimum=0.0),
    Parameter("t_end", 8.0, "s", "simulated time", minimum=0.0, exclusive_minimum=True),
    Parameter("formulation", "augmented", "", "equations of motion: seed eq. 25 or 26",
              choices=("augmented", "embedded")),
    Parameter("rtol", 1e-6, "-", "IDAS relative tolerance", minimum=0.0, maximum=0.1, exclusive_minimum=True),
    Parameter("atol", 0.0, "m", "IDAS absolute tolerance of positions (m, rad); 0: rtol/100 (1e-8 at the default "
              "rtol; a fixed 1e-8 made IDAS fail half its error tests at rtol 1e-4 and 1e-5)", minimum=0.0,
              maximum=0.1),
    Parameter("atol_velocity", 0.0, "m/s", "IDAS absolute tolerance of the velocities (m/s, rad/s); 0: 10 x atol "
              "(positions accurate to atol over motions up to 10 rad/s)", minimum=0.0, maximum=1.0),
    Parameter("n_out", 400, "-", "output intervals", minimum=10, maximum=100000),
    Parameter("irregularity_file", "", "", "CSV of measured track irregularities: header s_m (from the start, m) and "
              "any of alignment_m, level_m, cross_level_m, gauge_m (m); empty: ideal track",
              text="the path of a CSV file, or nothing", check=existing_file),
    *integrator_parameters(),
]

#: Track behind the wheelset's start on a layout with irregularities (m): its contact points
#: sit a little behind the axle when it yaws.
LEAD_M = 2.0
#: Track beyond the distance run (m).
TAIL_M = 10.0


def build(p: dict):
    """Scene, assembled model and the static placement of the wheelset for parameters ``p``."""
    pair = profile_pair(p["profile"], p["conicity"])
    dims = WheelsetDimensions(tape_circle_distance_m=1.5, nominal_radius_m=0.46)
    track = irregular_track(p, pair)
    try:
        placed = wheelset_on_track(pair.wheel, pair.rail, p["lateral_offset_m"], wheelset=dims, x_m=LEAD_M if track
                                   else 0.0, track=track)
    except ParameterError as err:
        raise ParameterError(f"lateral_offset_m={p['lateral_offset_m']:g}: {err}") from None
    v = p["speed_ms"]
    r_mean = 0.5 * (placed.contacts["left"].rolling_radius_m + placed.contacts["right"].rolling_radius_m)
    scene = Scene(gravity=(0.0, 0.0, -G))
    # Rolling without slip at the mean radius: spin about the axle (the body y axis).
    spin = placed.rotation[:, 1] * v / r_mean
    scene.add(RigidBody("wheelset", MASS_KG, INERTIA_KG_M2, position=placed.position_m, rotation=placed.rotation,
                        velocity=(v, 0.0, 0.0), angular_velocity=tuple(spin)))
    if p["axle_load_N"] > 0:
        scene.add(PointLoad("axle_load", "wheelset", force=(0.0, 0.0, -p["axle_load_N"])))
    creep = None
    if p["creep"] != "none":
        creep = CreepModel("linear" if p["creep"] == "linear" else "polach",
                           nominal_normal_force_N=0.5 * (MASS_KG * G + p["axle_load_N"]),
                           friction_coefficient=p["friction_coefficient"])
    for side in ("left", "right"):
        scene.add(WheelRailJoint(f"{side}_wheel", "wheelset", side, pair.wheel, pair.rail, wheelset=dims, creep=creep,
                                 track=track))
    scene.add(Driving("forward_speed", "wheelset", direction=(1.0, 0.0, 0.0), velocity=v))
    return scene, MultibodyModel(scene), placed, pair


def irregular_track(p: dict, pair):
    """Tangent track along global ``x`` carrying the irregularities of ``p["irregularity_file"]``
    (``s_m = 0`` at the wheelset's start, ``x = 0``), or None without a file."""
    path = p.get("irregularity_file", "")
    if not path:
        return None
    try:
        irregularities = read_irregularities(path, start_m=LEAD_M)
    except ParameterError as err:
        raise ParameterError(f"irregularity_file={path!r}: {err}") from None
    length = LEAD_M + p["speed_ms"] * p["t_end"] + TAIL_M
    return TrackLayout([Tangent(length)], rail_offset_m=rail_offset_for(pair.rail), irregularities=irregularities,
                       start_position_m=(-LEAD_M, 0.0, 0.0))


def wavelength(x: np.ndarray, y: np.ndarray) -> float:
    """Mean distance between successive upward zero crossings of ``y(x)`` (NaN if fewer than two)."""
    up = [x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i]) for i in range(len(y) - 1) if y[i] < 0 <= y[i + 1]]
    return float(np.mean(np.diff(up))) if len(up) >= 2 else math.nan


def klingel_wavelength(pair, placed, dims=None) -> float:
    """Klingel's wavelength from the centred contact points and the conicity at the offset."""
    centred = wheelset_on_track(pair.wheel, pair.rail, 0.0, wheelset=dims)
    b = 0.5 * (centred.contacts["left"].point_m[1] - centred.contacts["right"].point_m[1])
    r0 = centred.contacts["left"].rolling_radius_m
    y0 = placed.position_m[1]
    dr = placed.contacts["left"].rolling_radius_m - placed.contacts["right"].rolling_radius_m
    if abs(y0) < 1e-6 or dr / y0 <= 0:
        return math.nan
    return 2 * math.pi * math.sqrt(r0 * b * 2 * y0 / dr)


def run(p: dict) -> ModelOutput:
    scene, model, placed, pair = build(p)
    try:
        atol = p.get("atol") or 0.01 * p["rtol"]
        settings = IdasSettings(rtol=p["rtol"], atol=atol,
                                velocity_atol=p.get("atol_velocity") or VELOCITY_ATOL_FACTOR * atol,
                                n_out=int(p["n_out"]), progress=p.get("progress", True))
        res = integrate_model(model, p, p["t_end"], p["formulation"], "1", settings)
    except SolverError as err:
        raise SolverError(f"{err} (wheelset model: one constraint contact point per wheel, which jumps to the "
                          "lowest point of the gap; a free wheelset hunts, and at speed its flanges strike)",
                          partial=err.partial) from err
    x, y = res.coordinate("wheelset.x"), res.coordinate("wheelset.y")
    left, right = res.wheelrail["left_wheel"], res.wheelrail["right_wheel"]
    radius = {k: placed.contacts[k].rolling_radius_m for k in ("left", "right")}
    summary = {
        "lateral_wavelength_m": wavelength(x, y),
        "klingel_wavelength_m": klingel_wavelength(pair, placed, WheelsetDimensions(1.5, 0.46)),
        "normal_force_left_N": float(left["normal_force_N"][0]),
        "normal_force_right_N": float(right["normal_force_N"][0]),
        "rolling_radius_difference_m": radius["left"] - radius["right"],
        "lateral_displacement_max_m": float(np.abs(y).max()),
        "wall_s": float(res.stats["wall_s"]),
        "simulated_s": float(p["t_end"]),
        "max_position_drift_m": float(res.position_drift.max()),
        "normal_force_min_N": float(min(left["normal_force_N"].min(), right["normal_force_N"].min())),
    }
    stats = {k: res.stats.get(k, 0) for k in ("nsteps", "nfevals", "netfails", "nncfails", "restarts", "contact_jumps",
                                             "contact_calls", "contact_retries")}
    arrays = {"result": res}

    def write(out):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        res.save(out / "wheelset.npz")
        fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
        axes[0].plot(x, y * 1e3, "k-", lw=1)
        axes[0].set_ylabel("lateral displacement [mm]")
        axes[0].set_title(f"{p['profile']}, {p['speed_ms']:g} m/s, creep {p['creep']}: wavelength "
                          f"{summary['lateral_wavelength_m']:.2f} m (Klingel {summary['klingel_wavelength_m']:.2f} m)",
                          fontsize=9)
        yaw = np.array([math.atan2(*_yaw_parts(q)) for q in res.q[:, model.rigid_offset["wheelset"] + 3:][:, :4]])
        axes[1].plot(x, yaw * 1e3, "b-", lw=1)
        axes[1].set_ylabel("yaw [mrad]")
        axes[2].plot(x, left["normal_force_N"] / 1e3, "b-", lw=1, label="left")
        axes[2].plot(x, right["normal_force_N"] / 1e3, "g--", lw=1, label="right")
        axes[2].set_ylabel("normal force [kN]")
        axes[2].set_xlabel("distance travelled [m]")
        axes[2].legend(fontsize=8)
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.tight_layout()
        path = out / "wheelset.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        from symcat.results.paraview import write_multibody_series

        pvd = write_multibody_series(model, res.t_s, res.q, out / "paraview", "wheelset")
        return [path, out / "wheelset.npz", pvd]

    return ModelOutput(summary, stats, arrays, write)


def _yaw_parts(theta):
    """(sin, cos)-like pair of the yaw angle of the axle (body y axis) from Euler parameters."""
    e0, e1, e2, e3 = theta
    axle = np.array([2 * (e1 * e2 - e0 * e3), 2 * (e0**2 + e2**2) - 1, 2 * (e2 * e3 + e0 * e1)])
    return -axle[0], axle[1]


MODEL = Model("wheelset", "one wheelset on straight track: constraint wheel/rail contact with creep forces",
              PARAMETERS, run)
