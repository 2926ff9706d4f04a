"""The wires' ("bulk") step Jacobian of generalized-alpha (:class:`.alpha_bulk.Bulk`): from a
CasADi graph for a few elements (:class:`GraphJacobian`), else assembled in SciPy from the
element and force-element kernels (:class:`AssembledJacobian`), with no CasADi graph over a
line's coordinates to build."""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ..assembly.sparse import Congruence, PatternSum, ScatterPattern, to_scipy
from ..codegen.library import BufferedFunction, kernel_library
from ..dae.formulation import Formulation
from .alpha_bulk import step_data


class _Pattern:
    """The CSC pattern ``indptr, indices`` of a Jacobian of shape ``shape``."""

    indptr: np.ndarray
    indices: np.ndarray
    shape: tuple

    def sparsity(self) -> ca.Sparsity:
        """The pattern as CasADi's (for graphs that project onto it)."""
        return ca.Sparsity(self.shape[0], self.shape[1], self.indptr.tolist(), self.indices.tolist())


class GraphJacobian(_Pattern):
    """The bulk's step Jacobian from a CasADi function ``(y_b, p, shift_b) -> J`` (evaluated
    in place on NumPy memory: a call with NumPy arguments converts them to DM and back)."""

    def __init__(self, function: ca.Function):
        self._fn = BufferedFunction(function)
        colind, row = function.sparsity_out(0).get_ccs()
        self.indptr, self.indices = np.array(colind, np.int64), np.array(row, np.int64)
        self.shape = function.sparsity_out(0).shape

    def matrix(self, y_b, p, shift_b) -> sps.csc_matrix:
        """``J`` at ``(y_b, p, shift_b)`` (SciPy CSC on the pattern ``indptr, indices``)."""
        data = self._fn.nonzeros(y_b, p, shift_b)[0]
        return sps.csc_matrix((data, self.indices.copy(), self.indptr.copy()), shape=self.shape)


class AssembledJacobian(_Pattern):
    """The bulk's step Jacobian ``d r_b / d y_b = c_m M + gamma h D + P_b^T (beta h^2 K +
    gamma h C) P_b`` assembled in SciPy: ``M`` and ``D`` the constant mass and Rayleigh
    matrices on the free coordinates, ``K = -df/dq`` and ``C = -df/dv`` of the wires' element
    forces (:meth:`~symcat.assembly.system.System.eval_force_jacobians`) and of the bulk's force
    elements (each group's kernel differentiated per element and mapped), ``P_b`` the bulk's
    columns of the coordinate map. Every term keeps a fixed pattern (a factorization reuses
    its ordering), and nothing is a CasADi graph over the line's coordinates, whose
    construction took longer than a passage's static solve."""

    def __init__(self, bulk, form: Formulation):
        model = form.model
        n_b, n_a = bulk.n_b, model.ancf.n
        self.shape = (n_b, n_b)
        self._bulk, self._n_u = bulk, bulk.n_u
        self._system = model.ancf
        self._to_q = to_scipy(form.P).tocsc()[:, :n_b].tocsr()  # its rows are ANCF coordinates
        self._q_fixed = np.array(form.q_fixed, float).ravel()
        self._n_a = n_a
        groups = (_GroupJacobian(lib, group, n_a) for lib, group in model.force_groups.items())
        self._groups = [g for g in groups if g.n]
        k_sum, c_sum = self._system.force_jacobian_patterns(damping=True)
        self._damped = c_sum.nnz > 0
        patterns = [(k_sum.indptr, k_sum.indices)] + ([(c_sum.indptr, c_sum.indices)] if self._damped else [])
        for g in self._groups:
            patterns += [(pt.indptr, pt.indices) for pt in g.patterns]
        self._q_sum = PatternSum(patterns, (n_a, n_a))
        self._congruence = Congruence(self._to_q[:n_a], self._q_sum.indptr, self._q_sum.indices)
        m, d = bulk.mass_matrix.tocsc(), bulk.rayleigh.tocsc()
        m.sort_indices()
        d.sort_indices()
        self._m, self._d = m, d
        self._sum = PatternSum([(m.indptr, m.indices), (d.indptr, d.indices),
                                (self._congruence.indptr, self._congruence.indices)], self.shape)
        self.indptr, self.indices = self._sum.indptr, self._sum.indices

    def matrix(self, y_b, p, shift_b) -> sps.csc_matrix:
        """``J`` at ``(y_b, p, shift_b)`` (SciPy CSC on the pattern ``indptr, indices``)."""
        n_a = self._n_a
        u_pred, v_pred, _, t, bh2, gh, cm = step_data(p, self._n_u)
        n_b = self.shape[0]
        a = (y_b - u_pred[:n_b] - (0.0 if shift_b is None else shift_b)) / bh2
        q = self._q_fixed + self._to_q @ y_b
        v = self._to_q @ (v_pred[:n_b] + gh * a)
        k, c = self._system.eval_force_jacobians(q[:n_a], v[:n_a] if self._damped else None)
        terms = [bh2 * k.data] + ([gh * c.data] if self._damped else [])
        for g in self._groups:
            k_g, c_g = g.values(q, v, float(t))
            terms += [bh2 * k_g, gh * c_g]
        wires = self._congruence.data(self._q_sum.data(terms))
        return self._sum.csc([cm * self._m.data, gh * self._d.data, wires])


class _GroupJacobian:
    """``-df/dq`` and ``-df/dv`` of the force elements of one kernel group that act on the
    wires alone (droppers, supports), per element from the kernel's derivative, mapped, and
    scattered on the wires' coordinates (:class:`~symcat.assembly.sparse.ScatterPattern`)."""

    def __init__(self, lib: str, group, n_a: int):
        rows, params = np.array(group.rows), np.array(group.params, float)
        keep = rows.max(axis=1) < n_a
        rows, params = rows[keep], params[keep]
        self.n = len(rows)
        if not self.n:
            return
        kernel = kernel_library(lib)[lib]
        n_loc = rows.shape[1]
        q_e, v_e, t = ca.MX.sym("q", n_loc), ca.MX.sym("v", n_loc), ca.MX.sym("t")
        p_e = ca.MX.sym("p", kernel.sparsity_in(3).numel())
        f_e = kernel(q_e, v_e, t, p_e)
        derivative = ca.Function(f"{lib}_jacobians", [q_e, v_e, t, p_e], [-ca.jacobian(f_e, q_e), -ca.jacobian(f_e, v_e)])
        q_all, v_all = ca.MX.sym("q", n_loc, self.n), ca.MX.sym("v", n_loc, self.n)
        mapped = derivative.map(self.n)(q_all, v_all, t, ca.DM(params.T))
        self._fn = BufferedFunction(ca.Function(f"{lib}_group_jacobians", [q_all, v_all, t], list(mapped)))
        self._flat = rows.ravel()
        self.patterns = [ScatterPattern(rows, rows, (n_a, n_a), derivative.sparsity_out(k)) for k in range(2)]

    def values(self, q: np.ndarray, v: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
        """The nonzeros of ``-df/dq`` and ``-df/dv`` on their patterns at ``(q, v, t)``."""
        k, c = self._fn.outputs(q[self._flat], v[self._flat], t)
        return self.patterns[0].data(k), self.patterns[1].data(c)
