"""Scatter of mapped element outputs into global vectors and sparse matrices (CasADi MX).

The scatter is a constant sparse 0/1 matrix applied to the stacked element outputs, so the
assembly is one sparse product in the CasADi graph (no Python loop at evaluation time).
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sps


def to_casadi_sparse(matrix: sps.spmatrix) -> ca.DM:
    m = sps.csc_matrix(matrix)
    m.sort_indices()
    sp = ca.Sparsity(m.shape[0], m.shape[1], m.indptr.tolist(), m.indices.tolist())
    return ca.DM(sp, m.data.tolist())


def to_scipy(matrix: ca.DM) -> sps.csc_matrix:
    """CasADi sparse DM -> SciPy CSC."""
    colind, row = matrix.sparsity().get_ccs()
    return sps.csc_matrix((np.array(matrix.nonzeros()), np.array(row), np.array(colind)), shape=matrix.shape)


def vector_scatter(indices: np.ndarray, n_global: int) -> ca.DM:
    """Matrix that adds stacked element vectors (columns of length n_loc) into a global vector.

    Negative indices mark local entries that are dropped.
    """
    rows = np.asarray(indices).ravel()  # element after element, as vec() stacks them
    cols = np.arange(rows.size)
    keep = rows >= 0
    a = sps.csc_matrix((np.ones(keep.sum()), (rows[keep], cols[keep])), shape=(n_global, rows.size))
    return to_casadi_sparse(a)


class MatrixScatter:
    """Adds element matrices (stacked as ``vec`` of an (n_r x n_c*N) map output) into a global
    sparse matrix.

    Parameters
    ----------
    rows, cols : ndarray (N, n_r) and (N, n_c)
        Global row and column of each local row and column of each element.
    shape : (int, int)
        Shape of the global matrix.
    local_sparsity : casadi.Sparsity
        Sparsity of one element matrix (only its nonzeros are scattered).
    """

    def __init__(self, rows: np.ndarray, cols: np.ndarray, shape, local_sparsity: ca.Sparsity):
        rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
        n_el, n_r = rows.shape
        n_c = cols.shape[1]
        colind, row = local_sparsity.get_ccs()
        col = np.repeat(np.arange(n_c), np.diff(colind))
        row = np.asarray(row, dtype=np.int64)
        g_row = rows[:, row].ravel()          # element-major, then local nonzero order
        g_col = cols[:, col].ravel()
        n_rows, n_cols = shape
        pattern = sps.csc_matrix((np.ones(g_row.size), (g_row, g_col)), shape=shape)
        pattern.sum_duplicates()
        pattern.sort_indices()
        self.sparsity = ca.Sparsity(n_rows, n_cols, pattern.indptr.tolist(), pattern.indices.tolist())
        # Position of each (row, col) pair among the global nonzeros (CSC order).
        key = pattern.indices.astype(np.int64) + n_rows * np.repeat(np.arange(n_cols), np.diff(pattern.indptr)).astype(np.int64)
        pos = np.searchsorted(key, g_row + n_rows * g_col)
        # Local nonzeros of element k sit at k * (n_r * n_c) + linear index in vec(map output).
        src = (np.arange(n_el)[:, None] * (n_r * n_c) + (row + n_r * col)[None, :]).ravel()
        t = sps.csc_matrix((np.ones(src.size), (pos, src)), shape=(pattern.nnz, n_el * n_r * n_c))
        self.transfer = to_casadi_sparse(t)

    @classmethod
    def square(cls, indices: np.ndarray, n_global: int, local_sparsity: ca.Sparsity) -> "MatrixScatter":
        return cls(indices, indices, (n_global, n_global), local_sparsity)

    def __call__(self, mapped: ca.MX) -> ca.MX:
        """Global sparse matrix from the mapped element matrices ``mapped``."""
        nz = ca.mtimes(self.transfer, ca.vec(ca.densify(mapped)))
        return ca.sparsity_cast(nz, self.sparsity)
