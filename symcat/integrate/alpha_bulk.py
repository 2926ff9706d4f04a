"""The window-independent part of a generalized-alpha step (:mod:`.alpha_step`): the wires'
("bulk") residual rows and Jacobian, their constant mass and Rayleigh matrices, and the
factorized bulk matrix with its cached columns."""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..assembly.banded import BandedCholesky
from ..assembly.sparse import to_scipy
from ..codegen.library import BufferedFunction, kernel_library
from ..dae.formulation import Formulation
from ..errors import SolverError

#: Cached columns ``A^-1 e_i`` kept at most (a contact touches a dozen or two at a time).
MAX_COLUMNS = 256


def step_data(p, n_u):
    """The pieces of the step's data ``p`` (see :class:`StepEquations`)."""
    return (p[:n_u], p[n_u : 2 * n_u], p[2 * n_u : 3 * n_u], p[3 * n_u], p[3 * n_u + 1], p[3 * n_u + 2],
            p[3 * n_u + 3])


def bulk_rows(form: Formulation, n_b: int, n_u: int, y_b, p, shift_b) -> ca.MX:
    """The bulk's rows of the scaled step residual (MX) at the bulk unknowns ``y_b``, step data
    ``p`` and stabilization shift ``shift_b``: what :meth:`Bulk.residual` evaluates."""
    model = form.model
    zero = ca.MX(form.n_f - n_b, 1)
    u_pred, v_pred, b, t, bh2, gh, cm = step_data(p, n_u)
    a_b = (y_b - u_pred[:n_b] - shift_b) / bh2
    q = form.q_fixed + ca.mtimes(form.P, ca.vertcat(y_b, zero))
    v = ca.mtimes(form.P, ca.vertcat(v_pred[:n_b] + gh * a_b, zero))
    m_all = ca.mtimes(form.P.T, ca.mtimes(model.mass_matrix(q, "bulk"), form.P))
    f_b = ca.mtimes(form.P.T, model.forces(q, v, t, "bulk"))[:n_b]
    return bh2 * (ca.mtimes(m_all[:n_b, :n_b], cm * a_b + b[:n_b]) - f_b)


class Bulk:
    """The window-independent part of the step: the bulk's residual rows and Jacobian as
    functions of ``(y_b, p, shift_b)`` (the free ANCF coordinates come first among the
    unknowns, ``n_b`` of them), the constant bulk mass and Rayleigh matrices, the mass matrix
    of the rest, and the factorized bulk matrix ``A = c_m M + gamma h D + beta h^2 K`` with its
    cached columns.

    Parameters
    ----------
    form : Formulation
    n_u : int
        Free coordinates and sliding-joint arc lengths (the layout of ``p``).
    expand : bool
        A few wire elements: the Jacobian as CasADi's derivative of the rows' graph in scalar
        operations (:class:`.alpha_bulk_jacobian.GraphJacobian`, the quickest to evaluate), the force elements'
        functions expanded too. Else the Jacobian is assembled in SciPy
        (:class:`.alpha_bulk_jacobian.AssembledJacobian`), with no graph over the line's coordinates to build.
    whole : bool
        Evaluate the residual as one expanded function of ``(y_b, p, shift_b)`` (the wires'
        element forces called as their compiled kernels) instead of in pieces (see
        :meth:`residual`): for a few wire elements, where the pieces' NumPy and SciPy calls
        cost more than the evaluation (the seed's 8-element wire: 23 instead of 70 us).
    """

    def __init__(self, form: Formulation, n_u: int, expand: bool = False, whole: bool = False):
        model = form.model
        self.n_b = n_b = int(np.count_nonzero(model.free < model.ancf.n))
        self.n_f, self.n_u = form.n_f, n_u
        self.lu = None
        self.bh2 = None
        self.factorizations = 0
        self._columns: dict[int, np.ndarray] = {}
        self._last = None  # (index bytes, columns) of the last call of columns()
        self._permutation = None
        q_f = ca.MX.sym("q", form.n_f)
        mass_rest = ca.mtimes(form.P.T, ca.mtimes(model.mass_matrix(form.q_fixed + ca.mtimes(form.P, q_f), "rest"),
                                                  form.P))
        self._mass_rest = ca.Function("alpha_mass_rest", [q_f], [mass_rest])
        self._forces = self.jacobian = None
        self._matrices = {}  # (beta h^2 or 0, gamma h, c_m) -> B of residual()
        self._step = None  # (p, (B, c)) of the last step data, see residual()
        self._whole = None  # the residual as one function, see ``whole``
        if not n_b:
            return
        y_b, shift_b = ca.MX.sym("y_b", n_b), ca.MX.sym("shift_b", n_b)
        p = ca.MX.sym("p", 3 * n_u + 4)
        # the rows' graph only where it is evaluated (few elements): on a line it takes a
        # fraction of a second to build, and the assembled pieces serve instead
        r_b = bulk_rows(form, n_b, n_u, y_b, p, shift_b) if whole or expand else None
        if whole:
            try:
                self._whole = BufferedFunction(ca.Function("alpha_bulk_residual", [y_b, p, shift_b],
                                                           [ca.densify(r_b)]).expand())
            except RuntimeError:
                pass
        self._forces = _BulkForces(form, n_b, expand)
        # the wires' constant matrices on their free coordinates, P_b^T X P_b in SciPy (the
        # bulk's mass is the ANCF block's)
        p_b = to_scipy(form.P)[: model.ancf.n, :n_b]
        self.mass_matrix = (p_b.T @ model.ancf.mass_matrix @ p_b).tocsc()
        c = model.ancf.rayleigh_matrix
        self.rayleigh = (p_b.T @ c @ p_b).tocsc() if c is not None else sps.csc_matrix((n_b, n_b))
        self._mass_csr, self._rayleigh_csr = self.mass_matrix.tocsr(), self.rayleigh.tocsr()
        from .alpha_bulk_jacobian import AssembledJacobian, GraphJacobian  # (it uses step_data)

        if expand:  # few elements: the graph's Jacobian in scalar operations, the quickest to evaluate
            try:
                fn = ca.Function("alpha_bulk_jacobian", [y_b, p, shift_b], [ca.jacobian(r_b, y_b)]).expand()
                self.jacobian = GraphJacobian(fn)
            except RuntimeError:
                pass
        if self.jacobian is None:
            self.jacobian = AssembledJacobian(self, form)

    def residual(self, y_b, p, shift_b) -> np.ndarray:
        """The bulk's rows of the scaled step residual at the bulk unknowns ``y_b``, step data
        ``p`` and stabilization shift ``shift_b``.

        With ``a = (y_b - u_pred - shift_b) / (beta h^2)`` and ``v = v_pred + gamma h a``, the
        residual is ``beta h^2 (M (c_m a + b) + D v - f)``. Linearized wires: ``B (y_b -
        shift_b) + c - beta h^2 f_n`` with ``B = c_m M + gamma h D + beta h^2 K``, ``c`` the
        rest of the affine part, both fixed over a step, and ``f_n`` the forces that are not
        affine: one sparse product per Newton iteration instead of three. Nonlinear wires: the
        mass and Rayleigh products as written (``B`` would have the Rayleigh matrix's denser
        pattern, and its two products per step cost more than these per iteration)."""
        if self._whole is not None:
            return self._whole.nonzeros(y_b, p, 0.0 if shift_b is None else shift_b)[0]
        n_b, n_u = self.n_b, self.n_u
        u_pred, v_pred, b, t, bh2, gh, cm = step_data(p, n_u)
        if self._forces.stiffness is None:
            e = y_b - u_pred[:n_b]
            if shift_b is not None:
                e -= shift_b
            r = self._mass_csr @ (cm * e + bh2 * b[:n_b])
            v_b = v_pred[:n_b] + (gh / bh2) * e
            if self.rayleigh.nnz:
                r += self._rayleigh_csr @ (bh2 * v_b)
            f = self._forces(y_b, v_b, t)
            if f is not None:
                r -= bh2 * f
            return r
        matrix, c = self._affine(p)
        a = (y_b - u_pred[:n_b] - shift_b) / bh2
        r = matrix @ y_b + c
        if shift_b is not None and np.any(shift_b):
            r -= self._matrix(p, linear=False) @ shift_b
        f = self._forces(y_b, v_pred[:n_b] + gh * a, t)
        if f is not None:
            r -= bh2 * f
        return r

    def _matrix(self, p, linear: bool = True):
        """``c_m M + gamma h D`` (with ``linear``: plus ``beta h^2 K`` of linearized wires) of
        the step data ``p``, cached for its coefficients."""
        bh2, gh, cm = (float(x) for x in p[3 * self.n_u + 1 : 3 * self.n_u + 4])
        key = (bh2 if linear and self._forces.stiffness is not None else 0.0, gh, cm)
        cache = self._matrices
        found = cache.get(key)
        if found is None:
            if len(cache) > 8:  # step sizes of halvings and restarts: keep a few
                cache.clear()
            found = cm * self.mass_matrix + gh * self.rayleigh
            if key[0]:
                found = found + bh2 * self._forces.stiffness
            found = cache[key] = found.tocsr()
        return found

    def _affine(self, p):
        """``B`` and ``c`` of :meth:`residual` for the step data ``p`` (cached for the last
        ``p``: the Newton iterations of a step share it)."""
        if self._step is not None and np.array_equal(self._step[0], p):
            return self._step[1]
        n_b = self.n_b
        u_pred, v_pred, b, t, bh2, gh, cm = step_data(p, self.n_u)
        matrix = self._matrix(p)
        c = self._mass_csr @ (bh2 * b[:n_b] - cm * u_pred[:n_b]) + self._rayleigh_csr @ (bh2 * v_pred[:n_b]
                                                                                      - gh * u_pred[:n_b])
        if self._forces.stiffness is not None:
            c -= bh2 * self._forces.constant
        self._step = (p.copy(), (matrix, c))
        return matrix, c

    def mass(self, q_f: np.ndarray) -> sps.csc_matrix:
        """The mass matrix on the free coordinates at ``q_f``."""
        m = to_scipy(self._mass_rest(q_f))
        if self.n_b:
            m = m + sps.block_diag([self.mass_matrix, sps.csc_matrix((self.n_f - self.n_b,) * 2)], format="csc")
        return m.tocsc()

    def set(self, y, p, shift) -> None:
        """Factorize ``A`` at ``(y, p)`` (``shift``: the stabilization's shift of the step)."""
        self._columns.clear()
        self._last = None
        self.bh2 = float(p[3 * self.n_u + 1])
        self.factorizations += 1
        if not self.n_b:
            self.lu = True
            return
        a = self.jacobian.matrix(y[: self.n_b], p, shift[: self.n_b])
        try:
            asymmetry = abs(a - a.T).max() if a.nnz else 0.0
            if asymmetry <= 1e-12 * abs(a).max():
                # A catenary's matrix is a narrow band after reordering: a banded Cholesky solves
                # several times faster than SuperLU's LU (which it falls back to when not SPD)
                self.lu = BandedCholesky(a, self._permutation)
                self._permutation = self.lu.permutation  # same pattern at every refactorization
            else:
                self.lu = spla.splu(a.tocsc())
        except RuntimeError:
            raise SolverError("generalized-alpha: singular iteration matrix of the wires (an ANCF coordinate "
                              "without mass or stiffness?)") from None

    def valid_for(self, bh2: float) -> bool:
        return self.lu is not None and self.bh2 == bh2

    def solve(self, r: np.ndarray) -> np.ndarray:
        return self.lu.solve(r) if self.n_b else r

    def columns(self, index: np.ndarray) -> np.ndarray:
        """``A^-1 e_i`` for each ``i`` of ``index`` (n_b x len(index), not to be written to).
        The matrix of the last ``index`` is kept: a contact stays on one element for many
        steps, and gathering the columns again cost as much as the rest's Jacobian."""
        key = index.tobytes()
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        out = np.empty((self.n_b, index.size))
        missing = [i for i in index.tolist() if i not in self._columns]
        if missing:
            if len(self._columns) + len(missing) > MAX_COLUMNS:
                self._columns.clear()
                missing = index.tolist()
            if isinstance(self.lu, BandedCholesky):
                solved = self.lu.columns(np.array(missing))
            else:
                e = np.zeros((self.n_b, len(missing)))
                e[missing, np.arange(len(missing))] = 1.0
                solved = self.lu.solve(e)
            for i, col in zip(missing, solved.T):
                self._columns[i] = col
        for k, i in enumerate(index.tolist()):
            out[:, k] = self._columns[i]
        self._last = (key, out)
        return out


class _BulkForces:
    """The bulk's forces ``f(y_b, v_b, t)`` (no Rayleigh term, free coordinates): the ANCF
    element forces as one function of the wire coordinates and each group of bulk force
    elements (droppers, supports) as one of the coordinates it acts on, gathered, scattered
    and mapped to the free coordinates in NumPy. One CasADi graph of it all held a work vector
    of every coordinate per operation, and on a line evaluated some 40 % slower in the step.

    Linearized wires' forces are affine, ``constant - stiffness y_b`` (free coordinates):
    :class:`Bulk` folds them into its step matrix, and a call leaves them out."""

    def __init__(self, form: Formulation, n_b: int, expand: bool):
        model = form.model
        self._n_q, self._n_a = model.n_q, model.ancf.n
        p = to_scipy(form.P).tocsc()[:, :n_b]
        self._to_q, self._to_free = p.tocsr(), p.T.tocsr()
        # Without Cholesky coordinates P picks coordinates: indexing, not two sparse products
        # of the line's size per evaluation.
        picks = np.all(np.diff(p.indptr) == 1) and np.all(p.data == 1.0)
        self._picked = p.indices.copy() if picks else None
        self._q_fixed = np.array(form.q_fixed, float).ravel()
        system = model.ancf
        # Linearized wires: one SciPy product (CasADi's sparse product in its virtual machine
        # took five times as long), folded into the step matrix.
        linear = system.affine_forces()
        self.stiffness = self.constant = None
        if linear is None:
            # evaluated in NumPy (the mapped element kernels, scattered): as fast as the
            # graph's call, without building the graph of the line
            self._ancf = lambda q_a, v_a: system.eval_internal_force(q_a, v_a) + system.external_force_value(q_a)
        else:
            f_ref, k_ref, q_ref = linear
            to_q = self._to_q[: self._n_a]
            self.stiffness = (self._to_free[:, : self._n_a] @ k_ref @ to_q).tocsr()
            self.constant = self._to_free[:, : self._n_a] @ (f_ref - k_ref @ (self._q_fixed[: self._n_a] - q_ref))
        self._groups = []
        for lib, group in model.force_groups.items():
            rows, params = np.array(group.rows), np.array(group.params)
            keep = rows.max(axis=1) < self._n_a
            rows, params = rows[keep], params[keep]
            if not len(rows):
                continue
            q_g, v_g, t = ca.MX.sym("q", rows.size), ca.MX.sym("v", rows.size), ca.MX.sym("t")
            shape = (rows.shape[1], rows.shape[0])
            out = kernel_library(lib)[lib].map(len(rows))(ca.reshape(q_g, *shape), ca.reshape(v_g, *shape), t,
                                                          ca.DM(params.T))
            fn = ca.Function(f"alpha_bulk_{lib}", [q_g, v_g, t], [ca.densify(ca.vec(out))])
            flat = rows.ravel()
            self._groups.append((BufferedFunction(_expanded(fn, expand)), flat))
        if self._picked is not None:
            # a group's coordinates straight from y_b (free ones) and q_fixed: no vector of all
            y_of_q = np.full(self._n_q, -1)
            y_of_q[self._picked] = np.arange(n_b)
            self._gathers = []
            for fn, flat in self._groups:
                at = y_of_q[flat]
                free = at >= 0
                fixed = self._q_fixed[flat] * ~free
                self._gathers.append((fn, np.where(free, at, 0), free, fixed, at[free]))
            # The picked coordinates are a few contiguous runs (a line's anchors and supports
            # are the gaps): copied as slices into kept buffers that hold the fixed values,
            # three times faster than indexing by the picks.
            breaks = np.flatnonzero(np.diff(self._picked) != 1) + 1
            starts, stops = np.r_[0, breaks], np.r_[breaks, n_b]
            self._runs = [(int(self._picked[a]), int(self._picked[a]) + int(b - a), int(a), int(b))
                          for a, b in zip(starts, stops)]
            self._q_buffer, self._v_buffer = self._q_fixed.copy(), np.zeros(self._n_q)

    def __call__(self, y_b: np.ndarray, v_b: np.ndarray, t: float) -> np.ndarray | None:
        """The forces at ``(y_b, v_b, t)`` but the linearized wires' affine ones (None: no
        others)."""
        picked = self._picked
        if self.stiffness is not None:
            if not self._groups:
                return None
            if picked is not None:
                f = np.zeros(y_b.size)
                for fn, at, free, fixed, to in self._gathers:
                    values = fn.nonzeros(fixed + np.where(free, y_b[at], 0.0), np.where(free, v_b[at], 0.0), t)[0]
                    f += np.bincount(to, values[free], minlength=y_b.size)
                return f
        if picked is not None:
            return self._picked_forces(y_b, v_b, t)
        q, v = self._q_fixed + self._to_q @ y_b, self._to_q @ v_b
        f = np.zeros(self._n_q)
        if self.stiffness is None:
            # (dense outputs: their nonzeros are the vector, no scatter into a new array)
            f[: self._n_a] = self._ancf(q[: self._n_a], v[: self._n_a])
        for fn, flat in self._groups:
            f += np.bincount(flat, fn.nonzeros(q[flat], v[flat], t)[0], minlength=self._n_q)
        return self._to_free @ f

    def _picked_forces(self, y_b: np.ndarray, v_b: np.ndarray, t: float) -> np.ndarray:
        """:meth:`__call__` of nonlinear wires whose free coordinates are picked (no Cholesky
        coordinates): the wires' forces on the buffers and on the free coordinates by runs,
        each group's added by its free entries."""
        q, v, q_fixed = self._q_buffer, self._v_buffer, self._q_fixed
        for qa, qb, ya, yb in self._runs:
            np.add(q_fixed[qa:qb], y_b[ya:yb], out=q[qa:qb])
            v[qa:qb] = v_b[ya:yb]
        f_wires = self._ancf(q[: self._n_a], v[: self._n_a])
        f = np.empty(y_b.size)
        for qa, qb, ya, yb in self._runs:
            f[ya:yb] = f_wires[qa:qb]
        for (fn, flat), (_, _, free, _, to) in zip(self._groups, self._gathers):
            f += np.bincount(to, fn.nonzeros(q[flat], v[flat], t)[0][free], minlength=y_b.size)
        return f


def _expanded(fn: ca.Function, expand: bool) -> ca.Function:
    """``fn`` expanded to scalar operations if asked and its graph allows it."""
    if expand:
        try:
            return fn.expand()
        except RuntimeError:
            pass
    return fn
