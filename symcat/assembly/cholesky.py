"""Cholesky coordinates (seed paper, Section 5): the constant transformation that makes the
ANCF mass matrix the identity.

With ``M = U^T U`` (``U`` upper triangular), the Cholesky coordinates are ``p = U e``, so
``T = 1/2 e_dot^T M e_dot = 1/2 p_dot^T p_dot``; generalized forces transform as
``Q_p = U^{-T} Q_e``. ANCF mass matrices are banded along a chain, so ``U`` is banded and
both directions cost O(n * bandwidth) (the inverse ``U^{-1}`` itself is dense: never formed).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sps


class CholeskyCoordinates:
    """Banded Cholesky factor of a constant symmetric positive definite mass matrix.

    Parameters
    ----------
    mass : scipy sparse matrix
        The mass matrix (of the free coordinates).
    """

    def __init__(self, mass: sps.spmatrix):
        m = sps.csr_matrix(mass)
        self.n = m.shape[0]
        coo = m.tocoo()
        self.bandwidth = int(np.abs(coo.row - coo.col).max(initial=0))
        u = self.bandwidth
        band = np.zeros((u + 1, self.n))  # upper form: band[u + i - j, j] = M[i, j]
        mask = coo.col >= coo.row
        band[u + coo.row[mask] - coo.col[mask], coo.col[mask]] = coo.data[mask]
        self._band = sla.cholesky_banded(band, lower=False)

    def factor(self) -> sps.csc_matrix:
        """``U`` as a sparse upper-triangular matrix."""
        u = self.bandwidth
        diags = [self._band[u - k, k:] for k in range(u + 1)]
        return sps.diags(diags, list(range(u + 1)), shape=(self.n, self.n), format="csc")

    def to_cholesky(self, e: np.ndarray) -> np.ndarray:
        """``p = U e``."""
        return self.factor() @ e

    def from_cholesky(self, p: np.ndarray) -> np.ndarray:
        """``e = U^{-1} p`` (banded back substitution)."""
        return sla.solve_banded((0, self.bandwidth), self._band, p)

    def force_to_cholesky(self, q_e: np.ndarray) -> np.ndarray:
        """``Q_p = U^{-T} Q_e``."""
        lower = self._band_transposed()
        return sla.solve_banded((self.bandwidth, 0), lower, q_e)

    def _band_transposed(self) -> np.ndarray:
        u = self.bandwidth
        lower = np.zeros_like(self._band)
        for k in range(u + 1):
            lower[k, : self.n - k] = self._band[u - k, k:]
        return lower
