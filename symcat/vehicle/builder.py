"""Assemble the seed paper's vehicle (Figures 8 and 9) into a :class:`symcat.scene.Scene`.

Topology (each bogie, centre ``x_b``; ``x`` forward, ``y`` left, ``z`` up, rail top at ``z = 0``):

- two **wheelsets** at ``x_b +- semi_wheelbase``, each wheel on its rail by a
  :class:`WheelRailJoint` (constraint contact, creep forces optional);
- two **equalizer bars** (left, right) resting on the axleboxes of both wheelsets through
  journal pads: a :class:`Bushing` at each axlebox (on the axle line, so the wheelset's spin does
  not move it) with the primary longitudinal and lateral stiffness and a stiff, damped vertical
  pad;
- the **frame** on the equalizer bars: two vertical equalizer springs per bar (the primary
  vertical stiffness and damping) and a guide at the bar's centre (stiff and damped in x and y,
  holding its roll and its yaw: a bar free to yaw would let the wheelsets run as free ones);
- the **bolster** on the frame: the secondary suspension (one bushing per side with the
  benchmark's stiffness, damping and lateral bump stop) and the anti-roll bar (torsion about x);
- the **car body** on both bolsters by a centre plate: a :class:`Revolute` about the vertical
  axis with the secondary yaw stiffness as a :class:`RotationalSpring`.

Every suspension element starts undeflected, with the static load of the symmetric vehicle as
its preload, so the vehicle starts in equilibrium up to the wheel/rail contacts (whose normal
forces are multipliers). The leading wheelset of each bogie is driven at the forward speed,
either by a driving constraint on its centre (seed paper: ``V = 17 m/s``) or by a traction
motor (a speed servo between frame and wheelset).

Curved track: given a :class:`symcat.wheelrail.track.TrackLayout`, the vehicle starts on a
tangent (straight, uncanted) stretch of it, the coordinates above being those of the track frame
there (``x`` the chainage); the wheelsets are placed on the layout and every contact follows it.
The driving constraint holds the velocity along a fixed global direction, so it only suits a
layout without curves; on a curve the traction servo drives (``drive="torque"``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..scene import Bushing, CreepModel, Driving, Revolute, RigidBody, RotationalSpring, Scene, WheelRailJoint
from ..wheelrail import WheelsetDimensions
from ..wheelrail.track import Curve, Tangent, TrackLayout
from .parameters import VehicleParameters
from .placement import wheelset_on_track

BOGIES = ("b1", "b2")          # front (x > 0) and rear
WHEELSETS = ("ws1", "ws2")     # leading and trailing within a bogie
SIDES = ("left", "right")
DRIVES = ("constraint", "torque")
#: Gain of the traction servo (N m per rad/s of spin error).
SERVO_DAMPING_N_M_S = 2e4


@dataclass
class VehicleLayout:
    """Names of what :func:`add_vehicle` put in the scene.

    Attributes
    ----------
    car_body : str
    wheelsets : list of str
        Wheelset bodies, front to rear.
    contacts : dict
        ``{wheelset: {side: wheel/rail joint name}}``.
    frames, bolsters, equalizers : list of str
    placements : dict
        ``{wheelset: WheelsetPlacement}`` at the start.
    parameters : VehicleParameters
    pair : ProfilePair
        Wheel and rail profiles of the contacts.
    track : TrackLayout or None
        The layout the vehicle runs on; ``None``: tangent track along global ``x``.
    """

    car_body: str = "car_body"
    wheelsets: list = field(default_factory=list)           # body names, front to rear
    contacts: dict = field(default_factory=dict)            # wheelset -> {side: joint name}
    frames: list = field(default_factory=list)
    bolsters: list = field(default_factory=list)
    equalizers: list = field(default_factory=list)
    placements: dict = field(default_factory=dict)          # wheelset -> WheelsetPlacement
    parameters: VehicleParameters | None = None
    pair: object = None                                     # ProfilePair of the contacts
    track: TrackLayout | None = None                        # None: tangent track along global x

    @property
    def contact_names(self) -> list[str]:
        return [self.contacts[w][s] for w in self.wheelsets for s in SIDES]

    @property
    def body_masses_kg(self) -> dict:
        """``{body name: mass (kg)}`` of the vehicle's rigid bodies (they sum to
        ``parameters.total_mass_kg``)."""
        p = self.parameters
        out = {self.car_body: p.car_body_mass_kg}
        for names, mass in ((self.frames, p.frame_mass_kg), (self.bolsters, p.bolster_mass_kg),
                            (self.equalizers, p.equalizer_mass_kg), (self.wheelsets, p.wheelset_mass_kg)):
            out.update(dict.fromkeys(names, mass))
        return out


@dataclass(frozen=True)
class _Site:
    """Where the vehicle starts: maps vehicle coordinates (``x`` the chainage, ``y`` left, ``z``
    up from the rail top, m) and directions to global ones. On tangent track (``axes`` None) the
    map is the identity, so positions are passed on unchanged."""

    x_m: float
    origin_m: np.ndarray | None = None   # global centreline point at chainage x_m
    axes: np.ndarray | None = None       # track frame there (columns: tangent, left, up)

    def point(self, p) -> tuple:
        if self.axes is None:
            return tuple(p)
        return tuple(self.origin_m + self.axes @ (np.asarray(p, float) - np.array([self.x_m, 0.0, 0.0])))

    def vector(self, v) -> tuple:
        return tuple(v) if self.axes is None else tuple(self.axes @ np.asarray(v, float))

    @property
    def bushing_axes(self):
        """Bushing axes (rows): the track frame, or None (global axes) on tangent track."""
        return None if self.axes is None else tuple(map(tuple, self.axes.T))


def vehicle_half_span_m(parameters: VehicleParameters) -> float:
    """Distance from the vehicle centre to its outermost wheelsets along the track (m):
    ``bogie_semi_distance_m + semi_wheelbase_m``."""
    return parameters.bogie_semi_distance_m + parameters.semi_wheelbase_m


def tangent_stretches(track: TrackLayout) -> list[tuple[float, float]]:
    """The straight, uncanted stretches of a layout.

    Parameters
    ----------
    track : TrackLayout

    Returns
    -------
    list of (float, float)
        ``(start, end)`` chainages (m) of the runs of :class:`Tangent` segments (zero curvature
        and zero cant everywhere; a transition's ends are not included), adjacent ones merged.
    """
    out: list[tuple[float, float]] = []
    for seg, start in zip(track.segments, track.joins_m[:-1]):
        if not isinstance(seg, Tangent):
            continue
        end = float(start + seg.length_m)
        if out and abs(out[-1][1] - start) < 1e-9:
            out[-1] = (out[-1][0], end)
        else:
            out.append((float(start), end))
    return out


def check_start_on_tangent(track: TrackLayout, x_m: float, parameters: VehicleParameters) -> None:
    """Check that a vehicle centred at chainage ``x_m`` (m) starts with every wheelset on one
    straight, uncanted stretch of ``track`` (:func:`tangent_stretches`, ends included).

    Parameters
    ----------
    track : TrackLayout
    x_m : float
        Chainage of the vehicle centre (m).
    parameters : VehicleParameters
        The vehicle (its wheelset positions).

    Raises
    ------
    ParameterError
        Naming ``x_m``, its value, the wheelsets' chainages and the allowed ranges of ``x_m``.
    """
    half = vehicle_half_span_m(parameters)
    stretches = tangent_stretches(track)
    if any(a - 1e-9 <= x_m - half and x_m + half <= b + 1e-9 for a, b in stretches):
        return
    allowed = [f"{a + half:g} <= x_m <= {b - half:g} m" for a, b in stretches if b - a >= 2 * half]
    what = (" or ".join(allowed) if allowed else
            f"none: no tangent stretch of the layout is as long as the distance between the vehicle's outermost "
            f"wheelsets ({2 * half:g} m)")
    raise ParameterError(f"x_m={x_m:g}: the vehicle's wheelsets (chainages {x_m - half:g} to {x_m + half:g} m) must "
                         f"all start on a tangent (straight, uncanted) stretch of the track layout; allowed: {what}")


def _is_straight(track: TrackLayout) -> bool:
    return not any(isinstance(seg, Curve) for seg in track.segments)


def _site(track, x_m: float, drive: str, parameters: VehicleParameters) -> _Site:
    """Check the track and the start position; the map from vehicle to global coordinates."""
    if track is None:
        return _Site(x_m)
    if not isinstance(track, TrackLayout):
        raise ParameterError(f"track={track!r}: must be a TrackLayout or None (tangent track along global x)")
    check_start_on_tangent(track, x_m, parameters)
    if drive == "constraint" and not _is_straight(track):
        raise ParameterError("drive='constraint': the driving constraint holds the velocity along a fixed global "
                             "direction and cannot follow a curved track layout; use drive='torque' (traction servo)")
    frame = track.track_frame(x_m)
    return _Site(x_m, frame.R[0], frame.A[0])


def add_vehicle(scene: Scene, pair, *, speed_ms: float, parameters: VehicleParameters | None = None,
                creep: str = "linear", friction_coefficient: float = 0.3, drive: str = "constraint",
                lateral_offset_m: float = 0.0, x_m: float = 0.0, contact_form: str = "railframe",
                car_body_load_N: float = 0.0, track: TrackLayout | None = None) -> VehicleLayout:
    """Add the vehicle, centred at ``x_m`` on tangent track or on a track layout, moving at
    ``speed_ms`` (m/s).

    Parameters
    ----------
    scene : Scene
        Receives 13 rigid bodies, their suspensions, 8 wheel/rail contacts and the drive.
    pair : ProfilePair
        Wheel and rail profiles (:func:`symcat.wheelrail.profile_pair`).
    speed_ms : float
        Forward speed (m/s).
    parameters : VehicleParameters, optional
        Default: the Manchester benchmark vehicle with symcat's bolster and equalizer values.
    creep : {"none", "linear", "polach"}
        Creep force law of every contact.
    friction_coefficient : float
        For ``"polach"``.
    drive : {"constraint", "torque"}
        Leading wheelsets driven by a constraint on the forward position (along the start
        tangent: a layout with curves needs ``"torque"``), or by a traction servo (torque
        between frame and wheelset holding the spin ``V / r0``).
    lateral_offset_m : float
        Initial lateral displacement of the whole vehicle toward the left rail (m).
    x_m : float
        Initial position of the vehicle centre along the track (m): global ``x`` on tangent
        track, the chainage on a layout.
    contact_form : {"railframe", "global"}
        Form of the contact constraints (seed eq. 22 or 21).
    car_body_load_N : float
        Vertical load (N) that other parts of the scene put on the car body (e.g. a pantograph
        and its contact force); the suspension preloads include it, so the vehicle starts in
        equilibrium.
    track : TrackLayout, optional
        Curved track (:class:`symcat.wheelrail.track.TrackLayout`, built with
        ``rail_offset_m=rail_offset_for(pair.rail)``); ``None`` (default): tangent track along
        global ``x``. Every wheelset must start on a tangent (straight, uncanted) stretch; the
        suspension preloads assume level track (a gradient starts the vehicle slightly out of
        equilibrium).

    Raises
    ------
    ParameterError
        For a bad drive, creep law or speed, a lateral offset that does not fit the rails, a
        start off the layout's tangent stretches (names ``x_m`` and the allowed range), or
        ``drive="constraint"`` on a layout with curves.
    """
    p = parameters or VehicleParameters()
    if drive not in DRIVES:
        raise ParameterError(f"drive={drive!r}: must be one of {', '.join(DRIVES)}")
    if creep not in ("none", "linear", "polach"):
        raise ParameterError(f"creep={creep!r}: must be none, linear or polach")
    if not speed_ms > 0:
        raise ParameterError(f"speed_ms={speed_ms!r}: must be > 0 (m/s)")
    site = _site(track, x_m, drive, p)
    loads = p.static_loads_N(car_body_load_N)
    layout = VehicleLayout(parameters=p, pair=pair, track=track)
    v = site.vector((speed_ms, 0.0, 0.0))
    y0 = lateral_offset_m
    scene.add(RigidBody("car_body", p.car_body_mass_kg, p.car_body_inertia_kg_m2,
                        site.point((x_m, y0, p.car_body_height_m)), rotation=site.axes, velocity=v))
    creep_model = None
    if creep != "none":
        creep_model = CreepModel(creep, nominal_normal_force_N=loads["wheel"], friction_coefficient=friction_coefficient)
    dims = WheelsetDimensions(p.tape_circle_distance_m, p.nominal_rolling_radius_m)
    for bogie, sign in zip(BOGIES, (1.0, -1.0)):
        xb = x_m + sign * p.bogie_semi_distance_m
        _add_bogie(scene, layout, site, p, loads, bogie, xb, y0, v, dims, creep_model, drive, speed_ms,
                   contact_form)
    return layout


def _add_bogie(scene, layout, site, p, loads, bogie, xb, y0, v, dims, creep_model, drive, speed, form):
    frame, bolster = f"{bogie}_frame", f"{bogie}_bolster"
    pair = layout.pair
    layout.frames.append(frame)
    layout.bolsters.append(bolster)
    scene.add(RigidBody(frame, p.frame_mass_kg, p.frame_inertia_kg_m2, site.point((xb, y0, p.frame_height_m)),
                        rotation=site.axes, velocity=v))
    scene.add(RigidBody(bolster, p.bolster_mass_kg, p.bolster_inertia_kg_m2, site.point((xb, y0, p.bolster_height_m)),
                        rotation=site.axes, velocity=v))
    a = p.suspension_semi_spacing_m
    up = np.array([0.0, 0.0, 1.0])
    axes = site.bushing_axes
    # Bolster on the frame: secondary suspension per side, anti-roll bar at the centre.
    for side, ys in zip(SIDES, (a, -a)):
        scene.add(Bushing(f"{bogie}_secondary_{side}", frame, bolster,
                          at=site.point((xb, y0 + ys, p.secondary_height_m)),
                          stiffness=p.secondary_stiffness_N_m, damping=p.secondary_damping_N_s_m,
                          preload=tuple(loads["secondary"] * up), clearance=(0.0, p.bump_stop_clearance_m, 0.0),
                          stop_stiffness=(0.0, p.bump_stop_stiffness_N_m, 0.0), axes=axes))
    scene.add(Bushing(f"{bogie}_anti_roll_bar", frame, bolster, at=site.point((xb, y0, p.secondary_height_m)),
                      rotational_stiffness=(p.anti_roll_stiffness_N_m_rad, 0.0, 0.0), axes=axes))
    # Car body on the bolster: centre plate (yaw only) with the secondary yaw stiffness.
    scene.add(Revolute(f"{bogie}_centre_plate", bolster, layout.car_body,
                       at=site.point((xb, y0, p.centre_plate_height_m)), axis=site.vector((0.0, 0.0, 1.0))))
    scene.add(RotationalSpring(f"{bogie}_yaw_stiffness", bolster, layout.car_body, axis=site.vector((0.0, 0.0, 1.0)),
                               stiffness=p.secondary_yaw_stiffness_N_m_rad))
    placed = {}
    for ws, sign in zip(WHEELSETS, (1.0, -1.0)):
        name = f"{bogie}_{ws}"
        xw = xb + sign * p.semi_wheelbase_m
        try:
            placed[ws] = wheelset_on_track(pair.wheel, pair.rail, y0, x_m=xw, wheelset=dims, track=layout.track)
        except ParameterError as err:
            raise ParameterError(f"lateral_offset_m={y0:g}: wheelset {name}: {err}") from None
        pl = placed[ws]
        r_mean = 0.5 * (pl.contacts["left"].rolling_radius_m + pl.contacts["right"].rolling_radius_m)
        spin = pl.rotation[:, 1] * speed / r_mean
        scene.add(RigidBody(name, p.wheelset_mass_kg, p.wheelset_inertia_kg_m2, tuple(pl.position_m),
                            rotation=pl.rotation, velocity=v, angular_velocity=tuple(spin)))
        layout.wheelsets.append(name)
        layout.placements[name] = pl
        layout.contacts[name] = {}
        for side in SIDES:
            joint = f"{name}_{side}"
            scene.add(WheelRailJoint(joint, name, side, pair.wheel, pair.rail, wheelset=dims, creep=creep_model,
                                     form=form, track=layout.track))
            layout.contacts[name][side] = joint
        if ws == "ws1":
            if drive == "constraint":
                scene.add(Driving(f"{name}_drive", name, direction=site.vector((1.0, 0.0, 0.0)), velocity=speed))
            else:
                scene.add(RotationalSpring(f"{name}_traction", frame, name, axis=site.vector((0.0, 1.0, 0.0)),
                                           damping=SERVO_DAMPING_N_M_S, rate=speed / r_mean))
    # Equalizer bars on the axleboxes; the frame on the equalizer springs.
    for side, ys in zip(SIDES, (a, -a)):
        eq = f"{bogie}_equalizer_{side}"
        layout.equalizers.append(eq)
        scene.add(RigidBody(eq, p.equalizer_mass_kg, p.equalizer_inertia_kg_m2,
                            site.point((xb, y0 + ys, p.equalizer_height_m)), rotation=site.axes, velocity=v))
        kx, ky, _ = p.primary_stiffness_N_m
        cx, cy, cz = p.primary_damping_N_s_m
        for ws in WHEELSETS:
            pl = placed[ws]
            box = pl.position_m + pl.rotation[:, 1] * ys
            scene.add(Bushing(f"{bogie}_{ws}_journal_{side}", eq, f"{bogie}_{ws}", at=tuple(box),
                              stiffness=(kx, ky, p.journal_pad_stiffness_N_m), damping=(cx, cy, p.journal_pad_damping_N_s_m),
                              preload=(0.0, 0.0, -loads["journal"]), axes=axes))
        for k, dx in enumerate((p.equalizer_spring_offset_m, -p.equalizer_spring_offset_m)):
            scene.add(Bushing(f"{bogie}_equalizer_spring_{side}_{k + 1}", eq, frame,
                              at=site.point((xb + dx, y0 + ys, p.equalizer_spring_height_m)),
                              stiffness=(0.0, 0.0, p.primary_stiffness_N_m[2]), damping=(0.0, 0.0, cz),
                              preload=(0.0, 0.0, loads["equalizer_spring"]), axes=axes))
        g = p.equalizer_guide_stiffness_N_m
        scene.add(Bushing(f"{bogie}_equalizer_guide_{side}", frame, eq,
                          at=site.point((xb, y0 + ys, p.equalizer_height_m)),
                          stiffness=(g, g, 0.0), damping=(p.equalizer_guide_damping_N_s_m,) * 2 + (0.0,),
                          rotational_stiffness=(p.equalizer_roll_stiffness_N_m_rad, 0.0,
                                                p.equalizer_guide_yaw_stiffness_N_m_rad),
                          rotational_damping=(p.equalizer_roll_damping_N_m_s_rad, 0.0,
                                              p.equalizer_guide_yaw_damping_N_m_s_rad), axes=axes))
