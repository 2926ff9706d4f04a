"""Outputs a user can look at: centre-line samples, ParaView files (meshio) and plots."""
from .paraview import write_multibody_series, write_pvd
from .shapes import centerlines, plot_centerlines, write_centerlines_vtu, write_modes_vtu

__all__ = ["centerlines", "plot_centerlines", "write_centerlines_vtu", "write_modes_vtu", "write_multibody_series",
           "write_pvd"]
