"""Rayleigh damping of ANCF bodies."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import scipy.sparse as sps


@dataclass(frozen=True, eq=False)
class RayleighDamping:
    """Linear viscous damping ``Q = -(alpha M + beta K0) v`` on the coordinates of ANCF bodies.

    ``M`` is the bodies' constant mass matrix (consistent element mass and their
    :class:`NodalMass` terms), ``K0`` a constant stiffness, so the damping matrix ``C`` is
    assembled once, as a constant sparse matrix times the velocities.

    Parameters
    ----------
    bodies : tuple of str
        Names of the damped ANCF bodies (already in the scene). Their coordinates, body after
        body in this order (each ``body.q0.size``, fixed ones included), are the rows and
        columns of ``stiffness`` and the entries of ``stiffness_at``.
    alpha : float
        Mass-proportional coefficient (1/s), >= 0.
    beta : float
        Stiffness-proportional coefficient (s), >= 0.
    stiffness_at : "initial" or array
        Where ``K0`` is the tangent stiffness of the bodies' own elements (elastic forces
        only: no springs, loads or contacts): ``"initial"`` at their coordinates ``q0`` in the
        scene, or at the given coordinates (length: all the bodies' coordinates). Ignored
        when ``stiffness`` is given.
    stiffness : matrix, optional
        ``K0`` itself (SciPy sparse or dense, square over the bodies' coordinates), e.g. the
        stiffness a structural model used for its Rayleigh damping
        (:func:`symcat.catenary.catenary_scene` passes the
        :class:`~symcat.catenary.CatenaryStructure`'s, droppers and supports included).
    """

    bodies: tuple[str, ...]
    alpha: float
    beta: float
    stiffness_at: Any = "initial"
    stiffness: Any = None

    def stiffness_matrix(self) -> sps.csc_matrix | None:
        """``stiffness`` as SciPy CSC (None when not given)."""
        return None if self.stiffness is None else sps.csc_matrix(self.stiffness, dtype=float)
