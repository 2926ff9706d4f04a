"""Loads on ANCF nodes."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class NodalForce:
    """A dead force (N) on the position of a node of an ANCF body."""

    body: str
    node: int
    force: tuple[float, ...]


@dataclass(frozen=True)
class SlopeMoment:
    """A moment (N m) about a fixed unit ``axis`` applied through a node's slope ``r_x``.

    Conservative for any rotation (potential ``-M theta``), so a beam can be rolled up to a
    full circle with it.
    """

    body: str
    node: int
    moment: float
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def unit_axis(self) -> np.ndarray:
        a = np.asarray(self.axis, dtype=float)
        return a / np.linalg.norm(a)


@dataclass(frozen=True)
class NodalMass:
    """A point mass (kg) on the position of a node of an ANCF body (a clamp, a steady arm):
    a diagonal term on the node's position coordinates of the mass matrix, and its weight."""

    body: str
    node: int
    mass: float
