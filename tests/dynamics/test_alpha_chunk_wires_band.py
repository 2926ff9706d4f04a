"""The envelope band kernels (:func:`symcat.codegen.band_c.envelope_functions`) and the bordered
band on them (:class:`symcat.integrate.bordered_band.BorderedBand`): the row-major band
kernels' numbers bit for bit on a band whose rows reach less than its width (as a wire's
matrix ordered by reverse Cuthill-McKee), a dense solve's to round-off, and a factor that
keeps only the envelope's entries."""
from __future__ import annotations

import numpy as np
import pytest

from symcat.codegen.band_c import band_functions, envelope_functions, envelope_size


def _enveloped(n, bw, rng, zeros=False):
    """A band matrix whose rows start at varying distances from the diagonal (symmetric
    pattern, values not), diagonally dominant; ``zeros``: some entries inside the envelope
    exact zeros."""
    a = np.zeros((n, n))
    reach = rng.integers(0, bw + 1, size=n)
    reach[rng.integers(0, n)] = bw  # (the band's width reached)
    for i in range(n):
        for j in range(max(0, i - reach[i]), i):
            a[i, j], a[j, i] = rng.normal(size=2)
    if zeros:
        a[rng.random((n, n)) < 0.2] = 0.0
    a[np.diag_indices(n)] = 4.0 * (bw + 1) + rng.random(n)
    return a


@pytest.mark.parametrize("n, bw, zeros", [(1, 0, False), (7, 2, False), (60, 9, False), (60, 9, True), (200, 26, True)])
def test_envelope_kernels_are_the_band_kernels_bit_for_bit(n, bw, zeros):
    rng = np.random.default_rng(n + bw)
    a = _enveloped(n, bw, rng, zeros)
    w = 2 * bw + 1
    rows_major, cols_major = np.zeros(n * w), np.zeros(n * w)
    for i in range(n):
        for j in range(max(0, i - bw), min(n, i + bw + 1)):
            rows_major[i * w + j - i + bw] = a[i, j]
            cols_major[j * w + i - j + bw] = a[i, j]
    lu, solve = band_functions(n, bw)
    env_lu, env_solve = envelope_functions(n, bw)
    factor, env_factor = np.asarray(lu(rows_major)).ravel(), np.asarray(env_lu(cols_major)).ravel()
    assert env_factor.size == envelope_size(n, bw)
    b = rng.normal(size=n)
    x, env_x = np.asarray(solve(factor, b)).ravel(), np.asarray(env_solve(env_factor, b)).ravel()
    assert np.array_equal(x, env_x)
    assert np.abs(a @ env_x - b).max() <= 1e-12 * np.abs(b).max()
    for i in range(n):  # the same L and U, where the envelope reaches; zeros outside it
        for j in range(max(0, i - bw), min(n, i + bw + 1)):
            assert env_factor[j * w + i - j + bw] == factor[i * w + j - i + bw]
