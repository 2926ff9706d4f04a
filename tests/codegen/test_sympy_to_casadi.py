import casadi as ca
import numpy as np
import pytest
import sympy as sp

from symcat.codegen.sympy_to_casadi import SQRT_FLOOR, to_casadi


def _function(expr, symbols):
    xs = [ca.SX.sym(str(s)) for s in symbols]
    return ca.Function("f", xs, [to_casadi(expr, dict(zip(symbols, xs)))])


def test_conditionals_match_sympy(rng):
    x, y = sp.symbols("x y", real=True)
    expr = sp.Piecewise((x**2, x > 1), (sp.Max(x, y) - sp.Min(x, 2 * y), x > -1), (sp.Heaviside(y) * sp.cos(x), True))
    f = _function(expr, [x, y])
    for a, b in rng.uniform(-3, 3, (50, 2)):
        assert float(f(a, b)) == pytest.approx(float(expr.subs({x: a, y: b})), rel=1e-14, abs=1e-14)


def test_functions_and_powers(rng):
    x, y = sp.symbols("x y", positive=True)
    expr = sp.sqrt(x) * x ** sp.Rational(3, 2) + sp.atan2(y, x) + sp.exp(-x) * sp.log(y) / x**3 + sp.asinh(y) * sp.tanh(x)
    f = _function(expr, [x, y])
    for a, b in rng.uniform(0.1, 3, (20, 2)):
        assert float(f(a, b)) == pytest.approx(float(expr.subs({x: a, y: b})), rel=1e-13)


def test_sqrt_is_guarded_at_zero():
    x = sp.Symbol("x", real=True)
    xs = ca.SX.sym("x")
    g = ca.Function("g", [xs], [ca.jacobian(to_casadi(sp.sqrt(x**2), {x: xs}), xs)])
    assert np.isfinite(float(g(0.0)))
    assert float(g(0.0)) == 0.0 or abs(float(g(0.0))) < 1 / np.sqrt(SQRT_FLOOR)


def test_shared_subexpressions_stay_shared():
    """A deep expression with heavy reuse converts to a graph linear in its distinct nodes."""
    x = sp.Symbol("x", real=True)
    expr = x
    for k in range(20):
        expr = sp.sin(expr) * sp.cos(expr) + expr  # as a tree, 3^20 leaves
    n_distinct = len(_distinct_nodes(expr))  # 81
    f = _function(expr, [x])
    n_instructions = f.n_instructions()
    assert n_instructions <= 4 * n_distinct
    value = 0.3
    for _ in range(20):
        value = np.sin(value) * np.cos(value) + value
    assert float(f(0.3)) == pytest.approx(value, rel=1e-12)


def _distinct_nodes(expr):
    seen, stack = set(), [expr]
    while stack:
        node = stack.pop()
        if node not in seen:
            seen.add(node)
            stack.extend(node.args)
    return seen
