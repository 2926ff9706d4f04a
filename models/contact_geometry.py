"""Rigid contact geometry of a wheelset on straight track against lateral shift.

The wheelset (tape circles 1.5 m apart, i.e. a 1.360 m flange-back distance for S1002 and
EN 15302 wheel A; nominal rolling radius 0.46 m, the Manchester vehicle and EN 15302's 920 mm
wheels) is shifted laterally in 0.1 mm steps (EN 15302's largest step) and lowered onto the
rails; ``symcat.wheelrail.geometry`` finds the contact points. Profiles: ``conical`` (a coned
tread of ``conicity`` on UIC60 inclined 1:40), ``s1002_uic60`` (S1002 on UIC60 1:40) or
``en15302_a`` (EN 15302 reference wheel A on rail A; the standard's own track has
``gauge_m=1.43516``). The rails keep the inclination built into their profiles.

``rolling_radius_difference_m`` is ``r_left - r_right`` for a shift toward the left rail;
contact angles are measured from the track plane, positive when the normal on the wheel points
toward the track centre. ``equivalent_conicity`` is EN 15302's integration method (Annex B) at
2, 3 and 4 mm amplitude, from the rolling radius difference over at least +-7 mm. ``roll`` off
lowers each wheel onto its rail on its own (as EN 15302's reference results do); on, it also
solves for the wheelset's roll angle so that both wheels touch.
"""
from __future__ import annotations

import numpy as np

from symcat.model import Model, ModelOutput, Parameter
from symcat.wheelrail import (
    PAIR_NAMES,
    TrackCrossSection,
    WheelsetDimensions,
    contact_geometry,
    equivalent_conicity,
    profile_pair,
)

AMPLITUDES_M = (0.002, 0.003, 0.004)
STEP_M = 1e-4
CONICITY_RANGE_M = 0.007  # Delta r needed for the turning points of a 4 mm amplitude, with margin

PARAMETERS = [
    Parameter("profile", "s1002_uic60", "", "wheel/rail profiles", choices=PAIR_NAMES),
    Parameter("conicity", 0.05, "-", "tread conicity of the conical profile (0.05 is 1:20)", minimum=0.0,
              maximum=0.5, exclusive_minimum=True),
    Parameter("gauge_m", 1.435, "m", "track gauge, measured 14 mm below the top of the rails", minimum=1.0,
              maximum=2.0),
    Parameter("max_shift_m", 0.01, "m", "largest lateral shift of the wheelset (both directions)", minimum=0.0,
              maximum=0.03, exclusive_minimum=True),
    Parameter("roll", False, "", "solve for the roll angle so that both wheels touch"),
]


def run(p: dict) -> ModelOutput:
    pair = profile_pair(p["profile"], p["conicity"])
    track = TrackCrossSection(gauge_m=p["gauge_m"])
    wheelset = WheelsetDimensions(tape_circle_distance_m=1.5, nominal_radius_m=0.46)
    reach = max(p["max_shift_m"], CONICITY_RANGE_M)
    n = int(round(reach / STEP_M))
    shifts = np.arange(-n, n + 1) * STEP_M
    geo = contact_geometry(pair.wheel, pair.rail, shifts, track=track, wheelset=wheelset, roll=p["roll"])
    dr = geo.rolling_radius_difference_m
    conicity = equivalent_conicity(shifts, dr, AMPLITUDES_M, method="integration")
    shown = np.abs(shifts) <= p["max_shift_m"] + 1e-12
    two = geo.two_point["left"] | geo.two_point["right"]
    summary = {
        "lateral_shift_m": shifts[shown].tolist(),
        "rolling_radius_difference_m": dr[shown].tolist(),
        "contact_angle_left_rad": geo.contact_angle_rad["left"][shown].tolist(),
        "contact_angle_right_rad": geo.contact_angle_rad["right"][shown].tolist(),
        "equivalent_conicity": conicity.tolist(),
        "equivalent_conicity_amplitude_m": list(AMPLITUDES_M),
        "equivalent_conicity_method": "EN 15302 Annex B: integration of the nonlinear kinematic motion (Klingel)",
        "two_point_contact_shift_m": shifts[shown & two].tolist(),
    }
    if p["roll"]:
        summary["roll_angle_rad"] = geo.roll_angle_rad[shown].tolist()
    stats = {"shifts": int(len(shifts)), "shift_step_m": STEP_M}
    arrays = {"geometry": geo, "lateral_shift_m": shifts, "rolling_radius_difference_m": dr}

    def write(out):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        y = shifts[shown] * 1e3
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
        ax1.plot(y, dr[shown] * 1e3, "k-", lw=1.2, label="rolling radius difference")
        ax1.plot(y[two[shown]], dr[shown][two[shown]] * 1e3, "r.", ms=4, label="two-point contact")
        ax1.set_ylabel("r_left - r_right [mm]")
        text = ", ".join(f"{a * 1e3:g} mm: {c:.3f}" for a, c in zip(AMPLITUDES_M, conicity))
        ax1.set_title(f"{p['profile']}, gauge {p['gauge_m'] * 1e3:g} mm, roll {'on' if p['roll'] else 'off'}\n"
                      f"equivalent conicity (EN 15302) {text}", fontsize=9)
        ax1.grid(alpha=0.3)
        ax1.legend(fontsize=8)
        ax2.plot(y, geo.contact_angle_rad["left"][shown], "b-", lw=1.2, label="left wheel")
        ax2.plot(y, geo.contact_angle_rad["right"][shown], "g--", lw=1.2, label="right wheel")
        ax2.set_xlabel("lateral shift toward the left rail [mm]")
        ax2.set_ylabel("contact angle [rad]")
        ax2.grid(alpha=0.3)
        ax2.legend(fontsize=8)
        fig.tight_layout()
        path = out / "contact_geometry.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return [path]

    return ModelOutput(summary, stats, arrays, write)


MODEL = Model("contact_geometry", "rigid wheelset contact geometry against lateral shift (EN 15302 conicity)",
              PARAMETERS, run)
