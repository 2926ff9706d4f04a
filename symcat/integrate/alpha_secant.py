"""Broyden's secant updates of a kept generalized-alpha step matrix
(:meth:`.alpha_linear.StepSolve.secant`)."""
from __future__ import annotations

import numpy as np

#: Broyden updates of a kept step matrix at most (:meth:`.alpha_linear.StepSolve.secant`).
MAX_SECANTS = 20
#: A secant update that would scale the Newton update by more than this is skipped.
SECANT_GAIN = 10.0


class Secants:
    """Broyden's updates of an inverse matrix ``H_0`` in product form, ``H = (I + s_k c_k^T)
    ... (I + s_1 c_1^T) H_0`` (:meth:`.alpha_linear.StepSolve.secant`), applied at once: with ``z_0 = H_0
    v``, ``H v = z_0 + S^T alpha`` where ``alpha`` solves the unit lower triangular ``alpha_j -
    sum_{i<j} (c_j^T s_i) alpha_i = c_j^T z_0``, whose inverse is kept (a few products with
    small matrices instead of ``k`` pairs of vector operations)."""

    def __init__(self, n: int):
        self.s = np.zeros((MAX_SECANTS, n))
        self.c = np.zeros((MAX_SECANTS, n))
        self.inverse = np.zeros((MAX_SECANTS, MAX_SECANTS))  # of the triangular matrix above
        self.k = 0

    def clear(self) -> None:
        self.k = 0

    def add(self, s: np.ndarray, c: np.ndarray) -> None:
        k = self.k
        self.s[k], self.c[k] = s, c
        # [[L, 0], [l^T, 1]]^-1 = [[L^-1, 0], [-l^T L^-1, 1]] with l_i = -c^T s_i
        self.inverse[k, :k] = (self.s[:k] @ c) @ self.inverse[:k, :k]
        self.inverse[k, k] = 1.0
        self.k = k + 1

    def apply(self, z0: np.ndarray) -> np.ndarray:
        k = self.k
        if not k:
            return z0
        return z0 + (self.inverse[:k, :k] @ (self.c[:k] @ z0)) @ self.s[:k]

    def update(self, z: np.ndarray, step: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """The Newton update ``z = -H F(y)`` after the update ``step = -H F(y - step)``,
        corrected by Broyden's "good" update of ``H`` in the norm ``weights`` (the tolerances'
        scaling), which is added: ``H <- (I + s step^T W / |step|^2) H`` with ``s`` the
        corrected update (Kelley's product form). At most :data:`MAX_SECANTS` updates, and none
        whose denominator would amplify ``z`` more than :data:`SECANT_GAIN` times."""
        if self.k >= MAX_SECANTS:
            return z
        s_weighted = step * weights
        norm = float(s_weighted @ step)
        if not norm > 0:
            return z
        c = s_weighted / norm
        denominator = 1.0 - float(c @ z)
        if abs(denominator) < 1.0 / SECANT_GAIN:
            return z
        s = z / denominator
        self.add(s, c)
        return s
