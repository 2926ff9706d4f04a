"""Broyden's secant updates of a kept generalized-alpha step matrix
(:meth:`.alpha_step.StepEquations.secant`)."""
from __future__ import annotations

import numpy as np

#: Broyden updates of a kept step matrix at most (:meth:`.alpha_step.StepEquations.secant`).
MAX_SECANTS = 20


class Secants:
    """Broyden's updates of an inverse matrix ``H_0`` in product form, ``H = (I + s_k c_k^T)
    ... (I + s_1 c_1^T) H_0`` (:meth:`.alpha_step.StepEquations.secant`), applied at once: with ``z_0 = H_0
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
