"""Linearized free vibration about a static state: ``K phi = omega^2 M phi`` on free coordinates."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..assembly.system import System
from ..errors import ParameterError

DENSE_LIMIT = 2500


@dataclass
class ModalResult:
    """Natural frequencies and mode shapes.

    Attributes
    ----------
    frequencies_hz : ndarray
        Natural frequencies (Hz), ascending.
    shapes : ndarray (n, n_modes)
        Mode shapes in global coordinates (zero on fixed coordinates), mass-normalized.
    """

    frequencies_hz: np.ndarray
    shapes: np.ndarray


def modes(system: System, q: np.ndarray, n_modes: int, dof_mask: np.ndarray | None = None) -> ModalResult:
    """Lowest ``n_modes`` modes of the system linearized about the static state ``q``.

    Parameters
    ----------
    system : System
        Assembled scene; the stiffness includes the load stiffness of its loads at full load.
    q : ndarray
        Static state to linearize about.
    n_modes : int
        Number of modes.
    dof_mask : ndarray of bool, optional
        Restrict to these coordinates (e.g. the in-plane coordinates of a planar state,
        where in-plane and out-of-plane motions decouple).
    """
    free = system.dofs.free
    if dof_mask is not None:
        free = free[np.asarray(dof_mask)[free]]
    if not 1 <= n_modes < free.size:
        raise ParameterError(f"n_modes={n_modes}: must be between 1 and {free.size - 1}")
    _, jac = system.eval_static(q, 1.0)
    k = -jac[free][:, free]
    k = (k + k.T) / 2  # the load stiffness of a moment is not exactly symmetric
    m = system.mass_matrix[free][:, free]
    if free.size <= DENSE_LIMIT:
        w2, vec = sla.eigh(k.toarray(), m.toarray(), subset_by_index=[0, n_modes - 1])
    else:
        w2, vec = spla.eigsh(sps.csc_matrix(k), n_modes, sps.csc_matrix(m), sigma=0.0, which="LM")
        order = np.argsort(w2)
        w2, vec = w2[order], vec[:, order]
    shapes = np.zeros((system.n, n_modes))
    shapes[free] = vec
    return ModalResult(np.sqrt(np.maximum(w2, 0.0)) / (2 * np.pi), shapes)
