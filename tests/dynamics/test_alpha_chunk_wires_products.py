"""The wires' constant products and scatters of the compiled line steps
(:func:`symcat.codegen.sparse_c.symv`, :func:`~symcat.codegen.sparse_c.scatter`, used by
:class:`symcat.integrate.alpha_chunk_wires.LoopedWires`): the products of symmetric matrices
from one pass over their common upper triangle are the sparse products to round-off; a matrix
that is not symmetric is not taken; the scatter-add is NumPy's, in the same order."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sps

from symcat.codegen.sparse_c import scatter, symmetric_pattern, symv


def _symmetric(n, density, rng):
    a = sps.random(n, n, density=density, random_state=rng)
    return (a + a.T + sps.diags(rng.random(n) + 1.0)).tocsr()


def test_one_pass_over_the_upper_triangle_is_the_sum_of_the_products():
    rng = np.random.default_rng(0)
    n = 50
    mats = [_symmetric(n, 0.05, rng), _symmetric(n, 0.2, rng), _symmetric(n, 0.1, rng)]
    mats[1] = mats[1] + 1e-14 * sps.triu(mats[1], 1)  # (symmetric to round-off: its symmetric part)
    pattern = symmetric_pattern(mats)
    assert pattern is not None
    x = rng.normal(size=(3, n))
    y = np.asarray(symv(n, pattern[1].size, 3)(*pattern, x.ravel())).ravel()
    expected = sum(0.5 * (m + m.T) @ xm for m, xm in zip(mats, x))
    assert np.abs(y - expected).max() <= 1e-13 * np.abs(expected).max()


def test_a_matrix_that_is_not_symmetric_is_not_taken():
    rng = np.random.default_rng(1)
    a = _symmetric(20, 0.2, rng).tolil()
    a[3, 7] += 1.0
    assert symmetric_pattern([_symmetric(20, 0.2, rng), a.tocsr()]) is None


def test_scatter_adds_in_order_and_leaves_out_minus_one():
    rng = np.random.default_rng(2)
    index = rng.integers(-1, 10, size=200)
    v = rng.normal(size=200)
    expected = np.zeros(10)
    for i, x in zip(index, v):  # (in order: the sums bit for bit)
        if i >= 0:
            expected[i] += x
    y = np.asarray(scatter(10, 200)(index.astype(float), v)).ravel()
    assert np.array_equal(y, expected)
