"""Translate SymPy expression graphs into CasADi SX by a memoized walk.

Shared subexpressions stay shared (each distinct SymPy node becomes one SX node), and
piecewise constructs map to CasADi conditionals. Square roots are guarded: ``sqrt(x)`` becomes
``sqrt(fmax(x, SQRT_FLOOR))`` so that its derivative stays finite at zero (ANCF gradient norms
are never near zero in a valid state, but a Newton iterate may pass through one).
"""
from __future__ import annotations

import casadi as ca
import sympy as sp

SQRT_FLOOR = 1e-30


class SympyToCasadi:
    """Memoized converter for one set of symbol bindings.

    Parameters
    ----------
    bindings : dict
        Maps SymPy symbols to CasADi SX expressions.
    """

    def __init__(self, bindings: dict[sp.Symbol, ca.SX]):
        self.cache: dict[sp.Basic, ca.SX] = dict(bindings)

    def __call__(self, expr):
        if isinstance(expr, sp.MatrixBase):
            out = ca.SX(expr.rows, expr.cols)
            for i in range(expr.rows):
                for j in range(expr.cols):
                    out[i, j] = self(expr[i, j])
            return out
        return self._convert(sp.sympify(expr))

    def _convert(self, root: sp.Basic) -> ca.SX:
        # Iterative post-order walk over the DAG (each distinct node expanded once): deep
        # expressions must not hit Python's recursion limit, and shared subtrees must not be
        # walked once per path.
        cache = self.cache
        visited = set(cache)
        order = []
        stack = [(root, False)]
        while stack:
            node, ready = stack.pop()
            if ready:
                order.append(node)
                continue
            if node in visited:
                continue
            visited.add(node)
            stack.append((node, True))
            stack.extend((a, False) for a in _operands(node) if a not in visited)
        for node in order:
            cache[node] = self._apply(node)
        return cache[root]

    def _apply(self, node: sp.Basic) -> ca.SX:
        c = self.cache
        if node.is_Symbol:
            raise KeyError(f"unbound symbol {node} in the expression")
        if node.is_Number or node in (sp.pi, sp.E):
            return ca.SX(float(node))
        if isinstance(node, sp.Add):
            return _balanced(node.args, c, lambda x, y: x + y)
        if isinstance(node, sp.Mul):
            return _balanced(node.args, c, lambda x, y: x * y)
        if isinstance(node, sp.Pow):
            base, exp = node.args
            if exp == sp.Rational(1, 2):
                return ca.sqrt(ca.fmax(c[base], SQRT_FLOOR))
            if exp == -sp.Rational(1, 2):
                return 1 / ca.sqrt(ca.fmax(c[base], SQRT_FLOOR))
            if exp.is_Integer:
                return _integer_power(c[base], int(exp))
            if exp.is_Rational and exp.q == 2:
                root = ca.sqrt(ca.fmax(c[base], SQRT_FLOOR))
                return _integer_power(root, int(exp.p))
            return c[base] ** c[exp]
        if isinstance(node, sp.Piecewise):
            out = None
            for value, cond in reversed(node.args):
                if cond == sp.true:
                    out = c[value]
                elif out is None:
                    raise ValueError("Piecewise without a default branch")
                else:
                    out = ca.if_else(c[cond], c[value], out)
            return out
        if isinstance(node, sp.Heaviside):
            return ca.if_else(c[node.args[0]] > 0, 1, ca.if_else(c[node.args[0]] < 0, 0, 0.5))
        if isinstance(node, (sp.Max, sp.Min)):
            fn = ca.fmax if isinstance(node, sp.Max) else ca.fmin
            return _balanced(node.args, c, fn)
        if isinstance(node, sp.core.relational.Relational):
            lhs, rhs = c[node.lhs], c[node.rhs]
            return _RELATIONS[type(node)](lhs, rhs)
        if isinstance(node, (sp.And, sp.Or)):
            fn = ca.logic_and if isinstance(node, sp.And) else ca.logic_or
            return _balanced(node.args, c, fn)
        if isinstance(node, sp.Not):
            return ca.logic_not(c[node.args[0]])
        fn = _FUNCTIONS.get(type(node))
        if fn is not None:
            return fn(*[c[a] for a in node.args])
        raise NotImplementedError(f"no CasADi translation for {type(node).__name__}: {node}")


def _operands(node: sp.Basic):
    if isinstance(node, sp.Piecewise):
        return [x for pair in node.args for x in pair if x is not sp.true]
    if isinstance(node, sp.core.relational.Relational):
        return [node.lhs, node.rhs]
    if node.is_Atom:
        return []
    return list(node.args)


def _balanced(args, cache, op):
    terms = [cache[a] for a in args]
    while len(terms) > 1:  # pairwise: shallower graphs than a left fold
        terms = [op(terms[i], terms[i + 1]) if i + 1 < len(terms) else terms[i] for i in range(0, len(terms), 2)]
    return terms[0]


def _integer_power(x: ca.SX, n: int) -> ca.SX:
    if n == 0:
        return ca.SX(1.0)
    if n < 0:
        return 1 / _integer_power(x, -n)
    if n == 1:
        return x
    if n == 2:
        return x * x
    return ca.constpow(x, n)


_RELATIONS = {
    sp.StrictGreaterThan: lambda a, b: a > b,
    sp.GreaterThan: lambda a, b: a >= b,
    sp.StrictLessThan: lambda a, b: a < b,
    sp.LessThan: lambda a, b: a <= b,
    sp.Equality: lambda a, b: a == b,
    sp.Unequality: lambda a, b: a != b,
}

_FUNCTIONS = {
    sp.sin: ca.sin,
    sp.cos: ca.cos,
    sp.tan: ca.tan,
    sp.asin: ca.asin,
    sp.acos: ca.acos,
    sp.atan: ca.atan,
    sp.atan2: ca.atan2,
    sp.sinh: ca.sinh,
    sp.cosh: ca.cosh,
    sp.tanh: ca.tanh,
    sp.asinh: ca.asinh,
    sp.exp: ca.exp,
    sp.log: ca.log,
    sp.Abs: ca.fabs,
    sp.sign: ca.sign,
    sp.floor: ca.floor,
    sp.ceiling: ca.ceil,
}


def to_casadi(expr, bindings: dict[sp.Symbol, ca.SX]):
    """Convert one expression (or matrix) with a fresh memo table."""
    return SympyToCasadi(bindings)(expr)


def bind(symbols: sp.Matrix, values: ca.SX) -> dict[sp.Symbol, ca.SX]:
    """Pair a column of SymPy symbols with the entries of an SX column."""
    return {s: values[k] for k, s in enumerate(symbols)}
