"""The band factorization, band solve, dense product and store as C loops
(:mod:`symcat.codegen.band_c`): the numbers of a dense solve and product, the sources a
generated file calls appended to it, and a store that writes into its caller's memory."""
from __future__ import annotations

import subprocess

import casadi as ca
import numpy as np
import pytest

from symcat.codegen.band_c import band_functions, include_in, inputs_by_reference, matvec, store_function
from symcat.codegen.library import BufferedFunction, build_library, find_compiler


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


def _compiled(fn: ca.Function, tmp_path) -> str:
    """The library of ``fn``'s generated code with the kernels it calls."""
    import os

    path = tmp_path / f"{fn.name()}.c"
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        with inputs_by_reference():  # (CasADi reads the option when a function is added)
            gen = ca.CodeGenerator(str(path.name), {"with_header": False})
            gen.add(fn)
            gen.generate()
    finally:
        os.chdir(cwd)
    include_in(path)
    target = tmp_path / f"{fn.name()}.so"
    build_library(find_compiler(), ("-O1", "-fPIC", "-shared"), path, target)
    return str(target)


def test_a_store_writes_into_the_callers_buffer_and_orders_the_reads(tmp_path):
    """Compiled code reads a bound input where it is and a store writes into it: a read that
    takes the store's token sees the new values, one whose outputs the store takes sees the
    old, and after the call the caller's array holds what was stored (also with CasADi set to
    copy inputs of that size: the code is generated with them read in place)."""
    n = 12
    buffer, values, x = ca.MX.sym("buffer", n), ca.MX.sym("values", 2), ca.MX.sym("x", n)
    read = ca.Function("read", [buffer, x, ca.MX.sym("token")], [ca.dot(buffer, x)])
    before = read(buffer, x, 0)
    token = store_function(n, 3, 2)(buffer, values * before)  # after the read it follows from
    after = read(buffer, x, token)
    fn = ca.Function("stored", [buffer, values, x], [before, after])
    size = ca.GlobalOptions.getCopyElisionMinSize()
    ca.GlobalOptions.setCopyElisionMinSize(1000)
    try:
        stored = BufferedFunction(ca.external("stored", _compiled(fn, tmp_path)))
    finally:
        ca.GlobalOptions.setCopyElisionMinSize(size)
    memory = np.arange(1.0, n + 1)
    total = memory.sum()
    stored.bind({0: memory})
    old, new = (float(v[0]) for v in stored.outputs(memory, np.array([1.0, 2.0]), np.ones(n)))
    assert old == total
    assert memory.tolist() == [1.0, 2.0, 3.0, total, 2 * total] + list(np.arange(6.0, n + 1))
    assert new == memory.sum()
