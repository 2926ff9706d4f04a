"""The equations of one generalized-alpha step and their modified Newton solve, for
:mod:`symcat.integrate.generalized_alpha` (whose module docstring explains the method, the
unknowns and the scaling).

The step's equations are split where the physics splits them. The *bulk* is the ANCF structure
(element forces, Rayleigh damping, constant mass, node-to-node and node-to-ground force
elements): on a line, thousands of unknowns with a banded matrix that changes little over a
run (geometric stiffening, slack droppers). The *rest* is everything that couples bodies to it
(rigid bodies, joints, sliding joints, penalty contacts, multipliers): few unknowns plus the
ANCF coordinates of the elements a contact can currently touch (its element window).

- The bulk's residual and Jacobian are CasADi functions built once per run (they do not depend
  on the windows); its matrix ``A`` is factorized once and kept (:class:`Bulk`).
- The rest's residual and exact Jacobian are one small function per element window, on the
  kernels' SX forms and expanded to scalar operations, of only the unknowns the rest depends on:
  rebuilt in a fraction of a second when a window moves, evaluated in well under a millisecond.
- The linear solve of each Newton iteration is ``A`` (identity elsewhere) corrected by the
  rest's exact Jacobian through a Woodbury (capacitance) update on the few unknowns it touches,
  with the columns ``A^-1 e_i`` of those unknowns cached while the contact stays on an element.

This is how dedicated pantograph/catenary codes keep a constant iteration matrix while the
contact point moves; refactorizing a 7,000-unknown line whenever the contact crosses an element,
or differentiating the whole graph, costs more than the rest of the step many times over.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..assembly.banded import BandedCholesky
from ..codegen.library import BufferedFunction, symbolic_kernels
from ..dae.formulation import Formulation
from ..errors import SolverError

#: A Newton iteration that contracts by less than this per iteration updates its matrix.
SLOW_CONTRACTION = 0.3
#: Cached columns ``A^-1 e_i`` kept at most (a contact touches a dozen or two at a time).
MAX_COLUMNS = 256

_SINGULAR = ("generalized-alpha: singular iteration matrix (redundant constraints, or a sliding joint at a point "
             "where its wire has no tangent?)")


def _data(p, n_u):
    """The pieces of the step's data ``p`` (see :class:`StepEquations`)."""
    return (p[:n_u], p[n_u : 2 * n_u], p[2 * n_u : 3 * n_u], p[3 * n_u], p[3 * n_u + 1], p[3 * n_u + 2],
            p[3 * n_u + 3])


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
        Expand the bulk's functions to SX when the graph allows it.
    """

    def __init__(self, form: Formulation, n_u: int, expand: bool = False):
        model = form.model
        self.n_b = n_b = int(np.count_nonzero(model.free < model.ancf.n))
        self.n_f, self.n_u = form.n_f, n_u
        self.lu = None
        self.bh2 = None
        self.factorizations = 0
        self._columns: dict[int, np.ndarray] = {}
        self._permutation = None
        q_f = ca.MX.sym("q", form.n_f)
        mass_rest = ca.mtimes(form.P.T, ca.mtimes(model.mass_matrix(form.q_fixed + ca.mtimes(form.P, q_f), "rest"),
                                                  form.P))
        self._mass_rest = ca.Function("alpha_mass_rest", [q_f], [mass_rest])
        self._forces = self.jacobian = None
        if not n_b:
            return
        zero = ca.MX(form.n_f - n_b, 1)
        y_b, shift_b = ca.MX.sym("y_b", n_b), ca.MX.sym("shift_b", n_b)
        p = ca.MX.sym("p", 3 * n_u + 4)
        u_pred, v_pred, b, t, bh2, gh, cm = _data(p, n_u)
        a_b = (y_b - u_pred[:n_b] - shift_b) / bh2
        q = form.q_fixed + ca.mtimes(form.P, ca.vertcat(y_b, zero))
        v = ca.mtimes(form.P, ca.vertcat(v_pred[:n_b] + gh * a_b, zero))
        m_all = ca.mtimes(form.P.T, ca.mtimes(model.mass_matrix(q, "bulk"), form.P))
        f_b = ca.mtimes(form.P.T, model.forces(q, v, t, "bulk"))[:n_b]
        r_b = bh2 * (ca.mtimes(m_all[:n_b, :n_b], cm * a_b + b[:n_b]) - f_b)
        # The residual's constant-matrix terms (mass, Rayleigh) are SciPy products below; CasADi
        # evaluates the nonlinear forces only.
        v_b, t_s = ca.MX.sym("v_b", n_b), ca.MX.sym("t")
        f_nl = ca.mtimes(form.P.T, model.forces(q, ca.mtimes(form.P, ca.vertcat(v_b, zero)), t_s, "bulk",
                                                rayleigh=False))[:n_b]
        fns = [ca.Function("alpha_bulk_forces", [y_b, v_b, t_s], [ca.densify(f_nl)]),
               ca.Function("alpha_bulk_jacobian", [y_b, p, shift_b], [ca.jacobian(r_b, y_b)])]
        if expand:
            try:
                fns = [fn.expand() for fn in fns]
            except RuntimeError:
                pass
        # Evaluated in place on NumPy memory: a call with NumPy arguments converts them to DM
        # and back, which on a line of 7,000 unknowns costs more than the evaluation itself.
        self._forces, self.jacobian = (BufferedFunction(fn) for fn in fns)
        m_const = ca.evalf(ca.mtimes(form.P.T, ca.mtimes(model.mass_matrix(ca.MX.zeros(model.n_q), "bulk"), form.P)))
        self.mass_matrix = _csc(m_const)[:n_b, :n_b]
        c = model.ancf.rayleigh_matrix
        self.rayleigh = (_csc(ca.evalf(ca.mtimes(form.P.T, ca.mtimes(model._rayleigh_dm(), form.P))))[:n_b, :n_b]
                         if c is not None else sps.csc_matrix((n_b, n_b)))
        self._mass_csr, self._rayleigh_csr = self.mass_matrix.tocsr(), self.rayleigh.tocsr()

    def residual(self, y_b, p, shift_b) -> np.ndarray:
        """The bulk's rows of the scaled step residual at the bulk unknowns ``y_b``, step data
        ``p`` and stabilization shift ``shift_b``."""
        n_b, n_u = self.n_b, self.n_u
        u_pred, v_pred, b, t, bh2, gh, cm = _data(p, n_u)
        a = (y_b - u_pred[:n_b] - shift_b) / bh2
        v = v_pred[:n_b] + gh * a
        f = self._forces.nonzeros(y_b, v, t)[0]
        return bh2 * (self._mass_csr @ (cm * a + b[:n_b]) + self._rayleigh_csr @ v - f)

    def mass(self, q_f: np.ndarray) -> sps.csc_matrix:
        """The mass matrix on the free coordinates at ``q_f``."""
        m = _csc(self._mass_rest(q_f))
        if self.n_b:
            m = m + sps.block_diag([self.mass_matrix, sps.csc_matrix((self.n_f - self.n_b,) * 2)], format="csc")
        return m.tocsc()

    def set(self, y, p, shift) -> None:
        """Factorize ``A`` at ``(y, p)`` (``shift``: the stabilization's shift of the step)."""
        self._columns.clear()
        self.bh2 = float(p[3 * self.n_u + 1])
        self.factorizations += 1
        if not self.n_b:
            self.lu = True
            return
        a = self.jacobian.sparse(y[: self.n_b], p, shift[: self.n_b])[0]
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
        """``A^-1 e_i`` for each ``i`` of ``index`` (n_b x len(index))."""
        out = np.empty((self.n_b, index.size))
        missing = [i for i in index.tolist() if i not in self._columns]
        if missing:
            if len(self._columns) + len(missing) > MAX_COLUMNS:
                self._columns.clear()
                missing = index.tolist()
            e = np.zeros((self.n_b, len(missing)))
            e[missing, np.arange(len(missing))] = 1.0
            for i, col in zip(missing, self.lu.solve(e).T):
                self._columns[i] = col
        for k, i in enumerate(index.tolist()):
            out[:, k] = self._columns[i]
        return out


class StepEquations:
    """The step equations of one element window: the rest's residual and exact Jacobian (one
    expanded function), with the window-independent :class:`Bulk` (carried over from the
    previous window's equations) and the split linear solve of the modified Newton iteration.

    ``y = [u, beta h^2 lambda (, nu), s_c]`` and the rows ``[dynamics, C_s^T lambda, C (, velocity
    constraints), T]``: the arc lengths ``s_c`` of the penalty contacts are algebraic unknowns of
    the step with their tangency rows ``T(q, s_c) = 0`` (no multiplier; their normal forces are
    in ``Q``). ``p = [u_pred, v_pred, b, t_{n+1}, beta h^2, gamma h, (1 - alpha_m)/(1 - alpha_f)]``
    with ``u_pred = u_n + h v_n + h^2 (1/2 - beta) a_n``, ``v_pred = v_n + h (1 - gamma) a_n`` and
    ``b = (alpha_m a_n - alpha_f v_dot_n) / (1 - alpha_f)``."""

    def __init__(self, form: Formulation, variant: str, expand: bool = False, bulk: Bulk | None = None,
                 mass_scale: float | None = None, proxies: bool = True):
        n_f, n_s, n_c, n_sc = form.n_f, form.n_s, form.n_c, form.n_sc
        self.n_u, self.n_c, self.n_s, self.n_sc = n_f + n_s, n_c, n_s, n_sc
        n_u = self.n_u
        self.n_y = n_y = n_u + n_c * (2 if variant == "stabilized" else 1) + n_sc
        self.variant, self.form = variant, form
        self.bulk = bulk if bulk is not None else Bulk(form, n_u, expand)
        y = ca.MX.sym("y", n_y)
        p = ca.MX.sym("p", 3 * n_u + 4)
        self.proxies = _Proxies.choose(self, y, p) if proxies else None
        model = form.model
        saved = [sl.window for sl in model.windowed()]
        w = ca.MX.sym("w", 0 if self.proxies is None else 2 * len(self.proxies.items))
        try:
            if self.proxies is not None:
                self.proxies.install(w)
            # The rest depends on few unknowns: entered as a structurally sparse y, its graph and
            # Jacobian never touch the other thousands.
            pattern = ca.Function("alpha_rest", [y, p, w], [self._rows(y, p)[0]]).sparsity_jac(0, 0)
            self.rest_columns = np.unique(np.array(pattern.get_col(), int))
            k = self.rest_columns.size
            y_rest = ca.MX.sym("y_rest", k)
            y_sparse = ca.MX(ca.Sparsity.triplet(n_y, 1, self.rest_columns.tolist(), [0] * k), y_rest)
            # Built on the kernels' SX forms and expanded: as scalar operations the rest's
            # Jacobian evaluates some 30 times faster than through the MX graph.
            with symbolic_kernels():
                rest = ca.Function("alpha_rest", [y_rest, p, w], list(self._rows(y_sparse, p, contacts=True)))
        finally:
            model.element_override.clear()
            for sl, window in zip(model.windowed(), saved):
                sl.window = window
        try:
            rest = rest.expand()
            y_rest, p, w = rest.sx_in()
        except RuntimeError:  # a kernel without an SX form: the MX graph
            y_rest, p, w = rest.mx_in()
        r_rest = rest(y_rest, p, w)[0]
        self._rest = BufferedFunction(rest)
        # the outputs are sparse (most rows belong to the bulk): their nonzeros' places
        self._r_rows = np.array(rest.sparsity_out(0).row(), int)
        self._shift_rows = np.array(rest.sparsity_out(1).row(), int)
        jac = ca.Function("alpha_rest_jacobian", [y_rest, p, w], [ca.jacobian(r_rest, y_rest)])
        self._rest_jacobian = BufferedFunction(jac)
        colind, row = jac.sparsity_out(0).get_ccs()
        self._jac_rows = np.array(row, int)
        self._jac_cols = self.rest_columns[np.repeat(np.arange(k), np.diff(colind))]
        self.mass_scale = mass_scale  # kg: mean diagonal of M, converts multiplier updates to positions
        self._coupling = None

    def _rows(self, y, p, contacts: bool = False):
        """The rest's scaled residual rows and the stabilization's shift ``G^T nu`` at ``(y,
        p)``: the step residual without the bulk's mass and forces (with ``contacts``, also the
        penalty contacts' gaps and normal forces)."""
        form, variant = self.form, self.variant
        n_f, n_s, n_c, n_sc, n_u, n_y = form.n_f, self.n_s, self.n_c, self.n_sc, self.n_u, self.n_y
        u_pred, v_pred, b, t, bh2, gh, cm = _data(p, n_u)
        u, lam_s = y[:n_u], y[n_u : n_u + n_c]
        sc = y[n_y - n_sc :] if n_sc else None
        q, s = u[:n_f], u[n_f:]
        shift = ca.MX(n_u, 1)
        if variant == "stabilized":
            nu = y[n_u + n_c : n_u + 2 * n_c]
            # C_q and C_s depend on positions only: the velocities of this probe are immaterial.
            g = self._terms(form, q, ca.MX.zeros(n_f), s, ca.MX.zeros(n_s), t, sc)
            shift = ca.vertcat(ca.mtimes(g["Cq"].T, nu), ca.mtimes(g["Cs"].T, nu))
        a = (u - u_pred - shift) / bh2
        v = v_pred + gh * a
        v_dot = cm * a + b
        k = self._terms(form, q, v[:n_f], s, v[n_f:], t, sc)
        rows = [bh2 * (ca.mtimes(k["M"], v_dot[:n_f]) - k["Q"]) + ca.mtimes(k["Cq"].T, lam_s),
                ca.mtimes(k["Cs"].T, lam_s), k["C"]]
        if variant == "stabilized":
            rows.append(bh2 / gh * (ca.mtimes(k["Cq"], v[:n_f]) + ca.mtimes(k["Cs"], v[n_f:]) + k["Ct"]))
        rows.append(k["T"])
        if contacts:
            return ca.vertcat(*rows), shift, k["gap"], k["fc"]
        return ca.vertcat(*rows), shift

    @staticmethod
    def _terms(form, q, v, s, w, t, sc=None):
        k = form.terms(q, v, s, w, t, sc, part="rest")
        if form.n_s == 0:  # an empty s would leave Cs 0 x 0 against n_c rows
            return {**k, "Cs": ca.MX(form.n_c, 0)}
        return k

    # --- evaluation ---------------------------------------------------------------------------
    def _inputs(self, y, p):
        """The rest's inputs at ``(y, p)`` and the proxies' maps (None without proxies)."""
        if self.proxies is None:
            return y[self.rest_columns], p, np.zeros(0), None
        y2, p2, w, maps = self.proxies.substitute(y, p)
        return y2[self.rest_columns], p2, w, maps

    def _rest_values(self, y, p):
        """The rest's residual (n_y) and shift (n_u) at ``(y, p)``, dense."""
        y_rest, p_in, w, maps = self._inputs(y, p)
        r_nz, shift_nz, *_ = self._rest.nonzeros(y_rest, p_in, w)
        r, shift = np.zeros(self.n_y), np.zeros(self.n_u)
        r[self._r_rows] = r_nz
        shift[self._shift_rows] = shift_nz
        if maps is not None:
            _move_back(r, maps)
            _move_back(shift, maps)
        return r, shift

    def residual(self, y, p) -> np.ndarray:
        r, shift = self._rest_values(y, p)
        n_b = self.bulk.n_b
        if n_b:
            r[:n_b] += self.bulk.residual(y[:n_b], p, shift[:n_b])
        return r

    def contacts(self, u, v, sc, t) -> tuple[np.ndarray, np.ndarray]:
        """Gaps (m) and normal forces (N) of the penalty contacts at the state ``(u, v, sc)``
        and time ``t``: the rest at ``y = [u, 0, sc]`` with step data for which ``v`` is the
        velocity (``u_pred = u``, ``v_pred = v``)."""
        n_u = self.n_u
        y = np.zeros(self.n_y)
        y[:n_u] = u
        if self.n_sc:
            y[self.n_y - self.n_sc :] = sc
        p = np.r_[u, v, np.zeros(n_u), t, 1.0, 1.0, 1.0]
        y_rest, p_in, w, _ = self._inputs(y, p)
        _, _, gap, force = self._rest.nonzeros(y_rest, p_in, w)
        return gap, force

    def update(self, y, p) -> tuple:
        """``a``, ``v`` and ``v_dot`` at the end of the step whose unknowns are ``y``."""
        shift = self._rest_values(y, p)[1]
        u_pred, v_pred, b, _, bh2, gh, cm = _data(p, self.n_u)
        a = (y[: self.n_u] - u_pred - shift) / bh2
        return a, v_pred + gh * a, cm * a + b

    def mass(self, y) -> sps.csc_matrix:
        """The mass matrix (free coordinates, scipy sparse) at the positions of ``y``."""
        return self.bulk.mass(y[: self.form.n_f])

    def _rest_triplets(self, y, p):
        """The rest's exact Jacobian as (rows, columns, values), nonzero values only, with the
        bulk rows' dependence on ``nu`` through the shift of ``a`` under the stabilized form:
        ``-(c_m M + gamma h C) G^T`` with the constant bulk mass and Rayleigh matrices."""
        y_rest, p_in, w, maps = self._inputs(y, p)
        values = self._rest_jacobian.nonzeros(y_rest, p_in, w)[0]
        keep = values != 0
        rows, cols, data = self._jac_rows[keep], self._jac_cols[keep], values[keep]
        if maps is not None:  # the proxies' rows and columns are those of the actual elements
            to = np.arange(self.n_y)
            for proxy, actual in maps:
                to[proxy] = actual
            rows, cols = to[rows], to[cols]
            keep = (rows >= 0) & (cols >= 0)
            rows, cols, data = rows[keep], cols[keep], data[keep]
        n_b, n_u, n_c = self.bulk.n_b, self.n_u, self.n_c
        if self.variant == "stabilized" and n_b:
            g = (rows >= n_u) & (rows < n_u + n_c) & (cols < n_b)  # G on the bulk coordinates
            if np.any(g):
                _, _, _, _, _, gh, cm = _data(p, n_u)
                g_cols, at = np.unique(cols[g], return_inverse=True)
                g_b = np.zeros((g_cols.size, n_c))  # G^T on the bulk columns it touches
                np.add.at(g_b, (at, rows[g] - n_u), data[g])
                block = cm * self.bulk.mass_matrix[:, g_cols] + gh * self.bulk.rayleigh[:, g_cols]
                extra = (-(block @ sps.csr_matrix(g_b))).tocoo()
                rows = np.r_[rows, extra.row]
                cols = np.r_[cols, n_u + n_c + extra.col]
                data = np.r_[data, extra.data]
        return rows, cols, data

    def jacobian(self, y, p) -> sps.csc_matrix:
        """The whole step Jacobian at ``(y, p)`` (bulk and rest; the starting acceleration's
        filter needs it once)."""
        rows, cols, data = self._rest_triplets(y, p)
        jac = sps.csc_matrix((data, (rows, cols)), shape=(self.n_y, self.n_y))
        n_b = self.bulk.n_b
        if n_b:
            shift = self._rest_values(y, p)[1]
            a = self.bulk.jacobian.sparse(y[:n_b], p, shift[:n_b])[0]
            jac = jac + sps.block_diag([a, sps.csc_matrix((self.n_y - n_b,) * 2)], format="csc")
        return jac.tocsc()

    # --- the linear solve ---------------------------------------------------------------------
    def factorize(self, y, p) -> None:
        """Refactorize the bulk matrix at ``(y, p)`` and prepare the rest's coupling there."""
        if self.mass_scale is None:
            # The mass matrix's own diagonal: the iteration matrix's also holds beta h^2 K, which
            # on the stiff cross-section gradients of a beam3d wire exceeds the mass by orders.
            diag = np.abs(self.mass(y).diagonal())
            self.mass_scale = float(diag.mean()) if diag.size and diag.mean() > 0 else 1.0
        self.bulk.set(y, p, self._rest_values(y, p)[1])
        self.prepare(y, p)

    def prepare(self, y, p) -> None:
        """The Woodbury update of the rest's exact Jacobian at ``(y, p)``: the unknowns ``K`` it
        touches (every non-bulk unknown and the bulk ones in a nonzero row or column), the
        columns ``Z = P^-1 E_K`` (``P`` = bulk matrix, identity elsewhere), and the factorized
        capacitance ``I + Delta Z_K`` with ``Delta = J_rest[K, K] - I`` on the non-bulk part."""
        n_b, n_y = self.bulk.n_b, self.n_y
        r_i, c_i, data = self._rest_triplets(y, p)
        touched = np.unique(np.concatenate([r_i[r_i < n_b], c_i[c_i < n_b]]))
        keys = np.concatenate([touched, np.arange(n_b, n_y)])
        pos = np.full(n_y, -1)
        pos[keys] = np.arange(keys.size)
        k = keys.size
        delta = np.zeros((k, k))
        np.add.at(delta, (pos[r_i], pos[c_i]), data)
        n_t = touched.size
        delta[n_t:, n_t:] -= np.eye(k - n_t)
        z_bulk = self.bulk.columns(touched) if n_t else np.zeros((n_b, 0))
        z_k = np.eye(k)
        if n_t:
            z_k[:n_t, :n_t] = z_bulk[touched]
        try:
            cap = sla.lu_factor(np.eye(k) + delta @ z_k)
        except (ValueError, sla.LinAlgError):
            raise SolverError(_SINGULAR) from None
        if np.any(np.diag(cap[0]) == 0):
            raise SolverError(_SINGULAR)
        self._coupling = (keys, n_t, delta, z_bulk, cap)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """``J^-1 rhs`` with ``J = P + E_K Delta E_K^T`` (Woodbury)."""
        keys, n_t, delta, z_bulk, cap = self._coupling
        n_b = self.bulk.n_b
        x = rhs.copy()
        x[:n_b] = self.bulk.solve(rhs[:n_b])
        w = sla.lu_solve(cap, delta @ x[keys])
        x[:n_b] -= z_bulk @ w[:n_t]
        x[n_b:] -= w[n_t:]
        return x


class _Proxies:
    """Stand-in elements for the element windows of sliding joints and penalty contacts.

    A window of many elements makes the rest's Jacobian structurally dense over all of them
    (the element is chosen by masks of ``s``) and must be rebuilt whenever the point nears its
    edge: on a line, several times per simulated second at a fraction of a second each. Instead
    the rest is built once with a one-element window on a *proxy* element of each wire
    (interior, all coordinates free, touched by nothing else of the rest, proxies two elements
    apart) whose start and length are inputs; each evaluation writes the actual element's
    coordinates and step data into the proxy's places, and the results at the proxy's rows and
    columns are moved back to the actual element's (dropping fixed coordinates)."""

    def __init__(self, step, items, elements):
        form = step.form
        model = form.model
        y_of_q = np.full(model.n_q, -1)
        y_of_q[model.free] = np.arange(form.n_f)
        q_fixed = np.array(form.q_fixed).ravel()
        n_sliding = len(model.sliding)
        self.n_u = step.n_u
        self._model = model
        self.items = []
        for i, (sl, j) in enumerate(zip(items, elements)):
            where = form.n_f + i if i < n_sliding else step.n_y - step.n_sc + (i - n_sliding)
            self.items.append((sl, j, y_of_q[sl.element_indices], q_fixed[sl.element_indices], where))

    @classmethod
    def choose(cls, step, y, p):
        """Proxies for ``step``'s model, or None when its windows never move or no element
        qualifies (the windows are then rebuilt as the points move)."""
        model = step.form.model
        items = model.windowed()
        if not items or not model.windows_move():
            return None
        y_of_q = np.full(model.n_q, -1)
        y_of_q[model.free] = np.arange(step.form.n_f)

        def candidates(offset):
            picked, used = [], set()
            for sl in items:
                n_el = len(sl.element_start) - 1
                ok = [j for j in range(1 + offset, n_el - 1) if np.all(y_of_q[sl.element_indices[j]] >= 0)
                      and not used & set(sl.element_indices[max(j - 1, 0) : j + 2].ravel().tolist())]
                if not ok:
                    return None
                picked.append(ok[0])
                used |= set(sl.element_indices[ok[0]].tolist())
            return picked

        first, second = candidates(0), candidates(3)
        if first is None or second is None:
            return None
        # Bulk columns of the rest that belong to no proxy: other rest terms on the wires.
        others = set()
        for elements in (first, second):
            proxy = cls(step, items, elements)
            w = ca.MX.sym("w", 2 * len(items))
            saved = [sl.window for sl in items]
            try:
                proxy.install(w)
                pattern = ca.Function("probe", [y, p, w], [step._rows(y, p)[0]]).sparsity_jac(0, 0)
            finally:
                model.element_override.clear()
                for sl, window in zip(items, saved):
                    sl.window = window
            cols = set(np.array(pattern.get_col(), int).tolist())
            mine = set(y_of_q[np.concatenate([sl.element_indices[j] for sl, j in zip(items, elements)])].tolist())
            others |= {c for c in cols - mine if c < step.bulk.n_b}
        proxy = cls(step, items, first)
        if others & set(y_of_q[np.concatenate([sl.element_indices[j] for sl, j in zip(items, first)])].tolist()):
            return None
        return proxy

    def install(self, w) -> None:
        """One-element windows on the proxies, their start and length the symbols ``w``."""
        for i, (sl, j, *_) in enumerate(self.items):
            sl.window = (j, j + 1)
            self._model.element_override[id(sl)] = (w[2 * i], w[2 * i + 1])

    def substitute(self, y, p):
        """``(y, p)`` with each proxy's places holding its actual element's values, the
        elements' start and length ``w``, and the maps ``(proxy, actual)`` of y indices."""
        n_u = self.n_u
        y2, p2 = y.copy(), p.copy()
        w = np.empty(2 * len(self.items))
        maps = []
        for i, (sl, j, index, fixed, where) in enumerate(self.items):
            n_el = len(sl.element_start) - 1
            k = int(np.clip(np.searchsorted(sl.element_start, y[where], side="right") - 1, 0, n_el - 1))
            proxy, actual = index[j], index[k]
            free = actual >= 0
            at = np.where(free, actual, 0)
            y2[proxy] = np.where(free, y[at], fixed[k])
            p2[proxy] = np.where(free, p[at], fixed[k])
            p2[n_u + proxy] = np.where(free, p[n_u + at], 0.0)
            p2[2 * n_u + proxy] = np.where(free, p[2 * n_u + at], 0.0)
            w[2 * i] = sl.element_start[k]
            w[2 * i + 1] = sl.element_start[k + 1] - sl.element_start[k]
            maps.append((proxy, actual))
        return y2, p2, w, maps


def _move_back(vector: np.ndarray, maps) -> None:
    """Add the proxies' entries of ``vector`` to their actual elements' (in place)."""
    values = [vector[proxy].copy() for proxy, _ in maps]
    for proxy, _ in maps:
        vector[proxy] = 0.0
    for (_, actual), v in zip(maps, values):
        keep = actual >= 0
        np.add.at(vector, actual[keep], v[keep])


def _csc(matrix) -> sps.csc_matrix:
    """A CasADi sparse matrix as SciPy CSC."""
    colind, row = matrix.sparsity().get_ccs()
    return sps.csc_matrix((np.array(matrix.nonzeros()), np.array(row), np.array(colind)), shape=matrix.shape)


def solve_step(st: StepEquations, y0, p, n_u, n_c, n_sc, tol, max_iterations, stats, refreshed: bool = False):
    """Modified Newton iteration of one step from the predictor ``y0``, with the bulk matrix
    kept and the rest's exact Jacobian at the predictor: when the iteration contracts by less
    than :data:`SLOW_CONTRACTION` per iteration the rest is re-evaluated at the current iterate,
    the second time the bulk is refactorized there. Converged when the last update, with the
    remaining error estimated from the contraction rate, is below ``tol``: an absolute
    tolerance on the coordinates and contact arc lengths (m, or the dimensionless slopes and
    Euler parameters), so that it means the same anywhere along a line (a tolerance relative to
    ``|u|`` would be 100 times looser 100 m down the line than at its start); the scaled
    multipliers ``beta h^2 lambda`` count as the position change ``beta h^2 lambda / m`` they
    cause on a mass ``m`` (the mean diagonal of ``M``), and ``nu`` as a position change.
    Returns ``(y, a, v, v_dot)`` or None."""
    y = y0.copy()
    bh2 = float(p[3 * n_u + 1])
    fresh = refreshed
    if not st.bulk.valid_for(bh2) or st.mass_scale is None:
        st.factorize(y, p)
        fresh = True
    elif not refreshed:
        st.prepare(y, p)
    scale = np.full_like(y, tol)
    scale[n_u : n_u + n_c] = tol * st.mass_scale
    previous = None
    slow = 0
    for _ in range(max_iterations):
        r = st.residual(y, p)
        dy = st.solve(-r)
        y += dy
        stats["newton_iterations"] += 1
        err = np.abs(dy / scale).max(initial=0.0)
        theta = err / previous if previous else 0.0
        if not np.isfinite(err):
            return None
        if err <= 1.0 and theta < 1.0 and theta / (1.0 - theta) * err <= 1.0 or err <= 1e-3:
            return (y, *st.update(y, p))
        if previous is not None and theta > SLOW_CONTRACTION:
            if fresh and theta >= 1.0:
                return None  # diverging with an up-to-date matrix
            slow += 1
            if slow == 1:  # the contact moved on: the rest at the current iterate first
                st.prepare(y, p)
            else:
                st.factorize(y, p)
                fresh = True
            previous = None
            continue
        previous = err
    if not fresh:  # a last attempt with an up-to-date matrix from the predictor
        st.factorize(y0, p)
        return solve_step(st, y0, p, n_u, n_c, n_sc, tol, max_iterations, stats, refreshed=True)
    return None
