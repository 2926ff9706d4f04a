"""The band factorization, band solve and dense product as C loops
(:mod:`symcat.codegen.band_c`): the numbers of a dense solve and product, and the sources a
generated file calls appended to it."""
from __future__ import annotations

import subprocess

import casadi as ca
import numpy as np
import pytest

from symcat.codegen.band_c import band_functions, include_in, matvec
from symcat.codegen.library import find_compiler


@pytest.mark.parametrize("n, bw", [(1, 0), (7, 2), (40, 5)])
def test_band_lu_and_solve_are_a_dense_solve(n, bw):
    rng = np.random.default_rng(n)
    a = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - bw), min(n, i + bw + 1)):
            a[i, j] = rng.normal()
        a[i, i] += 4.0 * (bw + 1)  # no pivoting needed
    w = 2 * bw + 1
    band = np.zeros(n * w)
    for i in range(n):
        for j in range(max(0, i - bw), min(n, i + bw + 1)):
            band[i * w + j - i + bw] = a[i, j]
    lu, solve = band_functions(n, bw)
    factors = np.asarray(lu(band)).ravel()
    b = rng.normal(size=n)
    x = np.asarray(solve(factors, b)).ravel()
    assert np.allclose(a @ x, b, rtol=0, atol=1e-12 * np.abs(b).max())
    # L unit lower and U: their product is the matrix
    low, up = np.eye(n), np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - bw), min(n, i + bw + 1)):
            (low if j < i else up)[i, j] = factors[i * w + j - i + bw]
    assert np.allclose(low @ up, a, atol=1e-12)


def test_matvec_is_the_product_and_maps_over_columns():
    rng = np.random.default_rng(0)
    a, x = rng.normal(size=(11, 30)), rng.normal(size=(30, 4))
    f = matvec(11, 30)
    assert np.allclose(np.asarray(f(a.ravel(order="F"), x[:, 0])).ravel(), a @ x[:, 0])
    mapped = np.asarray(f.map(4)(a.ravel(order="F"), x))
    assert np.allclose(mapped, a @ x)


def test_generated_code_that_calls_the_kernels_gets_their_source(tmp_path):
    lu, solve = band_functions(7, 2)
    prod = matvec(3, 4)
    band, rhs, m, v = ca.MX.sym("band", 35), ca.MX.sym("b", 7), ca.MX.sym("m", 12), ca.MX.sym("v", 4)
    fn = ca.Function("caller", [band, rhs, m, v], [solve(lu(band), rhs), prod(m, v)])
    path = tmp_path / "caller.c"
    gen = ca.CodeGenerator(str(path.name), {"with_header": False})
    gen.add(fn)
    import os

    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        gen.generate()
    finally:
        os.chdir(cwd)
    include_in(path)
    text = path.read_text()
    for name in ("symcat_band_lu_7_2", "symcat_band_solve_7_2", "symcat_matvec_3_4"):
        assert f"int {name}(const casadi_real** arg" in text  # defined, not only declared
    assert "symcat_matvec_3_5" not in text
    assert "void casadi_copy" not in text or "memmove(y, x, n * sizeof(casadi_real));" in text
    assert "return fmax(x, y);" not in text
    # and it compiles (CasADi's declarations and these definitions agree)
    done = subprocess.run([find_compiler(), "-c", str(path), "-o", str(tmp_path / "caller.o")], capture_output=True)
    assert done.returncode == 0, done.stderr.decode()
