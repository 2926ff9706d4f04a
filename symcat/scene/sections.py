"""Materials and cross-sections, and the kernel parameter vectors built from them."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..catalog import ElementType
from ..errors import ParameterError


def require_positive(name: str, value: float) -> float:
    """Return ``value`` as float, or raise naming the parameter if it is not > 0."""
    value = float(value)
    if not value > 0 or not math.isfinite(value):
        raise ParameterError(f"{name}={value:g}: must be a finite number > 0")
    return value


@dataclass(frozen=True)
class Material:
    """Linear elastic material.

    Parameters
    ----------
    E : float
        Young's modulus (Pa).
    rho : float
        Density (kg/m^3).
    nu : float
        Poisson's ratio (-), in (-1, 0.5); enters only through the shear modulus.
    """

    E: float
    rho: float
    nu: float = 0.3

    def __post_init__(self):
        require_positive("E", self.E)
        require_positive("rho", self.rho)
        if not -1.0 < self.nu < 0.5:
            raise ParameterError(f"nu={self.nu:g}: must be in (-1, 0.5)")

    @property
    def G(self) -> float:
        """Shear modulus (Pa)."""
        return self.E / (2 * (1 + self.nu))


@dataclass(frozen=True)
class Section:
    """Cross-section properties (doubly symmetric).

    Parameters
    ----------
    A : float
        Area (m^2).
    Iy, Iz : float
        Second moments ``int z^2 dA`` and ``int y^2 dA`` (m^4).
    J : float
        Torsion constant (m^4).
    shear_factor : float
        Shear correction factor (-).
    """

    A: float
    Iy: float
    Iz: float
    J: float
    shear_factor: float = 5.0 / 6.0

    def __post_init__(self):
        for name in ("A", "Iy", "Iz", "J", "shear_factor"):
            require_positive(name, getattr(self, name))

    @classmethod
    def rectangle(cls, width: float, height: float) -> "Section":
        """Solid rectangle, ``width`` along local y and ``height`` along local z (m)."""
        b = require_positive("width", width)
        h = require_positive("height", height)
        short, long_ = min(b, h), max(b, h)
        # Torsion constant of a solid rectangle (Roark, series truncated after the tanh term).
        beta = 1 / 3 - 0.21 * short / long_ * (1 - short**4 / (12 * long_**4))
        return cls(A=b * h, Iy=b * h**3 / 12, Iz=h * b**3 / 12, J=beta * long_ * short**3, shear_factor=5 / 6)

    @classmethod
    def circle(cls, diameter: float) -> "Section":
        """Solid circle of the given diameter (m)."""
        d = require_positive("diameter", diameter)
        i = math.pi * d**4 / 64
        return cls(A=math.pi * d**2 / 4, Iy=i, Iz=i, J=2 * i, shear_factor=6 / 7)

    @classmethod
    def from_stiffness(cls, EA: float, EI: float, E: float) -> "Section":
        """Section with the given axial and bending stiffness (N, N m^2) for modulus ``E`` (Pa)."""
        E = require_positive("E", E)
        i = require_positive("EI", EI) / E
        return cls(A=require_positive("EA", EA) / E, Iy=i, Iz=i, J=2 * i)


def element_parameters(
    element: ElementType,
    length: np.ndarray,
    material: Material,
    section: Section,
    prestrain: float = 0.0,
    damping_axial: float = 0.0,
    damping_bending: float = 0.0,
) -> np.ndarray:
    """Kernel parameter matrix (n_elements x n_params) in the catalog's order.

    Cables have isotropic bending and use ``section.Iz``.
    """
    length = np.atleast_1d(np.asarray(length, dtype=float))
    if np.any(length <= 0):
        raise ParameterError(f"element length={length.min():g} m: must be > 0")
    if not prestrain > -1:
        raise ParameterError(f"prestrain={prestrain:g}: must be > -1")
    for name, value in (("damping_axial", damping_axial), ("damping_bending", damping_bending)):
        if value < 0:
            raise ParameterError(f"{name}={value:g} s: must be >= 0")
    values = {
        "E": material.E, "G": material.G, "A": section.A, "I": section.Iz, "Iy": section.Iy,
        "Iz": section.Iz, "J": section.J, "shear_factor": section.shear_factor, "rho": material.rho,
        "prestrain": prestrain, "damping_axial": damping_axial, "damping_bending": damping_bending,
    }
    out = np.empty((length.size, len(element.params)))
    for k, name in enumerate(element.param_names):
        out[:, k] = length if name == "length" else values[name]
    return out
