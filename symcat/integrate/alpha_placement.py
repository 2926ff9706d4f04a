"""Index maps between a generalized-alpha step's unknowns and its rest's compiled function
(:mod:`.alpha_step`), for one placement of the proxy elements (:mod:`.alpha_proxies`) or for a
rest without them.

Each input of the rest is a weighted sum of entries of ``y`` or ``p`` plus a constant (a
proxy's coordinate is its actual element's, or a combination of a wire end's past the wire);
each nonzero of its outputs lands, weighted, on one or more rows and columns of the step. A
contact stays on one element for many steps: these maps are built once per placement, and an
evaluation is a few gathers and one ``bincount`` per vector instead of the substitution and
expansion in Python of every call."""
from __future__ import annotations

import numpy as np


def weighted_sum(index: np.ndarray, weights: np.ndarray, size: int) -> np.ndarray:
    """``bincount(index, weights, minlength=size)``, floats also without terms."""
    return np.bincount(index, weights, minlength=size) if index.size else np.zeros(size)


class Terms:
    """``out = bincount(place, x[source] * weight) + constant``: a vector of ``size`` made of
    weighted entries of another."""

    def __init__(self, place, source, weight, constant):
        self.place, self.source, self.weight = (np.asarray(place, int), np.asarray(source, int),
                                                np.asarray(weight, float))
        self.constant = np.asarray(constant, float)
        self.size = self.constant.size
        # one term per place with weight 1 (no proxy moved, or all on a real element): a gather
        self._copy = (self.place.size == self.size and np.array_equal(self.place, np.arange(self.size))
                      and np.all(self.weight == 1.0) and not self.constant.any())

    def __call__(self, x: np.ndarray) -> np.ndarray:
        if self._copy:
            return x[self.source]
        return weighted_sum(self.place, x[self.source] * self.weight, self.size) + self.constant


class Placement:
    """The rest's inputs from ``(y, p)`` and its outputs on the step's rows and columns.

    Parameters
    ----------
    y_terms, p_terms : Terms
        The rest's ``y`` and ``p`` inputs.
    w : ndarray
        Start and length (m) of each proxy's actual element (empty without proxies).
    r_out, shift_out : tuple
        ``(nonzero, row, weight)`` per term of the residual's and the shift's nonzeros.
    jac : tuple
        ``(nonzero, row, column, weight)`` per term of the Jacobian's nonzeros.
    n_y, n_u : int
    """

    def __init__(self, y_terms: Terms, p_terms: Terms, w: np.ndarray, r_out, shift_out, jac, n_y: int, n_u: int):
        self.y_terms, self.p_terms, self.w = y_terms, p_terms, w
        self._r, self._shift, self.n_y, self.n_u = r_out, shift_out, n_y, n_u
        self.jac_nonzero, self.jac_rows, self.jac_cols, self.jac_weight = jac
        # the bulk unknowns (< n_b) in the Jacobian's rows and columns, per n_b: see touched()
        self._touched: dict[int, tuple] = {}
        self.cache: dict = {}  # what the step equations keep for this placement

    def add_terms(self, rows: np.ndarray, cols: np.ndarray) -> None:
        """Append terms of a fixed pattern to :attr:`jac_rows` and :attr:`jac_cols` (their
        values follow :meth:`jacobian`'s)."""
        self.jac_rows, self.jac_cols = np.r_[self.jac_rows, rows], np.r_[self.jac_cols, cols]
        self._touched.clear()
        self.cache.pop("csc", None)

    def inputs(self, y: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The rest's ``y`` and ``p`` inputs and the proxies' element data ``w``."""
        return self.y_terms(y), self.p_terms(p), self.w

    def residual(self, r_nz: np.ndarray, shift_nz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The rest's residual (n_y) and shift (n_u), dense, from its outputs' nonzeros."""
        (at, row, weight), (s_at, s_row, s_weight) = self._r, self._shift
        return (weighted_sum(row, r_nz[at] * weight, self.n_y),
                weighted_sum(s_row, shift_nz[s_at] * s_weight, self.n_u))

    def jacobian(self, values: np.ndarray) -> np.ndarray:
        """The Jacobian's values on :attr:`jac_rows` and :attr:`jac_cols` (duplicates add)."""
        return values[self.jac_nonzero] * self.jac_weight

    def touched(self, n_b: int) -> tuple[np.ndarray, np.ndarray, int]:
        """``(keys, flat, k)`` of the capacitance (:meth:`.alpha_linear.StepSolve.prepare`): the bulk
        unknowns in a row or column of the Jacobian then the others from ``n_b``, and each
        Jacobian term's place in the ``k x k`` matrix on ``keys`` (row-major)."""
        found = self._touched.get(n_b)
        if found is None:
            found = self._touched[n_b] = capacitance_keys(self.jac_rows, self.jac_cols, n_b, self.n_y)
        return found


def csc_pattern(rows: np.ndarray, cols: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(place, indices, indptr)``: each term's place in the data of the ``n x n`` CSC matrix
    of the pattern ``(rows, cols)`` (duplicates share one), for ``bincount(place, values)``."""
    unique, place = np.unique(np.asarray(cols, np.int64) * n + rows, return_inverse=True)
    indptr = np.searchsorted(unique // n, np.arange(n + 1))
    return place, unique % n, indptr


def capacitance_keys(rows: np.ndarray, cols: np.ndarray, n_b: int, n_y: int) -> tuple[np.ndarray, np.ndarray, int]:
    """See :meth:`Placement.touched` (``rows``, ``cols``: the Jacobian's terms)."""
    touched = np.unique(np.concatenate([rows[rows < n_b], cols[cols < n_b]]))
    keys = np.concatenate([touched, np.arange(n_b, n_y)])
    pos = np.full(n_y, -1)
    pos[keys] = np.arange(keys.size)
    k = keys.size
    return keys, pos[rows] * k + pos[cols], k


def output_maps(expand, r_rows, shift_rows, jac_rows, jac_cols):
    """The output maps of :class:`Placement` through ``expand`` (an index array -> ``(position
    in it, step index, weight)`` per term; the identity without proxies)."""
    at, row, weight = expand(r_rows)
    s_at, s_row, s_weight = expand(shift_rows)
    # J_actual = T^T J_proxy T, T the maps of the proxy coordinates: rows, then columns
    j_at, rows, j_weight = expand(jac_rows)
    cols = jac_cols[j_at]
    c_at, cols, c_weight = expand(cols)
    return ((at, row, weight), (s_at, s_row, s_weight),
            (j_at[c_at], rows[c_at], cols, j_weight[c_at] * c_weight))


def identity(index: np.ndarray):
    """The ``expand`` of a rest without proxies."""
    return np.arange(index.size), index, np.ones(index.size)
