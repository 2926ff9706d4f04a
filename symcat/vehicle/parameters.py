"""Parameters of the seed paper's railroad vehicle (Figures 8 and 9): a car body on two bogies,
each with a frame, a bolster, two equalizer bars and two wheelsets.

Source of the values: the Manchester benchmark vehicle 1 (Iwnicki, Vehicle System Dynamics
30(3-4), 1998; see ``symcat/reference_data/vehicle-manchester.md``) for the car body, bogie frames,
wheelsets, geometry and suspension. The benchmark has no bolster and no equalizer bars; their
masses, the equalizer springs, journal pads and guides below are *plausible values chosen for
symcat* (marked "assumed"), sized so that the equalizer springs in series with the journal pads
give the benchmark's primary vertical stiffness per axlebox within 6 %.

The equalizer guide holds the bar's lateral position and yaw on the frame, as pedestal guides at
its two axleboxes would: ``2 k_guide a^2`` about the vertical (``a`` the semi-wheelbase, 32.8 MN
m/rad). With the guide at the bar's centre holding only translations, a bar yawed freely about it,
the frame could not steer its wheelsets, and each wheelset ran as a free one: Klingel's kinematic
oscillation (16.4 m on the conical 1:20 pair), growing at 17 m/s until the flanges struck (S1002 at
3.3 s). Held in yaw, the bogie damps the start offset out within 2 s.

The journal pads and the equalizer guides are rubber elements, damped by their hysteresis: a loss
factor ``eta = 0.2`` at the mode each one sets, as the viscous ``c = eta k / omega``. The pads
carry the bar's bounce near 94 Hz (``c = 0.2 * 20e6 / (2 pi 94)``, 6.8 kN s/m, taken as 7), the
guides its lateral mode near 61 Hz (5.2 kN s/m, taken as 5) and its yaw near 120 Hz (``0.2 *
32.8e6 / (2 pi 120)``, 8.7 kN m s/rad, taken as 9). Undamped, these modes of a 120 kg
bar ring at a damping ratio of 0.016 to 0.06 after every contact-point jump, and IDAS resolves
them: on the S1002 vehicle at rtol 1e-4 this damping took 987 steps per simulated second to 812
(measured before the bars were held in yaw).
"""
from __future__ import annotations

from dataclasses import dataclass, fields

from ..errors import ParameterError

G = 9.81


@dataclass(frozen=True)
class VehicleParameters:
    """Masses (kg), inertias about the centres of mass (kg m^2, body axes x forward, y left, z
    up), geometry (m, heights above the rail top), stiffness (N/m, N m/rad) and damping
    (N s/m, N m s/rad) of the vehicle. Per-element values unless stated."""

    # Manchester benchmark vehicle 1
    car_body_mass_kg: float = 32000.0
    car_body_inertia_kg_m2: tuple = (56800.0, 1970000.0, 1970000.0)
    frame_mass_kg: float = 2615.0
    frame_inertia_kg_m2: tuple = (1722.0, 1476.0, 3067.0)
    wheelset_mass_kg: float = 1813.0
    wheelset_inertia_kg_m2: tuple = (1120.0, 112.0, 1120.0)
    nominal_rolling_radius_m: float = 0.46
    tape_circle_distance_m: float = 1.5
    semi_wheelbase_m: float = 1.28
    bogie_semi_distance_m: float = 9.5
    suspension_semi_spacing_m: float = 1.0
    car_body_height_m: float = 1.8
    secondary_height_m: float = 0.8275
    frame_height_m: float = 0.6
    primary_stiffness_N_m: tuple = (31391e3, 3884e3, 1220e3)   # per axlebox x, y, z
    primary_damping_N_s_m: tuple = (15e3, 2e3, 4e3)
    secondary_stiffness_N_m: tuple = (160e3, 160e3, 430e3)     # per bogie side
    secondary_damping_N_s_m: tuple = (0.0, 32e3, 20e3)
    secondary_yaw_stiffness_N_m_rad: float = 10.5e3
    anti_roll_stiffness_N_m_rad: float = 940e3
    bump_stop_clearance_m: float = 0.025
    bump_stop_stiffness_N_m: float = 500e3   # linear fit of the benchmark's progressive stop to 55 mm
    # assumed (not in the benchmark)
    bolster_mass_kg: float = 600.0
    bolster_inertia_kg_m2: tuple = (340.0, 40.0, 340.0)          # a 2.6 m beam across the bogie
    bolster_height_m: float = 0.9
    centre_plate_height_m: float = 0.95
    equalizer_mass_kg: float = 120.0
    equalizer_inertia_kg_m2: tuple = (2.0, 80.0, 80.0)           # a 2.8 m bar along the bogie
    equalizer_height_m: float = 0.42
    equalizer_spring_offset_m: float = 0.5                       # springs at +-0.5 m from the bogie centre
    equalizer_spring_height_m: float = 0.55
    journal_pad_stiffness_N_m: float = 20e6                       # vertical, in series with the springs
    journal_pad_damping_N_s_m: float = 7e3                        # vertical; see the note below
    equalizer_guide_stiffness_N_m: float = 10e6                   # frame to equalizer, x and y
    equalizer_guide_damping_N_s_m: float = 5e3                    # x and y; see the note below
    equalizer_guide_yaw_stiffness_N_m_rad: float = 32.8e6        # as two guides at the axleboxes; see the note
    equalizer_guide_yaw_damping_N_m_s_rad: float = 9e3           # see the note
    equalizer_roll_stiffness_N_m_rad: float = 1e5
    equalizer_roll_damping_N_m_s_rad: float = 1e3

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            values = value if isinstance(value, tuple) else (value,)
            if any(not isinstance(v, (int, float)) or v != v or v < 0 for v in values):
                raise ParameterError(f"vehicle parameter {f.name}={value!r}: must be finite and >= 0")
            if f.name.endswith(("mass_kg", "inertia_kg_m2", "radius_m")) and any(v <= 0 for v in values):
                raise ParameterError(f"vehicle parameter {f.name}={value!r}: must be > 0")

    @property
    def total_mass_kg(self) -> float:
        """Mass of the whole vehicle (kg)."""
        per_bogie = (self.frame_mass_kg + self.bolster_mass_kg + 2 * self.equalizer_mass_kg
                     + 2 * self.wheelset_mass_kg)
        return self.car_body_mass_kg + 2 * per_bogie

    def static_loads_N(self, car_body_load_N: float = 0.0) -> dict:
        """Static vertical load (N) carried by one element of each suspension level, for the
        symmetric vehicle at rest: ``secondary`` (per bogie side), ``equalizer_spring`` (two
        per equalizer), ``journal`` (per axlebox) and ``wheel`` (per wheel).
        ``car_body_load_N``: a further vertical load on the car body, centred (N; e.g. the
        pantograph)."""
        above_bolster = (self.car_body_mass_kg + car_body_load_N / G) / 2
        secondary = (above_bolster + self.bolster_mass_kg) * G / 2
        equalizer_spring = (above_bolster + self.bolster_mass_kg + self.frame_mass_kg) * G / 4
        journal = (above_bolster + self.bolster_mass_kg + self.frame_mass_kg + 2 * self.equalizer_mass_kg) * G / 4
        wheel = journal + self.wheelset_mass_kg * G / 2
        return {"secondary": secondary, "equalizer_spring": equalizer_spring, "journal": journal, "wheel": wheel}
