"""Sparse linear algebra as CasADi graphs for compiled code: the LU factorization of a matrix
that is a band plus a dense border, and its solve.

A model of wires with a few bodies, joints or contacts has a step matrix whose wire block,
ordered by reverse Cuthill-McKee, is a narrow band (half-bandwidth ~12 for cable elements);
the other unknowns (a body, an arc length, multipliers) form a dense border of a few rows and
columns. Factorized as

    [B  E]   B = L U (band, no pivoting)
    [F  D]   S = D - F B^-1 E (dense, small: solved through its QR),

the cost is O(n b^2) and every index is known when the code is generated: the band's
factorization and solves are C loops over its fixed layout (:mod:`symcat.codegen.band_c`;
column-major, over the envelope the values reach: a band ordered by reverse Cuthill-McKee
holds about half its width on average, and the solves, a line's largest cost, stream the
factor from memory), the
border's gathers and products straight-line code, with no sparse bookkeeping at run time. Without pivoting the band must not
need it: the wires' block of a generalized-alpha step is ``c_m M + gamma h D + beta h^2 K``
plus small constraint terms, positive definite in practice; a zero or tiny pivot shows as a
non-finite solution, which the caller treats as a failed step.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
from scipy.sparse import csr_matrix, identity
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ..codegen.band_c import envelope_functions, envelope_size, matvec


class BorderedBand:
    """The layout of a square sparsity pattern ``[B E; F D]`` (``B`` the first ``n_b`` unknowns)
    as a band after a reverse Cuthill-McKee ordering of ``B`` plus a dense border, and the
    graphs of its factorization and solve.

    Parameters
    ----------
    sparsity : casadi.Sparsity
        Of the whole matrix (n x n).
    n_b : int
        Size of the banded block.
    e_cols, f_rows : sequence of int, optional
        The border's columns whose rows in ``E`` and the border's rows whose columns in ``F``
        can be nonzero (positions in the border, default all): on a wire with a body on a
        sliding joint the body's own coordinates touch the wire through no entry of ``E``,
        and each border column or row left out saves a band solve at every renewal of the
        border and a column of the products at every solve.
    """

    def __init__(self, sparsity: ca.Sparsity, n_b: int, e_cols=None, f_rows=None):
        n = sparsity.size1()
        self.n, self.n_b, self.n_r = n, n_b, n - n_b
        self.e_cols = np.arange(self.n_r) if e_cols is None else np.asarray(e_cols, int)
        self.f_rows = np.arange(self.n_r) if f_rows is None else np.asarray(f_rows, int)
        self.pattern = sparsity
        colind, row = sparsity.get_ccs()
        rows = np.array(row, int)
        cols = np.repeat(np.arange(n), np.diff(colind))
        self.nnz = rows.size
        in_b = (rows < n_b) & (cols < n_b)
        pattern = csr_matrix((np.ones(in_b.sum()), (rows[in_b], cols[in_b])), shape=(n_b, n_b))
        pattern = pattern + pattern.T + identity(n_b, format="csr") if n_b else pattern
        self.perm = reverse_cuthill_mckee(pattern.tocsr(), symmetric_mode=True).astype(int) if n_b else np.zeros(0, int)
        where = np.empty(n_b, int)
        where[self.perm] = np.arange(n_b)
        i, j = where[rows[in_b]], where[cols[in_b]]
        self.bw = int(np.max(np.abs(i - j))) if i.size else 0
        w = 2 * self.bw + 1
        # Gathers from the matrix's nonzeros (index nnz: a zero) into the band (column-major,
        # a[i, j] at j * w + i - j + bw: see band_c.envelope_functions), the border E
        # (n_b x n_r), F (n_r x n_b) and D.
        zero = self.nnz
        self.band_from = np.full(n_b * w, zero)
        self.band_from[j * w + i - j + self.bw] = np.flatnonzero(in_b)
        self.e_from = np.full((n_b, self.n_r), zero)
        self.f_from = np.full((self.n_r, n_b), zero)
        self.d_from = np.full((self.n_r, self.n_r), zero)
        e = (rows < n_b) & (cols >= n_b)
        self.e_from[where[rows[e]], cols[e] - n_b] = np.flatnonzero(e)
        f = (rows >= n_b) & (cols < n_b)
        self.f_from[rows[f] - n_b, where[cols[f]]] = np.flatnonzero(f)
        d = (rows >= n_b) & (cols >= n_b)
        self.d_from[rows[d] - n_b, cols[d] - n_b] = np.flatnonzero(d)
        self.band_entries = envelope_size(n_b, self.bw) if n_b else 0  # the band's LU and its envelope
        # the couplings that can be nonzero: E's columns e_cols, F's rows f_rows
        self.e_from, self.f_from = self.e_from[:, self.e_cols], self.f_from[self.f_rows, :]
        # the factor: LU of the band, X = B^-1 E (n_b x n_e), F (n_f x n_b), S^-1
        self.n_e, self.n_f = self.e_cols.size, self.f_rows.size
        self.size = self.band_entries + n_b * (self.n_e + self.n_f) + self.n_r**2

    # --- graphs -----------------------------------------------------------------------------
    def factorize(self, nonzeros: ca.MX) -> ca.MX:
        """The factor (a vector of :attr:`size`) of the matrix with the given nonzeros (in the
        CCS order of the pattern)."""
        n_b, n_r = self.n_b, self.n_r
        values = ca.vertcat(nonzeros, 0)

        def gather(index):
            return values[index.ravel(order="F").tolist()]

        lu = envelope_functions(n_b, self.bw)[0](gather(self.band_from)) if n_b else ca.MX(0, 1)
        return self._with_border(lu, gather) if n_r else lu

    def refactorize_border(self, factor: ca.MX, nonzeros: ca.MX) -> ca.MX:
        """``factor`` with its border (``E``, ``F``, ``D`` and the Schur complement) from the
        matrix with the given nonzeros, its band's LU kept (the band's entries are not read)."""
        if not self.n_r:
            return factor
        return ca.vertcat(factor[: self.band_entries], self.border(factor, nonzeros))

    def border(self, factor: ca.MX, nonzeros: ca.MX) -> ca.MX:
        """The border's part of the factor (its entries from :attr:`band_entries` on) from the
        matrix with the given nonzeros and the band's LU in ``factor``: what
        :meth:`refactorize_border` renews, for a caller that writes it into the factor's
        memory in place."""
        values = ca.vertcat(nonzeros, 0)
        return self._border(factor[: self.band_entries], lambda index: values[index.ravel(order="F").tolist()])

    def _with_border(self, lu: ca.MX, gather) -> ca.MX:
        return ca.vertcat(lu, self._border(lu, gather))

    def _border(self, lu: ca.MX, gather) -> ca.MX:
        n_b, n_r, n_e, n_f = self.n_b, self.n_r, self.n_e, self.n_f
        e = ca.reshape(gather(self.e_from), n_b, n_e)
        f = ca.reshape(gather(self.f_from), n_f, n_b)
        d = ca.reshape(gather(self.d_from), n_r, n_r)
        # a call per column, not a map: a map's code copies the LU it shares once per column
        solve = envelope_functions(n_b, self.bw)[1]
        x = ca.horzcat(*(solve(lu, e[:, j]) for j in range(n_e))) if n_b and n_e else ca.MX(n_b, n_e)
        s = ca.MX(d)
        if n_e and n_f:
            fx = ca.reshape(matvec(n_f, n_b).map(n_e)(ca.vec(f), x), n_f, n_e) if n_b else ca.MX(n_f, n_e)
            s[self.f_rows.tolist(), self.e_cols.tolist()] = s[self.f_rows.tolist(), self.e_cols.tolist()] - fx
        s_inv = ca.solve(s, ca.MX.eye(n_r), "qr")
        return ca.vertcat(ca.vec(x), ca.vec(f), ca.vec(s_inv))

    def solve(self, factor: ca.MX, rhs: ca.MX) -> ca.MX:
        """``A^-1 rhs`` from :meth:`factorize`'s factor."""
        n_b, n_r = self.n_b, self.n_r
        lu = factor[: self.band_entries]
        perm = self.perm.tolist()
        z = envelope_functions(n_b, self.bw)[1](lu, rhs[perm]) if n_b else ca.MX(0, 1)
        if n_r:
            n_e, n_f = self.n_e, self.n_f
            at = self.band_entries
            x = factor[at : at + n_b * n_e]  # (n_b x n_e, column-major)
            f = factor[at + n_b * n_e : at + n_b * (n_e + n_f)]  # (n_f x n_b)
            s_inv = ca.reshape(factor[at + n_b * (n_e + n_f) :], n_r, n_r)
            t = ca.MX(rhs[n_b:])
            if n_f and n_b:
                t[self.f_rows.tolist()] = t[self.f_rows.tolist()] - matvec(n_f, n_b)(f, z)
            y_r = ca.mtimes(s_inv, t)
            if n_e and n_b:
                z = z - matvec(n_b, n_e)(x, y_r[self.e_cols.tolist()])
        else:
            y_r = ca.MX(0, 1)
        back = np.empty(n_b, int)
        back[self.perm] = np.arange(n_b)
        return ca.vertcat(z[back.tolist()] if n_b else ca.MX(0, 1), y_r)


def step_layout(st, couplings: tuple | None = None) -> BorderedBand:
    """The iteration matrix's :class:`BorderedBand`: the wires' block in the bulk's pattern,
    the rows and columns of the other unknowns dense; of their couplings to the wires only
    ``couplings = (e_cols, f_rows)`` (:meth:`.ChunkResidual.couplings`; default: all)."""
    n_b, n = st.bulk.n_b, st.n_y
    rows, cols = [], []
    if n_b:
        b_colind, b_row = st.bulk.jacobian.indptr, st.bulk.jacobian.indices
        rows += b_row.tolist()
        cols += np.repeat(np.arange(n_b), np.diff(b_colind)).tolist()
    # the border: its columns whole, its rows over the wires' columns (n (n - n_b) entries,
    # not a test of all n^2 places: a line has tens of thousands of unknowns)
    n_r = n - n_b
    rows += np.tile(np.arange(n), n_r).tolist() + np.tile(np.arange(n_b, n), n_b).tolist()
    cols += np.repeat(np.arange(n_b, n), n).tolist() + np.repeat(np.arange(n_b), n_r).tolist()
    return BorderedBand(ca.Sparsity.triplet(n, n, rows, cols), n_b, *(couplings or (None, None)))
