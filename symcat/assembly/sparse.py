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


#: Structures (:class:`ScatterPattern`, :class:`PatternSum`, :class:`Congruence`) kept by their
#: inputs: form finding assembles a new system of the same topology at every iteration.
_STRUCTURES: dict = {}
MAX_STRUCTURES = 32


def _memo(kind: str, arrays, extra, build):
    key = (kind, extra, *(np.ascontiguousarray(a).tobytes() for a in arrays))
    found = _STRUCTURES.get(key)
    if found is None:
        if len(_STRUCTURES) >= MAX_STRUCTURES:
            _STRUCTURES.pop(next(iter(_STRUCTURES)))
        found = _STRUCTURES[key] = build()
    return found


class ScatterPattern:
    """Where the nonzeros of element matrices land in a global sparse matrix, in NumPy: the
    global pattern (CSC, sorted) and, for each element's local nonzeros, the global nonzero it
    adds to. The numeric assembly (:meth:`data`, :meth:`csc`) and CasADi's
    (:class:`MatrixScatter`) share it.

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
        self.n_elements, self.local_shape = rows.shape[0], (rows.shape[1], cols.shape[1])
        self.shape = (int(shape[0]), int(shape[1]))
        colind, row = local_sparsity.get_ccs()
        self.local_rows = np.asarray(row, dtype=np.int64)
        self.local_cols = np.repeat(np.arange(cols.shape[1]), np.diff(colind))
        n_rows, n_cols = self.shape

        def build():
            g_row = rows[:, self.local_rows].ravel()  # element-major, then local nonzero order
            g_col = cols[:, self.local_cols].ravel()
            # the global pattern from the sorted unique (column, row) keys
            unique, position = np.unique(g_col * n_rows + g_row, return_inverse=True)
            return unique % n_rows, np.searchsorted(unique // n_rows, np.arange(n_cols + 1)).astype(np.int64), position

        self.indices, self.indptr, self.position = _memo("scatter", (rows, cols, self.local_rows, self.local_cols),
                                                         self.shape, build)
        self.nnz = self.indices.size

    def data(self, local: np.ndarray) -> np.ndarray:
        """The global nonzeros (CSC order) from the element matrices' nonzeros ``local``
        (element after element, each in its CCS order: a mapped kernel's sparse output)."""
        return np.bincount(self.position, weights=local, minlength=self.nnz)

    def csc(self, local: np.ndarray) -> sps.csc_matrix:
        """The global matrix from ``local`` (see :meth:`data`)."""
        return sps.csc_matrix((self.data(local), self.indices, self.indptr), shape=self.shape)

    def sparsity(self) -> ca.Sparsity:
        return ca.Sparsity(self.shape[0], self.shape[1], self.indptr.tolist(), self.indices.tolist())


class MatrixScatter:
    """Adds element matrices (stacked as ``vec`` of an (n_r x n_c*N) map output) into a global
    sparse matrix in a CasADi graph: one constant sparse product (:class:`ScatterPattern`'s
    positions as a 0/1 transfer matrix).

    Parameters
    ----------
    rows, cols, shape, local_sparsity
        As :class:`ScatterPattern`.
    """

    def __init__(self, rows: np.ndarray, cols: np.ndarray, shape, local_sparsity: ca.Sparsity):
        pattern = ScatterPattern(rows, cols, shape, local_sparsity)
        self.sparsity = pattern.sparsity()
        n_r, n_c = pattern.local_shape
        n_el = pattern.n_elements
        # Local nonzeros of element k sit at k * (n_r * n_c) + linear index in vec(map output).
        src = (np.arange(n_el)[:, None] * (n_r * n_c) + (pattern.local_rows + n_r * pattern.local_cols)[None, :]).ravel()
        t = sps.csc_matrix((np.ones(src.size), (pattern.position, src)), shape=(pattern.nnz, n_el * n_r * n_c))
        self.transfer = to_casadi_sparse(t)

    @classmethod
    def square(cls, indices: np.ndarray, n_global: int, local_sparsity: ca.Sparsity) -> "MatrixScatter":
        return cls(indices, indices, (n_global, n_global), local_sparsity)

    def __call__(self, mapped: ca.MX) -> ca.MX:
        """Global sparse matrix from the mapped element matrices ``mapped``."""
        nz = ca.mtimes(self.transfer, ca.vec(ca.densify(mapped)))
        return ca.sparsity_cast(nz, self.sparsity)


def _keys(indptr: np.ndarray, indices: np.ndarray, n_rows: int) -> np.ndarray:
    cols = np.repeat(np.arange(len(indptr) - 1, dtype=np.int64), np.diff(indptr))
    return cols * n_rows + np.asarray(indices, np.int64)


class PatternSum:
    """Sum of sparse matrices of fixed patterns (CSC ``(indptr, indices)``) on the union of
    the patterns, which stays fixed: a SciPy sum drops entries whose values cancel, and a
    factorization or a precomputed index needs the same pattern at every call.

    Parameters
    ----------
    patterns : list of (indptr, indices)
        The terms' CSC patterns (sorted indices).
    shape : (int, int)
    """

    def __init__(self, patterns, shape):
        self.shape = (int(shape[0]), int(shape[1]))
        patterns = [(np.asarray(ptr, np.int64), np.asarray(ind, np.int64)) for ptr, ind in patterns]
        if len(patterns) == 1:  # the term's own pattern
            self.indptr, self.indices = patterns[0]
            self.positions = [np.arange(self.indices.size)]
        else:
            self.indices, self.indptr, self.positions = _memo(
                "sum", [a for pattern in patterns for a in pattern], self.shape, lambda: self._union(patterns))
        self.nnz = self.indices.size

    def _union(self, patterns):
        # SciPy's sum of the patterns with unit values (a merge of sorted columns, nothing
        # cancels): linear, where sorting every term's entries (np.unique) took seconds on a line
        total = sps.csc_matrix(self.shape)
        for ptr, ind in patterns:
            total = total + sps.csc_matrix((np.ones(ind.size), ind, ptr), shape=self.shape)
        total.sort_indices()
        indptr, indices = total.indptr.astype(np.int64), total.indices.astype(np.int64)
        union = _keys(indptr, indices, self.shape[0])
        return indices, indptr, [np.searchsorted(union, _keys(ptr, ind, self.shape[0])) for ptr, ind in patterns]

    def data(self, terms) -> np.ndarray:
        """The sum's nonzeros from the terms' (one array per pattern, its CSC order)."""
        if len(self.positions) == 1:
            return np.array(terms[0], float)
        out = np.zeros(self.nnz)
        for at, values in zip(self.positions, terms):
            out += np.bincount(at, weights=values, minlength=self.nnz)
        return out

    def csc(self, terms) -> sps.csc_matrix:
        return sps.csc_matrix((self.data(terms), self.indices, self.indptr), shape=self.shape)


class Congruence:
    """``P^T A P`` as a linear map of the nonzeros of ``A`` (a fixed CSC pattern) to those of
    the result (its pattern fixed too): a change of coordinates of an assembled matrix (free
    coordinates picked, or Cholesky coordinates) without a sparse product's varying pattern.

    Parameters
    ----------
    p : scipy.sparse matrix (n x m)
    indptr, indices : ndarray
        The pattern of ``A`` (n x n).
    """

    def __init__(self, p, indptr, indices):
        p = sps.csr_matrix(p)
        p.sort_indices()
        indptr, indices = np.asarray(indptr, np.int64), np.asarray(indices, np.int64)
        self.shape = (p.shape[1], p.shape[1])
        self.indices, self.indptr, self.map = _memo("congruence", (p.indptr, p.indices, p.data, indptr, indices),
                                                    p.shape, lambda: self._build(p, indptr, indices))

    @staticmethod
    def _build(p, indptr, indices):
        n, m = p.shape
        a_cols = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr))
        a_rows = indices
        counts = np.diff(p.indptr)
        ci, cj = counts[a_rows], counts[a_cols]
        pairs = ci * cj
        entry = np.repeat(np.arange(a_rows.size), pairs)
        local = np.arange(pairs.sum()) - np.repeat(np.cumsum(pairs) - pairs, pairs)
        at_i = p.indptr[a_rows][entry] + local // cj[entry]
        at_j = p.indptr[a_cols][entry] + local % cj[entry]
        rows, cols = p.indices[at_i].astype(np.int64), p.indices[at_j].astype(np.int64)
        keys = cols * m + rows
        union, position = np.unique(keys, return_inverse=True)
        return (union % m, np.searchsorted(union // m, np.arange(m + 1)).astype(np.int64),
                sps.csr_matrix((p.data[at_i] * p.data[at_j], (position, entry)), shape=(union.size, a_rows.size)))

    def data(self, a_data: np.ndarray) -> np.ndarray:
        return self.map @ a_data

    def csc(self, a_data: np.ndarray) -> sps.csc_matrix:
        return sps.csc_matrix((self.data(a_data), self.indices, self.indptr), shape=self.shape)
