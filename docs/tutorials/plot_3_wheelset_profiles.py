"""
A wheelset on your own profiles
===============================

Wheel and rail profiles are :class:`~symcat.wheelrail.Profile` objects: C2 smoothing splines
through point data (:meth:`~symcat.wheelrail.Profile.from_points`, the data checked for order,
gaps and self-intersection), or the shipped S1002, UIC60 1:40 and EN 15302 profiles
(:func:`~symcat.wheelrail.profile_pair`). The frame (:mod:`symcat.wheelrail.profiles`): ``y``
lateral from the tape circle (wheel) or the rail's origin, ``z`` up; a wheel's ``z`` is its
radius deviation, so a coned tread of conicity ``c`` is ``z = -c y``.

This tutorial makes a wheel and a rail from points, computes their rigid contact geometry and
EN 15302 equivalent conicity, then runs a wheelset on them with the constraint wheel/rail
contact and Kalker's linear creep forces, and compares its lateral wavelength with Klingel's.
"""

import math
import os

import matplotlib.pyplot as plt
import numpy as np

from symcat.wheelrail import Profile, WheelsetDimensions, contact_geometry, equivalent_conicity

FULL = os.environ.get("SYMCAT_DOCS_FULL") == "1"

# %%
# Profiles from points
# --------------------
# The wheel: a 1:40 tread whose slope steepens toward the flange side (``y < -20 mm``), like a
# slightly hollow worn tread. The rail: a head of 300 mm radius rounded into its gauge face (on
# the ``-y`` side) by a 13 mm corner, down to 25 mm below the top, as the gauge is measured 14 mm
# below it. Point data in metres, ordered along the profile; a real profile would come from a
# measurement file (two columns, read with NumPy).

y_wheel = np.linspace(-0.050, 0.060, 111)
z_wheel = -0.025 * y_wheel + 2.0 * np.clip(-0.020 - y_wheel, 0.0, None) ** 2
wheel = Profile.from_points(y_wheel, z_wheel, "wheel", "my wheel")

R_TOP, R_CORNER = 0.300, 0.013
theta = math.asin(-0.020 / R_TOP)                              # where the corner takes over
centre = np.array([0.0, -R_TOP]) + (R_TOP - R_CORNER) * np.array([math.sin(theta), math.cos(theta)])
phi = np.linspace(math.radians(-80.0), theta, 40)[:-1]         # the corner, down to a face at 10 deg
corner = centre + R_CORNER * np.column_stack([np.sin(phi), np.cos(phi)])
face_dir = np.array([math.sin(phi[0]), math.cos(phi[0])])
face_tangent = np.array([-face_dir[1], face_dir[0]])           # downward along the gauge face
face = corner[0] + np.outer(np.linspace(0.020, 0.0, 20, endpoint=False), face_tangent)
top = np.column_stack([R_TOP * np.sin(a := np.linspace(theta, math.asin(0.035 / R_TOP), 60)),
                       R_TOP * np.cos(a) - R_TOP])
points = np.vstack([face, corner, top])
rail = Profile.from_points(points[:, 0], points[:, 1], "rail", "my rail")

fig, ax = plt.subplots(figsize=(7, 3))
for prof, label in ((wheel, "wheel (radius deviation)"), (rail, "rail head")):
    _, pts = prof.sample(1e-4)
    ax.plot(pts[:, 0] * 1e3, pts[:, 1] * 1e3, label=label)
ax.set(xlabel="y [mm]", ylabel="z [mm]", title="own profiles")
ax.legend()
fig.tight_layout()

# %%
# Contact geometry and equivalent conicity
# ----------------------------------------
# :func:`~symcat.wheelrail.contact_geometry` finds the contact points of both wheels against the
# wheelset's lateral shift (here with its roll), and
# :func:`~symcat.wheelrail.equivalent_conicity` integrates the rolling radius difference as
# EN 15302 does, at the amplitudes asked for.

dims = WheelsetDimensions(tape_circle_distance_m=1.5, nominal_radius_m=0.46)
shifts = np.linspace(-0.006, 0.006, 61)
geo = contact_geometry(wheel, rail, shifts, roll=True)
dr = geo.rolling_radius_difference_m
amplitudes = np.array([0.002, 0.003, 0.004, 0.005])
gamma = equivalent_conicity(shifts, dr, amplitudes)
for a, g in zip(amplitudes, gamma):
    print(f"equivalent conicity at {a * 1e3:.0f} mm: {g:.4f}")

fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(shifts * 1e3, dr * 1e3)
ax.set(xlabel="lateral shift [mm]", ylabel="r_left - r_right [mm]", title="rolling radius difference")
fig.tight_layout()

# %%
# A wheelset running on them
# --------------------------
# The scene: one rigid wheelset (the Manchester benchmark's mass and inertia, as in the
# ``wheelset`` model), placed on the rails 3 mm off centre by
# :func:`~symcat.vehicle.wheelset_on_track`, rolling without slip, loaded by its share of the car
# body, driven forward at constant speed; each wheel touches its rail through a
# :class:`~symcat.scene.WheelRailJoint` (four surface parameters, five constraints, the normal
# force a Lagrange multiplier) with Kalker's linear creep forces.

from symcat.assembly.multibody import MultibodyModel
from symcat.scene import CreepModel, Driving, PointLoad, RigidBody, Scene, WheelRailJoint
from symcat.simulation import simulate
from symcat.vehicle import wheelset_on_track

G, MASS, AXLE_LOAD = 9.81, 1813.0, (32000.0 + 2 * 2615.0) / 4 * 9.81
speed = 20.0
placed = wheelset_on_track(wheel, rail, 0.003, wheelset=dims)
r_mean = 0.5 * (placed.contacts["left"].rolling_radius_m + placed.contacts["right"].rolling_radius_m)
scene = Scene(gravity=(0.0, 0.0, -G))
scene.add(RigidBody("wheelset", MASS, (1120.0, 112.0, 1120.0), position=placed.position_m,
                    rotation=placed.rotation, velocity=(speed, 0.0, 0.0),
                    angular_velocity=tuple(placed.rotation[:, 1] * speed / r_mean)))
scene.add(PointLoad("axle_load", "wheelset", force=(0.0, 0.0, -AXLE_LOAD)))
creep = CreepModel("linear", nominal_normal_force_N=0.5 * (MASS * G + AXLE_LOAD))
for side in ("left", "right"):
    scene.add(WheelRailJoint(f"{side}_wheel", "wheelset", side, wheel, rail, wheelset=dims, creep=creep))
scene.add(Driving("forward_speed", "wheelset", direction=(1.0, 0.0, 0.0), velocity=speed))

t_end = 4.0 if FULL else 2.0
result = simulate(MultibodyModel(scene), t_end, "augmented", "1", rtol=1e-5, atol=1e-7, n_out=200, progress=False)
x, y = result.coordinate("wheelset.x"), result.coordinate("wheelset.y")
print(f"{result.stats.get('nsteps')} IDAS steps, {result.stats.get('contact_jumps', 0)} contact jumps")

# Klingel: lambda = 2 pi sqrt(r0 b / gamma), gamma from the rolling radius difference at the offset
b = 0.5 * (placed.contacts["left"].point_m[1] - placed.contacts["right"].point_m[1])
gamma0 = (placed.contacts["left"].rolling_radius_m - placed.contacts["right"].rolling_radius_m) / (2 * 0.003)
klingel = 2 * math.pi * math.sqrt(r_mean * b / gamma0)
print(f"Klingel's wavelength at the 3 mm offset: {klingel:.1f} m")

fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(x, y * 1e3, label="wheelset")
ax.plot(x, 3.0 * np.cos(2 * math.pi * (x - x[0]) / klingel), "k--", lw=0.8, label="Klingel, 3 mm")
ax.set(xlabel="distance [m]", ylabel="lateral displacement [mm]", title=f"wheelset at {speed:g} m/s on own profiles")
ax.legend()
fig.tight_layout()

# %%
# The shipped models do the same on the shipped profiles: ``symcat run wheelset --set
# profile=s1002_uic60`` and ``symcat run contact_geometry --set profile=en15302_a``.
