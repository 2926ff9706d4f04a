"""Wheel forces of a simulated vehicle: the contact force on each wheel, its lateral and
vertical components in the track frame at the contact, the derailment quotient Y/Q, and the
wheelsets' lateral displacements relative to the track.

Frames (:mod:`symcat.wheelrail.track`): at a contact's chainage ``s1r`` the canted track frame
has columns tangent, lateral (toward the left rail, in the running plane: horizontal on uncanted
track) and up (normal to the running plane). On tangent track without cant they are the global
axes, so the components are the global ``y`` and ``z`` ones.
"""
from __future__ import annotations

import numpy as np

from ..wheelrail.track_pieces import rail_frames, rot_x

SIDE_SIGN = {"left": 1.0, "right": -1.0}


def contact_frames(layout, side: str, s, frames=None):
    """Creep frame and track axes of the wheels on rail ``side`` at surface parameters ``s``.

    Parameters
    ----------
    layout : VehicleLayout
        From :func:`symcat.vehicle.add_vehicle` (its profile pair and track).
    side : {"left", "right"}
    s : ndarray (n, 4)
        Surface parameters ``[s1w, s2w, s1r, s2r]`` over the outputs (m, rad, m, m).
    frames : TangentRailFrames or TrackRailFrames, optional
        The rail frames of ``side`` (:func:`symcat.wheelrail.track_pieces.rail_frames`), to
        reuse; built from ``layout`` if omitted.

    Returns
    -------
    t1, n : ndarray (n, 3)
        Unit rail tangent along the track at the contact (the creep force's ``t1``, as
        :func:`symcat.assembly.wheelrail.creep_function` builds it) and the rail's unit outward
        normal; ``t2 = n x t1``.
    axes : ndarray (n, 3, 3)
        Canted track frame at the contact's chainage (columns tangent, lateral to the left, up).
    """
    s = np.atleast_2d(np.asarray(s, float))
    frames = frames or rail_frames(layout.pair.rail, side, layout.track)
    _, A, dR, dA = frames.frames(s[:, 2])
    sign = SIDE_SIGN[side]
    pr, dr = layout.pair.rail.position(s[:, 3]), layout.pair.rail.derivative(s[:, 3])
    u = np.stack([np.zeros(len(s)), sign * pr[:, 0], pr[:, 1]], axis=1)
    du = np.stack([np.zeros(len(s)), sign * dr[:, 0], dr[:, 1]], axis=1)
    t1 = dR + np.einsum("nij,nj->ni", dA, u)
    t1 = t1 / np.linalg.norm(t1, axis=1, keepdims=True)
    n = sign * np.cross(t1, np.einsum("nij,nj->ni", A, du))
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    axes = A @ rot_x(-frames.roll_rad)  # the rail frame without the rail's own inclination
    return t1, n, axes


def wheel_forces(result, layout) -> dict:
    """Contact force components of every wheel over time.

    The force the rail exerts on the wheel is the constraint force of the contact (its normal
    force, from the multipliers: ``result.reactions_N``) plus the creep forces along the contact
    frame ``t1`` (the rail tangent along the track at the contact: global ``x`` on tangent
    track) and ``t2 = n x t1`` (``n`` the rail's outward normal). The lateral and vertical
    components are taken in the track frame at the contact (module docstring).

    Returns
    -------
    dict
        ``{contact name: {"Y_N", "Q_N", "Y_over_Q", "normal_N", "lateral_N", "force_N"}}``
        (arrays over the outputs): ``Q_N`` the force on the wheel along the track's up axis (N),
        ``lateral_N`` along the track's lateral axis, positive toward the left rail (N),
        ``Y_N`` the same positive toward the track centre (the direction a flange contact pushes
        the wheel; Nadal's criterion bounds ``Y / Q``), the normal force (N) and the whole
        force in global components, ``force_N`` (n, 3).
    """
    out = {}
    frames = {side: rail_frames(layout.pair.rail, side, layout.track) for side in SIDE_SIGN}
    for wheelset in layout.wheelsets:
        for side, name in layout.contacts[wheelset].items():
            reaction = np.asarray(result.reactions_N[name], float)
            rec = result.wheelrail[name]
            t1, n, axes = contact_frames(layout, side, rec["s"], frames[side])
            t2 = np.cross(n, t1)
            force = reaction + rec["fx_N"][:, None] * t1 + rec["fy_N"][:, None] * t2
            lateral = np.einsum("ni,ni->n", force, axes[:, :, 1])
            q_n = np.einsum("ni,ni->n", force, axes[:, :, 2])
            y_n = -SIDE_SIGN[side] * lateral   # the left rail is at +y: inward is -y there
            out[name] = {"Y_N": y_n, "Q_N": q_n, "Y_over_Q": y_n / np.where(np.abs(q_n) > 0, q_n, np.nan),
                         "normal_N": np.asarray(rec["normal_force_N"], float), "lateral_N": lateral,
                         "force_N": force}
    return out


def lateral_force_sum_N(forces: dict) -> np.ndarray:
    """Sum over all wheels of the track-lateral force toward the left rail (N, per output): the
    net lateral force of the rails on the vehicle, each wheel's in its own track frame."""
    return np.sum([f["lateral_N"] for f in forces.values()], axis=0)


def momentum_rate_N(result, layout) -> np.ndarray:
    """Rate of change of the vehicle's linear momentum, the sum of ``m a`` over its bodies (N,
    global components, (n, 3) over the outputs; the accelerations ``result.a`` of the same KKT
    solve as the contact forces).

    By Newton's second law it equals the sum of the external forces on the vehicle: gravity, the
    rail forces of :func:`wheel_forces`, the driving constraint's force (along the track) and
    whatever else in the scene acts on the vehicle (e.g. a pantograph on the car body). On
    level tangent track the sum of the wheels' ``Q_N`` is therefore the weight plus its ``z``
    component, and the sum of their ``lateral_N`` its ``y`` component.
    """
    total = np.zeros((len(result.t_s), 3))
    for body, mass in layout.body_masses_kg.items():
        i = result.coordinate_names.index(f"{body}.x")
        total += mass * np.asarray(result.a[:, i : i + 3], float)
    return total


def lateral_displacement_m(result, layout) -> dict:
    """Lateral displacement of each wheelset's axle centre from the track centre line toward
    the left rail, in the track frame at its chainage (m; ``{wheelset: (n,)}``). On tangent
    track: its global ``y`` coordinate."""
    out = {}
    for w in layout.wheelsets:
        if layout.track is None:
            out[w] = result.coordinate(f"{w}.y")
            continue
        position = np.stack([result.coordinate(f"{w}.{c}") for c in "xyz"], axis=1)
        names = layout.contacts[w]
        s = 0.5 * (result.wheelrail[names["left"]]["s"][:, 2] + result.wheelrail[names["right"]]["s"][:, 2])
        out[w] = track_offset(layout.track, position, s)[0]
    return out


def track_offset(track, position_m, s_guess_m):
    """Lateral offset (m, toward the left) of global points ``position_m`` (n, 3) from the
    centre line of ``track`` in its track frame, and their chainage (m): the cross-section
    through each point, by fixed-point iterations from ``s_guess_m`` (n,)."""
    p = np.asarray(position_m, float)
    s = np.clip(np.asarray(s_guess_m, float), 0.0, track.length_m)
    for _ in range(6):
        f = track.track_frame(s)
        s = np.clip(s + np.einsum("ni,ni->n", p - f.R, f.A[:, :, 0]), 0.0, track.length_m)
    f = track.track_frame(s)
    return np.einsum("ni,ni->n", p - f.R, f.A[:, :, 1]), s


def wheel_summary(result, layout, wheels: dict | None = None) -> dict:
    """The wheel/rail summary keys of the models that run the vehicle (``seo2005``,
    ``seo2005_line``): ``wheel_names``, each wheel's normal force at the start, its minimum and
    maximum (N), and each wheelset's largest lateral displacement (m). ``wheels``: the
    :func:`wheel_forces` of the run, if at hand."""
    wheels = wheel_forces(result, layout) if wheels is None else wheels
    names = layout.contact_names
    return {
        "wheel_names": names,
        "wheel_normal_force_static_N": [float(wheels[n]["normal_N"][0]) for n in names],
        "wheel_normal_force_min_N": [float(wheels[n]["normal_N"].min()) for n in names],
        "wheel_normal_force_max_N": [float(wheels[n]["normal_N"].max()) for n in names],
        "wheelset_lateral_displacement_max_m": [float(np.abs(result.coordinate(f"{w}.y")).max())
                                                for w in layout.wheelsets],
    }
