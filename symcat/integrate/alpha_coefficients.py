"""The coefficients of the generalized-alpha method (Chung and Hulbert 1993) of the multibody
integrator (:mod:`symcat.integrate.generalized_alpha`), its Python and compiled steps."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import ParameterError


@dataclass(frozen=True)
class AlphaCoefficients:
    """Chung-Hulbert coefficients for the spectral radius ``rho_inf`` at infinite frequency
    (second order, maximal high-frequency dissipation for the low-frequency error)."""

    rho_inf: float

    def __post_init__(self):
        if not (isinstance(self.rho_inf, (int, float)) and 0.0 <= self.rho_inf <= 1.0):
            raise ParameterError(f"rho_inf={self.rho_inf!r}: must be within 0..1 (1: no numerical dissipation)")

    @property
    def alpha_m(self) -> float:
        return (2 * self.rho_inf - 1) / (self.rho_inf + 1)

    @property
    def alpha_f(self) -> float:
        return self.rho_inf / (self.rho_inf + 1)

    @property
    def gamma(self) -> float:
        return 0.5 + self.alpha_f - self.alpha_m

    @property
    def beta(self) -> float:
        return 0.25 * (self.gamma + 0.5) ** 2
