"""The seed paper's railroad vehicle: car body, two bogies (frame, bolster, two equalizer bars,
two wheelsets), suspensions and wheel/rail contacts."""
from .builder import BOGIES, DRIVES, SIDES, WHEELSETS, VehicleLayout, add_vehicle
from .parameters import VehicleParameters
from .wheel_forces import wheel_forces

__all__ = ["BOGIES", "DRIVES", "SIDES", "WHEELSETS", "VehicleLayout", "VehicleParameters", "add_vehicle", "wheel_forces"]
