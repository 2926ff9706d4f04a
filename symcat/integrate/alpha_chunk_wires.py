"""The wires' rows of a compiled generalized-alpha step and their block of the iteration matrix
(:mod:`.alpha_chunk_residual`) as CasADi graphs whose generated code is loops over constant
data: its size does not grow with the wires' elements.

Why: expanded to scalar operations (what the compiled steps of a cable or a short wire use),
the wires' rows and Jacobian are straight-line code over every element; on a catenary line of
hundreds of elements that is tens of megabytes of C and minutes of compiler time. Here they are
built from the pieces the Python steps evaluate (:class:`.alpha_bulk.Bulk`):

- the constant mass and Rayleigh matrices (and the stiffness of linearized wires), symmetric,
  multiplied in one pass over their common upper triangle (:func:`~symcat.codegen.sparse_c.symv`:
  half the entries, one index for all of them; a Newton iteration's largest cost after the
  band's solve); a matrix that is not symmetric as a CasADi sparse product;
- the element forces and stiffness, and the force elements between nodes (droppers, supports)
  with their derivatives, as the kernels' SX functions mapped over the elements (a serial map:
  a loop calling the kernel's code once per element);
- gathered from the unknowns and scattered into the rows and the Jacobian's nonzeros with
  constant index arrays (:func:`~symcat.codegen.sparse_c.scatter`: a sparse 0/1 matrix would be
  two integers of constant data per entry, the Jacobian's hundreds of thousands).

The rows are those of :func:`.alpha_bulk.bulk_rows` and the Jacobian their derivative in the
bulk's pattern (``c_m M + gamma h D + beta h^2 K`` plus the force elements' terms): the same
numbers to round-off. The kernels must be the SX forms: build inside
:func:`symcat.codegen.library.symbolic_kernels`.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ..assembly.sparse import to_casadi_sparse, to_scipy
from ..codegen.sparse_c import scatter, symmetric_pattern, symv
from ..codegen.library import kernel_library
from ..scene.loads import SlopeMoment
from .alpha_bulk import step_data

#: Wire elements from which the compiled steps build the wires' part as loops
#: (:func:`looped`); below, expanded to scalar operations, which runs faster while its code
#: is small.
LOOPED_ELEMENTS = 64


def looped(model) -> bool:
    """Whether the compiled steps of ``model`` build its wires' part as loops (more than
    :data:`LOOPED_ELEMENTS` wire elements)."""
    return sum(es.n for es in model.ancf.element_sets) > LOOPED_ELEMENTS


def unloopable(form) -> str | None:
    """Why the wires of ``form`` cannot be built as loops, or None: wire coordinates that are
    combinations (Cholesky coordinates, not picked ones), slope moments (forces that depend
    on the coordinates outside the elements' kernels), or linearized wires whose forces are not
    affine (element damping: their elastic part is the linearization, not the kernels)."""
    model = form.model
    n_b = int(np.count_nonzero(model.free < model.ancf.n))
    p = to_scipy(form.P).tocsc()[:, :n_b]
    if not (np.all(np.diff(p.indptr) == 1) and np.all(p.data == 1.0)):
        return "wire coordinates that are combinations of the model's (not picked)"
    if any(isinstance(load, SlopeMoment) for load in model.scene.loads):
        return "slope moments on the wires"
    if model.scene.linear_wires and model.ancf.affine_forces() is None:
        return "linearized wires with element damping"
    return None


class _Gather:
    """The local coordinates of a set of kernel calls (``indices``: N x n_loc model
    coordinates, -1 none) from the wires' unknowns: each local entry a free unknown or a fixed
    coordinate's constant; and the scatter of local rows (or local matrices' entries) back to
    the free unknowns."""

    def __init__(self, indices: np.ndarray, y_of_q: np.ndarray, q_fixed: np.ndarray, n_b: int):
        indices = np.asarray(indices, np.int64)
        self.n, self.n_loc = indices.shape
        at = np.where(indices >= 0, y_of_q[np.maximum(indices, 0)], -1)
        self.free = at >= 0
        fixed = ~self.free
        values = np.where(indices >= 0, q_fixed[np.maximum(indices, 0)], 0.0)[fixed]
        constants, which = np.unique(values, return_inverse=True)
        # local entry -> place in [y_b, constants] (positions) and in [v_b, 0] (rates: fixed
        # coordinates do not move)
        q_from, v_from = at.copy(), at.copy()
        q_from[fixed], v_from[fixed] = n_b + which, n_b
        # column-major over (local, call): as the kernels' map takes them (n_loc x N)
        self._q_from, self._v_from = q_from.ravel().tolist(), v_from.ravel().tolist()
        self._constants = ca.DM(constants)
        self.at = at

    def positions(self, y_b: ca.MX) -> ca.MX:
        return ca.reshape(ca.vertcat(y_b, self._constants)[self._q_from], self.n_loc, self.n)

    def rates(self, v_b: ca.MX) -> ca.MX:
        return ca.reshape(ca.vertcat(v_b, 0)[self._v_from], self.n_loc, self.n)

    def vector_index(self) -> np.ndarray:
        """The unknown each local row adds to (stacked call after call; -1 none), as numbers."""
        return self.at.ravel().astype(float)

    def matrix_index(self, position_of) -> np.ndarray:
        """The Jacobian's nonzero each local matrix entry adds to (each call's ``n_loc x n_loc``
        column-major, call after call; ``position_of(rows, cols)``: places in its pattern; -1
        none), as numbers."""
        n, m = self.n, self.n_loc
        i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")  # local row, column
        src = (np.arange(n)[:, None, None] * m * m + j[None] * m + i[None]).ravel()
        rows, cols = self.at[:, i].ravel(), self.at[:, j].ravel()
        keep = (rows >= 0) & (cols >= 0)
        index = np.full(n * m * m, -1.0)
        index[src[keep]] = position_of(rows[keep], cols[keep])
        return index


class _Pattern:
    """Places of ``(row, col)`` entries among the nonzeros of a CasADi sparsity (CCS order)."""

    def __init__(self, sparsity: ca.Sparsity):
        colind, row = sparsity.get_ccs()
        self.n_rows, self.nnz = sparsity.size1(), sparsity.nnz()
        cols = np.repeat(np.arange(sparsity.size2()), np.diff(colind))
        self._keys = np.asarray(row, np.int64) + self.n_rows * cols.astype(np.int64)

    def __call__(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        keys = np.asarray(rows, np.int64) + self.n_rows * np.asarray(cols, np.int64)
        pos = np.minimum(np.searchsorted(self._keys, keys), self.nnz - 1)
        if keys.size and not np.array_equal(self._keys[pos], keys):
            raise ValueError("an entry of the wires' Jacobian outside the bulk's pattern")
        return pos

    def values(self, matrix: sps.spmatrix) -> np.ndarray:
        """``matrix``'s entries at the pattern's nonzeros (a dense vector of :attr:`nnz`)."""
        m = sps.coo_matrix(matrix)
        out = np.zeros(self.nnz)
        np.add.at(out, self(m.row, m.col), m.data)
        return out


class LoopedWires:
    """The wires' rows ``(y_b, p, shift_b) -> rows`` and Jacobian ``(y_b, p, shift_b) -> d rows
    / d y_b`` (in the pattern of ``st.bulk``'s Jacobian) of the step equations ``st`` (a
    :class:`~.alpha_step.StepEquations`), as MX functions of loops (see the module's notes)."""

    def __init__(self, st):
        form, bulk = st.form, st.bulk
        why = unloopable(form)
        if why is not None:
            raise ValueError(f"the wires cannot be built as loops: {why}")
        model, system = form.model, form.model.ancf
        n_b = self.n_b = bulk.n_b
        self.n_u = st.n_u
        n_a = system.n
        picked = to_scipy(form.P).tocsc()[:, :n_b].indices
        y_of_q = np.full(model.n_q, -1)
        y_of_q[picked] = np.arange(n_b)
        q_fixed = np.array(form.q_fixed, float).ravel()
        pattern = bulk.jacobian.sparsity()
        where = _Pattern(pattern)
        self._mass = to_casadi_sparse(bulk.mass_matrix)
        self._rayleigh = to_casadi_sparse(bulk.rayleigh) if bulk.rayleigh.nnz else None
        # constants of the Jacobian's nonzeros: c_m M + gamma h D (+ beta h^2 K, linear wires)
        self._m_nz, self._d_nz = ca.DM(where.values(bulk.mass_matrix)), ca.DM(where.values(bulk.rayleigh))
        affine = system.affine_forces()
        if affine is not None:  # linearized wires: f = f0 - K (q - q0), the element kernels unused
            f_ref, k_ref, q_ref = affine
            k_b = k_ref[picked][:, picked]
            self._constant = (f_ref - k_ref @ (q_fixed[:n_a] - q_ref))[picked]
            self._stiffness = to_casadi_sparse(k_b)
            self._k_nz = ca.DM(where.values(k_b))
        else:
            self._constant = system.external_force_value(q_fixed[:n_a])[picked]
            self._stiffness = self._k_nz = None
        # the kernel calls: (kind, kernel name, library, gather, parameters)
        self._calls = []
        if affine is None:
            for es in system.element_sets:
                kind = "damped element" if es.damped else "element"
                self._calls.append((kind, es.element.name, es.element.name,
                                    _Gather(es.indices, y_of_q, q_fixed, n_b), ca.DM(es.params.T)))
        for lib, group in model.force_groups.items():
            rows, params = np.array(group.rows), np.array(group.params)
            keep = rows.max(axis=1) < n_a  # between wire nodes or to the ground: the bulk's
            if keep.any():
                self._calls.append(("force", lib, lib, _Gather(rows[keep], y_of_q, q_fixed, n_b),
                                    ca.DM(params[keep].T)))
        # the scatters' places: of each local entry (call after call) in the rows, and of each
        # local matrix entry in the Jacobian's nonzeros (-1: none)
        self._f_index = np.concatenate([g.vector_index() for *_, g, _ in self._calls] or [np.zeros(0)])
        self._j_index = np.concatenate([g.matrix_index(where) for *_, g, _ in self._calls] or [np.zeros(0)])
        # the constant products: M (c_m e + beta h^2 b) + D beta h^2 v (+ K beta h^2 y, linear wires)
        constant = [bulk.mass_matrix] + ([bulk.rayleigh] if self._rayleigh is not None else []) + (
            [k_b] if affine is not None else [])
        self._symmetric = symmetric_pattern(constant)
        self.pattern = pattern

    def functions(self) -> tuple[ca.Function, ca.Function]:
        """``(rows, jacobian)``, each ``(y_b, p, shift_b) -> ...``."""
        n_b = self.n_b
        y_b, p, shift_b = ca.MX.sym("y_b", n_b), ca.MX.sym("p", 3 * self.n_u + 4), ca.MX.sym("shift_b", n_b)
        rows = ca.Function("alpha_chunk_bulk", [y_b, p, shift_b], [self.rows(y_b, p, shift_b)])
        jacobian = ca.Function("alpha_chunk_bulk_jacobian", [y_b, p, shift_b], [self.jacobian(y_b, p, shift_b)])
        return rows, jacobian

    def _state(self, y_b, p, shift_b):
        n_b = self.n_b
        u_pred, v_pred, b, t, bh2, gh, cm = step_data(p, self.n_u)
        e = y_b - u_pred[:n_b] - shift_b  # beta h^2 times the acceleration
        return e, v_pred[:n_b] + (gh / bh2) * e, b[:n_b], t, bh2, gh, cm

    def rows(self, y_b, p, shift_b) -> ca.MX:
        """``beta h^2 (M (c_m a + b) + D v - f)``, ``f`` the wires' forces but damping."""
        e, v_b, b, t, bh2, gh, cm = self._state(y_b, p, shift_b)
        f = ca.DM(self._constant)
        if self._symmetric is not None:  # one pass over the constant matrices' upper triangle
            x = [cm * e + bh2 * b] + ([bh2 * v_b] if self._rayleigh is not None else []) + (
                [bh2 * y_b] if self._stiffness is not None else [])  # (K y_b: -f's, times beta h^2)
            pointers, columns, values, diagonals = (ca.DM(a) for a in self._symmetric)
            r = symv(self.n_b, columns.numel(), len(x))(pointers, columns, values, diagonals, ca.vertcat(*x))
        else:
            r = ca.mtimes(self._mass, cm * e + bh2 * b)
            if self._rayleigh is not None:
                r = r + ca.mtimes(self._rayleigh, bh2 * v_b)
            if self._stiffness is not None:
                f = f - ca.mtimes(self._stiffness, y_b)
        local = []
        for kind, name, lib, gather, params in self._calls:
            kernels, q = kernel_library(lib), gather.positions(y_b)
            if kind == "force":
                out = kernels[name].map(gather.n)(q, gather.rates(v_b), t, params)
            else:
                out = kernels[f"{name}_force"].map(gather.n)(q, params)
                if kind == "damped element":
                    out = out + kernels[f"{name}_damping"].map(gather.n)(q, gather.rates(v_b), params)
            local.append(ca.vec(ca.densify(out)))
        if local:
            f = f + scatter(self.n_b, self._f_index.size)(ca.DM(self._f_index), ca.vertcat(*local))
        return r - bh2 * f

    def jacobian(self, y_b, p, shift_b) -> ca.MX:
        """``c_m M + gamma h D + beta h^2 K - (beta h^2 df/dq + gamma h df/dv)`` of the force
        elements and damped elements, as a sparse matrix of the bulk's pattern."""
        e, v_b, b, t, bh2, gh, cm = self._state(y_b, p, shift_b)
        nz = cm * self._m_nz + gh * self._d_nz
        if self._k_nz is not None:
            nz = nz + bh2 * self._k_nz
        local = []
        for kind, name, lib, gather, params in self._calls:
            kernels, q = kernel_library(lib), gather.positions(y_b)
            if kind == "force":
                jq, jv = _derivatives(kernels[name]).map(gather.n)(q, gather.rates(v_b), t, params)
                block = -(bh2 * jq + gh * jv)
            else:
                block = bh2 * kernels[f"{name}_stiffness"].map(gather.n)(q, params)
                if kind == "damped element":
                    d, c = kernels[f"{name}_damping_matrices"].map(gather.n)(q, gather.rates(v_b), params)
                    block = block + bh2 * d + gh * c
            local.append(ca.vec(ca.densify(block)))
        if local:
            nz = nz + scatter(self.pattern.nnz(), self._j_index.size)(ca.DM(self._j_index), ca.vertcat(*local))
        return ca.sparsity_cast(nz, self.pattern)


def _derivatives(kernel: ca.Function) -> ca.Function:
    """``(q, v, t, params) -> (df/dq, df/dv)`` of a force element's SX kernel (dense)."""
    q, v, t, params = kernel.sx_in()
    f = kernel(q, v, t, params)
    return ca.Function(f"{kernel.name()}_derivatives", [q, v, t, params],
                       [ca.densify(ca.jacobian(f, q)), ca.densify(ca.jacobian(f, v))])
