"""The seed paper's railroad vehicle: car body, two bogies (frame, bolster, two equalizer bars,
two wheelsets), suspensions and wheel/rail contacts, on tangent track or on a track layout; and a
wheelset placed on its rails (:func:`wheelset_on_track`), the initial state of such scenes."""
from .builder import BOGIES, DRIVES, SIDES, WHEELSETS, VehicleLayout, add_vehicle, check_start_on_tangent
from .curving import curve_track, steady_curving_forces_N
from .parameters import VehicleParameters
from .placement import WheelsetPlacement, wheelset_on_track
from .wheel_forces import lateral_displacement_m, lateral_force_sum_N, momentum_rate_N, wheel_forces, wheel_summary

__all__ = ["BOGIES", "DRIVES", "SIDES", "WHEELSETS", "VehicleLayout", "VehicleParameters", "WheelsetPlacement",
           "add_vehicle", "check_start_on_tangent", "curve_track", "lateral_displacement_m", "lateral_force_sum_N",
           "momentum_rate_N", "steady_curving_forces_N", "wheel_forces", "wheel_summary", "wheelset_on_track"]
