"""Lumped-mass pantographs: a chain of masses on springs and dampers above the roof.

Stage 1 sits on the roof, the last stage is the pan-head. Coordinates are vertical
displacements (m) of the stages from their unloaded positions; gravity is balanced inside the
real pantograph and left out, so the static uplift is the static contact force.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True)
class LumpedPantograph:
    """A lumped-mass pantograph.

    Parameters
    ----------
    masses : tuple of float
        Stage masses from the roof up (kg); the last one is the pan-head.
    stiffness : tuple of float
        Spring of each stage to the stage below (the first to the roof) (N/m).
    damping : tuple of float
        Damper of each stage to the stage below (N s/m).
    uplift : float
        Static uplift force (N), applied to stage ``uplift_stage``.
    uplift_stage : int
        Stage (0 = lowest) carrying the uplift force.
    aero_coefficient : float
        Aerodynamic uplift on the pan-head, ``aero_coefficient * v^2`` (N s^2/m^2, v in m/s).
    name : str
    sources : dict
    """

    masses: tuple[float, ...]
    stiffness: tuple[float, ...]
    damping: tuple[float, ...]
    uplift: float
    uplift_stage: int = 0
    aero_coefficient: float = 0.0
    name: str = "pantograph"
    sources: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        n = len(self.masses)
        if n < 1:
            raise ParameterError("masses: a pantograph needs at least one stage")
        for label, values in (("stiffness", self.stiffness), ("damping", self.damping)):
            if len(values) != n:
                raise ParameterError(f"{label}: {len(values)} values for {n} stages")
        for m in self.masses:
            if not m > 0:
                raise ParameterError(f"masses: {m:g} kg must be > 0")
        for k in self.stiffness:
            if not k >= 0:
                raise ParameterError(f"stiffness: {k:g} N/m must be >= 0")
        for c in self.damping:
            if not c >= 0:
                raise ParameterError(f"damping: {c:g} N s/m must be >= 0")
        if not self.uplift > 0:
            raise ParameterError(f"uplift={self.uplift:g} N: must be > 0 (the pantograph must press on the wire)")
        if not 0 <= self.uplift_stage < n:
            raise ParameterError(f"uplift_stage={self.uplift_stage}: must be 0..{n - 1}")

    @property
    def n(self) -> int:
        return len(self.masses)

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Mass (kg), damping (N s/m) and stiffness (N/m) matrices of the stage displacements."""
        n = self.n
        m = np.diag(self.masses)
        c, k = np.zeros((n, n)), np.zeros((n, n))
        for i in range(n):
            for mat, val in ((c, self.damping[i]), (k, self.stiffness[i])):
                mat[i, i] += val
                if i > 0:
                    mat[i - 1, i - 1] += val
                    mat[i, i - 1] -= val
                    mat[i - 1, i] -= val
        return m, c, k

    def static_force(self, speed: float) -> np.ndarray:
        """Constant forces on the stages (N): uplift plus aerodynamic uplift at ``speed`` (m/s)."""
        f = np.zeros(self.n)
        f[self.uplift_stage] += self.uplift
        f[-1] += self.aero_coefficient * speed**2
        return f


def en50367_mean_force(speed_kmh: float) -> float:
    """EN 50367 AC target mean contact force 0.00097 v^2 + 70 (N, v in km/h)."""
    return 0.00097 * speed_kmh**2 + 70.0


def benchmark2015_pantograph(speed_kmh: float) -> LumpedPantograph:
    """The 2015 benchmark's three-mass pantograph with the EN 50367 mean force as uplift."""
    return LumpedPantograph(
        masses=(6.0, 9.0, 7.5), stiffness=(160.0, 15500.0, 7000.0), damping=(0.0, 0.0, 0.0),
        uplift=en50367_mean_force(speed_kmh), uplift_stage=0, name="benchmark2015",
        sources={"stages": "Bruni et al., Vehicle System Dynamics 53(3), 2015 (public set; dampers (?) taken as 0)",
                 "uplift": "EN 50367 AC target 0.00097 v^2 + 70 N on the lower frame (?)"})


def en50318_pantograph(static_force: float = 120.0) -> LumpedPantograph:
    """The EN 50318:2002 two-mass reference pantograph (static force on the frame, N)."""
    return LumpedPantograph(
        masses=(15.0, 7.2), stiffness=(50.0, 4200.0), damping=(90.0, 10.0), uplift=static_force, uplift_stage=0,
        name="en50318",
        sources={"stages": "EN 50318:2002 reference pantograph (public transcriptions)",
                 "uplift": f"choice: {static_force:g} N on the frame (public sources disagree)"})
