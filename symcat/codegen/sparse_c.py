"""The wires' constant sparse products and scatter-adds as C loops, for the compiled
generalized-alpha steps of a line (:mod:`symcat.integrate.alpha_chunk_wires`): the products of
its constant symmetric matrices in one pass over their common upper triangle (:func:`symv`)
and the scatter-add of the elements' local values by constant indices (:func:`scatter`).

Externals to CasADi as the band kernels of :mod:`.band_c` are, compiled and included the same
way (:func:`.band_c.include_in` appends their sources to generated code that calls them).
"""
from __future__ import annotations

from functools import lru_cache

import casadi as ca
import numpy as np

from .band_c import _library

_SYMV = r"""
/* symcat symmetric products: y = A_1 x_1 + ... + A_{k} x_{k}, the A constant symmetric n = {n}
   matrices of one pattern: their diagonals (n x {k}, per row its k numbers), their strictly
   upper triangle by rows (row pointers n + 1, columns, values nnz x {k}; indices as numbers)
   (symcat.codegen.band_c) */
#ifndef casadi_real
#define casadi_real double
#endif
#ifndef casadi_int
#define casadi_int long long int
#endif
static const casadi_int {name}_sp[6][3] = {{{{{n1}, 1, 1}}, {{{nnz}, 1, 1}}, {{{knnz}, 1, 1}}, {{{kn}, 1, 1}}, {{{kn}, 1, 1}}, {{{n}, 1, 1}}}};

int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  const casadi_int n = {n}, k = {k};
  const casadi_real *restrict ptr = arg[0], *restrict col = arg[1], *restrict val = arg[2], *restrict dia = arg[3],
                    *restrict x = arg[4];
  casadi_real *restrict y = res[0], acc, xi[{k}];
  casadi_int i, e, j, m, end;
  if (!y) return 0;
  for (i = 0; i < n; ++i) y[i] = 0;
  if (!ptr || !col || !val || !dia || !x) return 0;
  for (i = 0; i < n; ++i) {{
    acc = 0;
    for (m = 0; m < k; ++m) {{
      xi[m] = x[m * n + i];
      acc += dia[i * k + m] * xi[m];
    }}
    end = (casadi_int) ptr[i + 1];
    for (e = (casadi_int) ptr[i]; e < end; ++e) {{
      j = (casadi_int) col[e];
      for (m = 0; m < k; ++m) {{
        acc += val[e * k + m] * x[m * n + j];
        y[j] += val[e * k + m] * xi[m];
      }}
    }}
    y[i] += acc;
  }}
  return 0;
}}

casadi_int {name}_n_in(void) {{ return 5; }}
casadi_int {name}_n_out(void) {{ return 1; }}
const casadi_int* {name}_sparsity_in(casadi_int i) {{ return {name}_sp[i]; }}
const casadi_int* {name}_sparsity_out(casadi_int i) {{ return {name}_sp[5]; }}
"""


_SCATTER = r"""
/* symcat scatter-add: y[index[e]] += v[e] (index -1: left out), {m} numbers into {n}
   (symcat.codegen.band_c) */
#ifndef casadi_real
#define casadi_real double
#endif
#ifndef casadi_int
#define casadi_int long long int
#endif
static const casadi_int {name}_sp[3][3] = {{{{{m}, 1, 1}}, {{{m}, 1, 1}}, {{{n}, 1, 1}}}};

int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  casadi_int e, i;
  const casadi_real *restrict index = arg[0], *restrict v = arg[1];
  casadi_real *restrict y = res[0];
  if (!y) return 0;
  for (i = 0; i < {n}; ++i) y[i] = 0;
  if (!index || !v) return 0;
  for (e = 0; e < {m}; ++e) {{
    i = (casadi_int) index[e];
    if (i >= 0) y[i] += v[e];
  }}
  return 0;
}}

casadi_int {name}_n_in(void) {{ return 2; }}
casadi_int {name}_n_out(void) {{ return 1; }}
const casadi_int* {name}_sparsity_in(casadi_int i) {{ return {name}_sp[i]; }}
const casadi_int* {name}_sparsity_out(casadi_int i) {{ return {name}_sp[2]; }}
"""


def symv_source(n: int, nnz: int, k: int) -> str:
    """The C source of ``symcat_symv_<n>_<nnz>_<k>`` (:func:`symv`)."""
    return _SYMV.format(name=f"symcat_symv_{n}_{nnz}_{k}", n=n, nnz=nnz, k=k, n1=n + 1, knnz=k * nnz, kn=k * n)


@lru_cache(maxsize=32)
def symv(n: int, nnz: int, k: int) -> ca.Function:
    """``(pointers, columns, values, diagonals, x) -> A_1 x_1 + ... + A_k x_k`` for ``k``
    symmetric ``n x n`` matrices of one pattern (:func:`symmetric_pattern`; ``x`` the ``x_m``
    stacked), as a CasADi external.

    Why: the wires' rows of a compiled step multiply the constant mass, Rayleigh and (linearized
    wires) stiffness matrices in every Newton iteration; as CasADi's sparse products each reads
    its whole pattern (an index and a value per entry) and adds into memory. Here one pass over
    the upper triangle serves both triangles and all the matrices: half the entries, one index
    per entry for all of them, the row's sum in a register."""
    return ca.external(f"symcat_symv_{n}_{nnz}_{k}", str(_library(symv_source(n, nnz, k))))


def symmetric_pattern(matrices, tol: float = 1e-12):
    """The inputs of :func:`symv` for ``matrices`` (SciPy sparse, square, one size): ``(pointers,
    columns, values, diagonals)`` as NumPy arrays, or None if one is not symmetric (to ``tol``
    of its largest entry; each is taken as its symmetric part) or their upper triangles are
    empty."""
    import scipy.sparse as sps

    mats = [sps.csr_matrix(m, dtype=float) for m in matrices]
    for m in mats:
        scale = abs(m).max() if m.nnz else 0.0
        if m.nnz and abs(m - m.T).max() > tol * scale:
            return None
    mats = [0.5 * (m + m.T) for m in mats]
    upper = [sps.triu(m, 1, format="csr") for m in mats]
    pattern = sum(abs(u) for u in upper)
    pattern = sps.csr_matrix((np.ones(pattern.nnz), pattern.indices, pattern.indptr), shape=pattern.shape)
    pattern.sort_indices()
    if not pattern.nnz:
        return None
    rows = np.repeat(np.arange(pattern.shape[0]), np.diff(pattern.indptr))
    values = np.stack([np.asarray(u[rows, pattern.indices]).ravel() for u in upper], axis=1)
    diagonals = np.stack([m.diagonal() for m in mats], axis=1)
    return (pattern.indptr.astype(float), pattern.indices.astype(float), values.ravel(), diagonals.ravel())


def scatter_source(n: int, m: int) -> str:
    """The C source of ``symcat_scatter_<n>_<m>`` (:func:`scatter`)."""
    return _SCATTER.format(name=f"symcat_scatter_{n}_{m}", n=n, m=m)


@lru_cache(maxsize=32)
def scatter(n: int, m: int) -> ca.Function:
    """``(index, v) -> y``: ``y`` (``n`` numbers) the sum of the ``m`` numbers ``v`` at their
    places ``index`` (numbers; -1 none), in their order.

    Why: as a product with a sparse 0/1 matrix (CasADi's form of a scatter-add) its constant
    data is two integers per entry and its ones are written at every call; here one number per
    entry. The sums are the product's, in the same order."""
    return ca.external(f"symcat_scatter_{n}_{m}", str(_library(scatter_source(n, m))))
