"""The equations of one generalized-alpha step (their linear solve: :mod:`.alpha_linear`; the
modified Newton iteration over them: :mod:`.alpha_newton`), for
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

When the wires are not the larger part of the unknowns (the seed paper's 8-element wire under
its vehicle, or no wire at all) the whole step matrix is factorized instead (sparse LU), and a
rest of many unknowns keeps its factorization over the steps while Newton converges fast
(:meth:`.alpha_linear.StepSolve.keeps_coupling`), improved in between by Broyden's secant
updates (:meth:`.alpha_linear.StepSolve.secant`); the linear solve is
:mod:`.alpha_linear`'s. Under the stabilized form the iteration starts from the multipliers
``nu`` extrapolated from the last steps (:class:`.alpha_history.StartHistory`).

This is how dedicated pantograph/catenary codes keep a constant iteration matrix while the
contact point moves; refactorizing a 7,000-unknown line whenever the contact crosses an element,
or differentiating the whole graph, costs more than the rest of the step many times over.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ..assembly.wheelrail import has_creep
from ..codegen.library import BufferedFunction, symbolic_kernels
from ..dae.formulation import Formulation
from .alpha_bulk import Bulk, step_data
from .alpha_history import StartHistory
from .alpha_linear import StepSolve
from .alpha_placement import Placement, Terms, csc_pattern, identity, output_maps, weighted_sum
from .alpha_proxies import Proxies
from .alpha_rest import compiled_rest, expanded_rest


def step_sizes(form: Formulation, variant: str) -> tuple[int, int, int, int]:
    """``(n_u, n_c, n_sc, n_y)`` of the steps of ``form`` under ``variant``: the coordinates and
    arc lengths, the constraints, the penalty contacts' arc lengths and the unknowns ``y``
    (:class:`StepEquations`), known without building the equations."""
    n_u = form.n_f + form.n_s
    return n_u, form.n_c, form.n_sc, n_u + form.n_c * (2 if variant == "stabilized" else 1) + form.n_sc


class StepEquations:
    """The step equations of one element window: the rest's residual and exact Jacobian (one
    expanded function), with the window-independent :class:`Bulk` (carried over from the
    previous window's equations) and the split linear solve of the modified Newton iteration
    (:attr:`linear`, a :class:`~.alpha_linear.StepSolve`).

    ``y = [u, beta h^2 lambda (, nu), s_c]`` and the rows ``[dynamics, C_s^T lambda, C (, velocity
    constraints), T]``: the arc lengths ``s_c`` of the penalty contacts are algebraic unknowns of
    the step with their tangency rows ``T(q, s_c) = 0`` (no multiplier; their normal forces are
    in ``Q``). ``p = [u_pred, v_pred, b, t_{n+1}, beta h^2, gamma h, (1 - alpha_m)/(1 - alpha_f)]``
    with ``u_pred = u_n + h v_n + h^2 (1/2 - beta) a_n``, ``v_pred = v_n + h (1 - gamma) a_n`` and
    ``b = (alpha_m a_n - alpha_f v_dot_n) / (1 - alpha_f)``.

    ``compiled`` (models with wheel/rail contacts): True compiles the rest to C if it is not
    cached yet (:func:`.alpha_rest.compiled_rest`), None uses a cached library only, False never does."""

    def __init__(self, form: Formulation, variant: str, expand: bool = False, bulk: Bulk | None = None,
                 mass_scale: float | None = None, proxies: bool = True,
                 compiled: bool | None = True):
        n_u, n_c, n_sc, n_y = step_sizes(form, variant)
        self.n_u, self.n_c, self.n_s, self.n_sc, self.n_y = n_u, n_c, form.n_s, n_sc, n_y
        self.variant, self.form = variant, form
        model = form.model
        # Few wire unknowns against the rest (the seed's 8-element wire under a vehicle, or no
        # wire): the whole step matrix is factorized (sparse LU) instead of corrected by a
        # Woodbury update, whose capacitance is then as large as the system and, with the
        # stiff cross-section gradients of beam3d wires, too ill-conditioned to solve accurately.
        n_b = int(np.count_nonzero(model.free < model.ancf.n))
        self.direct = n_b <= n_y - n_b
        # The bulk's Jacobian is then evaluated at every factorization: expanded to scalar
        # operations (small here), three times faster than its graph; its residual likewise
        # one expanded function.
        self.bulk = bulk if bulk is not None else Bulk(form, n_u, expand or self.direct, whole=self.direct)
        y = ca.MX.sym("y", n_y)
        p = ca.MX.sym("p", 3 * n_u + 4)
        # The open flags of the wheel/rail contacts (1: lifted off), set by an event handler.
        self.mode = np.zeros(len(model.wheelrail))
        self.mode_symbol = mode = ca.MX.sym("mode", self.mode.size)
        self.proxies, probe = Proxies.choose(self, y, p) if proxies else (None, None)
        saved = [sl.window for sl in model.windowed()]
        # (on proxies: the rows the choice of proxies built, on its symbols w)
        w, rows, pattern = probe if probe is not None else (ca.MX.sym("w", 0), None, None)
        try:
            if self.proxies is not None:
                self.proxies.install(w)
            # The rest depends on few unknowns: entered as a structurally sparse y, its graph and
            # Jacobian never touch the other thousands.
            if rows is None:
                rows = self._rows(y, p, mode, contacts=True)  # built once: the graph of a vehicle takes a while
                pattern = ca.Function("alpha_rest", [y, p, w, mode], [rows[0]]).sparsity_jac(0, 0)
            self.rest_columns = np.unique(np.array(pattern.get_col(), int))
            k = self.rest_columns.size
            y_rest = ca.MX.sym("y_rest", k)
            y_sparse = ca.MX(ca.Sparsity.triplet(n_y, 1, self.rest_columns.tolist(), [0] * k), y_rest)
            # Likewise the step data: the predictors of the few unknowns it touches and the
            # scalars (copying the whole p into the function at every call cost more than its
            # evaluation on a line).
            outputs = ca.vertcat(*rows)
            used = ca.Function("alpha_rest", [y, p, w, mode], [outputs]).sparsity_jac(1, 0).get_col()
            self.p_columns = np.union1d(np.array(used, int), np.arange(3 * n_u, 3 * n_u + 4))
            p_rest = ca.MX.sym("p_rest", self.p_columns.size)
            p_sparse = ca.MX(ca.Sparsity.triplet(p.shape[0], 1, self.p_columns.tolist(), [0] * self.p_columns.size),
                             p_rest)
            # Built on the kernels' SX forms and expanded: as scalar operations the rest's
            # Jacobian evaluates some 30 times faster than through the MX graph.
            with symbolic_kernels():
                rest = ca.Function("alpha_rest", [y_rest, p_rest, w, mode],
                                   list(self._rows(y_sparse, p_sparse, mode, contacts=True)))
            if self.proxies is not None:
                self.proxies.restrict(self.rest_columns, self.p_columns)
        finally:
            model.element_override.clear()
            for sl, window in zip(model.windowed(), saved):
                sl.window = window
        rest, jac = compiled_rest(rest, build=compiled) if model.wheelrail and compiled is not False else \
            expanded_rest(rest)
        self._rest = BufferedFunction(rest)
        # the outputs are sparse (most rows belong to the bulk): their nonzeros' places
        self._r_rows = np.array(rest.sparsity_out(0).row(), int)
        self._shift_rows = np.array(rest.sparsity_out(1).row(), int)
        self._rest_jacobian = BufferedFunction(jac)
        colind, row = jac.sparsity_out(0).get_ccs()
        self._jac_rows = np.array(row, int)
        self._jac_cols = self.rest_columns[np.repeat(np.arange(k), np.diff(colind))]
        self._placements: dict[tuple, Placement] = {}
        if self.proxies is None:
            n_p = self.p_columns.size
            self._placements[()] = Placement(
                Terms(np.arange(k), self.rest_columns, np.ones(k), np.zeros(k)),
                Terms(np.arange(n_p), self.p_columns, np.ones(n_p), np.zeros(n_p)), np.zeros(0),
                *output_maps(identity, self._r_rows, self._shift_rows, self._jac_rows, self._jac_cols), n_y, n_u)
        self._contact_data = None  # the step data of contacts()
        self.mass_scale = mass_scale  # kg: mean diagonal of M, converts multiplier updates to positions
        self.last_iterations = 0
        self.history = StartHistory()
        self.last_shift = None  # the shift G^T nu of the last update()
        self.linear = StepSolve(self)  # the iteration matrix and its solves

    def reset(self) -> None:
        """Forget the factorizations, the prepared coupling and the open flags (a new run on
        the same equations)."""
        self.bulk.lu, self.bulk.bh2, self.bulk.factorizations = None, None, 0
        self.bulk._columns.clear()
        self.bulk._last = None
        self.mode[:] = 0.0
        self.last_iterations = 0
        self.linear.clear()
        self.history.clear()

    def _rows(self, y, p, mode, contacts: bool = False, part: str = "rest"):
        """The rest's scaled residual rows and the stabilization's shift ``G^T nu`` at ``(y,
        p)``: the step residual without the bulk's mass and forces (with ``contacts``, also the
        penalty contacts' gaps and normal forces; ``part="all"``: the whole step's residual). The wheel/rail contacts' creep forces depend
        on their normal forces (the multipliers ``lambda = y_lambda / (beta h^2)``); an open
        contact (``mode`` 1) has its gap rows replaced by its multipliers, as in the DAE
        (:meth:`Formulation.dae`)."""
        form, variant = self.form, self.variant
        n_f, n_s, n_c, n_sc, n_u, n_y = form.n_f, self.n_s, self.n_c, self.n_sc, self.n_u, self.n_y
        u_pred, v_pred, b, t, bh2, gh, cm = step_data(p, n_u)
        u, lam_s = y[:n_u], y[n_u : n_u + n_c]
        sc = y[n_y - n_sc :] if n_sc else None
        q, s = u[:n_f], u[n_f:]
        shift = ca.MX(n_u, 1)
        if variant == "stabilized" and n_c:  # (no constraints: no shift, and no graph of the terms for it)
            nu = y[n_u + n_c : n_u + 2 * n_c]
            # C_q and C_s depend on positions only: the velocities of this probe are immaterial.
            g = self._terms(form, q, ca.MX.zeros(n_f), s, ca.MX.zeros(n_s), t, sc, part)
            shift = ca.vertcat(ca.mtimes(g["Cq"].T, nu), ca.mtimes(g["Cs"].T, nu))
        a = (u - u_pred - shift) / bh2
        v = v_pred + gh * a
        v_dot = cm * a + b
        k = self._terms(form, q, v[:n_f], s, v[n_f:], t, sc, part)
        dyn = ca.mtimes(k["M"], v_dot[:n_f]) - k["Q"]
        if has_creep(form.model):
            dyn -= form.creep_force(k, s, v[n_f:], lam_s / bh2)[0]
        rows = [bh2 * dyn + ca.mtimes(k["Cq"].T, lam_s), ca.mtimes(k["Cs"].T, lam_s),
                form._release(k["C"], lam_s, mode)]
        if variant == "stabilized" and n_c:
            c_dot = bh2 / gh * (ca.mtimes(k["Cq"], v[:n_f]) + ca.mtimes(k["Cs"], v[n_f:]) + k["Ct"])
            rows.append(form._release(c_dot, nu, mode))
        rows.append(k["T"])
        if contacts:
            return ca.vertcat(*rows), shift, k["gap"], k["fc"]
        return ca.vertcat(*rows), shift

    @staticmethod
    def _terms(form, q, v, s, w, t, sc=None, part="rest"):
        k = form.terms(q, v, s, w, t, sc, part=part)
        if form.n_s == 0:  # an empty s would leave Cs 0 x 0 against n_c rows
            return {**k, "Cs": ca.MX(form.n_c, 0)}
        return k

    # --- evaluation ---------------------------------------------------------------------------
    def _placement(self, y) -> Placement:
        """The rest's index maps for the elements that hold the contact points in ``y``."""
        if self.proxies is None:
            return self._placements[()]
        key = self.proxies.key(y)
        found = self._placements.get(key)
        if found is None:
            if len(self._placements) > 64:
                self._placements.clear()
            y_terms, p_terms, w, expand = self.proxies.placement(key)
            found = self._placements[key] = Placement(
                y_terms, p_terms, w, *output_maps(expand, self._r_rows, self._shift_rows, self._jac_rows, self._jac_cols),
                self.n_y, self.n_u)
        return found

    def _rest_values(self, y, p):
        """The rest's residual (n_y) and shift (n_u) at ``(y, p)``, dense."""
        placement = self._placement(y)
        r_nz, shift_nz, *_ = self._rest.nonzeros(*placement.inputs(y, p), self.mode)
        return placement.residual(r_nz, shift_nz)

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
        p = self._contact_data
        if p is None:  # kept: a line's p is tens of thousands of entries, built at every step
            p = self._contact_data = np.r_[np.zeros(3 * n_u), 0.0, 1.0, 1.0, 1.0]
        p[:n_u], p[n_u : 2 * n_u], p[3 * n_u] = u, v, t
        _, _, gap, force = self._rest.nonzeros(*self._placement(y).inputs(y, p), self.mode)
        return gap, force

    def update(self, y, p) -> tuple:
        """``a``, ``v`` and ``v_dot`` at the end of the step whose unknowns are ``y``."""
        # the index-3 form has no shift: no evaluation of the rest
        shift = self._rest_values(y, p)[1] if self.variant == "stabilized" else 0.0
        self.last_shift = shift
        u_pred, v_pred, b, _, bh2, gh, cm = step_data(p, self.n_u)
        a = (y[: self.n_u] - u_pred - shift) / bh2
        return a, v_pred + gh * a, cm * a + b

    def mass(self, y) -> sps.csc_matrix:
        """The mass matrix (free coordinates, scipy sparse) at the positions of ``y``."""
        return self.bulk.mass(y[: self.form.n_f])

    def _rest_triplets(self, y, p) -> tuple[Placement, np.ndarray]:
        """The rest's exact Jacobian at ``(y, p)``: its placement, whose ``jac_rows`` and
        ``jac_cols`` are the terms' rows and columns (duplicates add), and their values."""
        placement = self._placement(y)
        values = self._rest_jacobian.nonzeros(*placement.inputs(y, p), self.mode)[0]
        data = placement.jacobian(values)
        extra = self._shift_coupling(placement, data, p)
        return placement, data if extra is None else np.concatenate([data, extra])

    def _shift_coupling(self, placement: Placement, data, p) -> np.ndarray | None:
        """The bulk rows' dependence on ``nu`` through the shift of ``a`` under the stabilized
        form, ``-(c_m M + gamma h C) G^T`` with the constant bulk mass and Rayleigh matrices:
        the values of terms (dense on the rows it reaches, appended to the placement's pattern
        at the first call) given the rest's Jacobian values ``data``; None if there are none."""
        n_b, n_u, n_c = self.bulk.n_b, self.n_u, self.n_c
        if self.variant != "stabilized" or not n_b:
            return None
        found = placement.cache.get("shift")
        if found is None:
            rows, cols = placement.jac_rows, placement.jac_cols
            g = np.flatnonzero((rows >= n_u) & (rows < n_u + n_c) & (cols < n_b))  # G on the bulk coordinates
            found = None
            if g.size:
                g_cols, at = np.unique(cols[g], return_inverse=True)
                g_rows, row_at = np.unique(rows[g] - n_u, return_inverse=True)  # the constraints on the bulk
                reach = abs(self.bulk.mass_matrix[:, g_cols]) + abs(self.bulk.rayleigh[:, g_cols])
                reached = np.unique(reach.nonzero()[0])
                found = (g, g_cols, at, row_at, g_rows.size, reached)
                placement.add_terms(np.repeat(reached, g_rows.size), np.tile(n_u + n_c + g_rows, reached.size))
            placement.cache["shift"] = found
        if found is None:
            return None
        g, g_cols, at, row_at, n_g, reached = found
        _, _, _, _, _, gh, cm = step_data(p, n_u)
        block = placement.cache.get("block")
        if block is None or block[0] != (gh, cm):
            dense = (cm * self.bulk.mass_matrix[reached][:, g_cols] + gh * self.bulk.rayleigh[reached][:, g_cols])
            block = placement.cache["block"] = ((gh, cm), dense.toarray())
        g_b = np.zeros((g_cols.size, n_g))  # G^T on the bulk columns it touches
        np.add.at(g_b, (at, row_at), data[g])
        return -(block[1] @ g_b).ravel()

    def jacobian(self, y, p) -> sps.csc_matrix:
        """The whole step Jacobian at ``(y, p)`` (bulk and rest), assembled on a pattern kept
        per placement."""
        placement, data = self._rest_triplets(y, p)
        n_b, n_y = self.bulk.n_b, self.n_y
        if n_b:
            shift = self._rest_values(y, p)[1]
            data = np.concatenate([data, self.bulk.jacobian.matrix(y[:n_b], p, shift[:n_b]).data])
        pattern = placement.cache.get("csc")
        if pattern is None:
            rows, cols = placement.jac_rows, placement.jac_cols
            if n_b:
                bulk = self.bulk.jacobian
                bulk_rows, bulk_cols = bulk.indices, np.repeat(np.arange(n_b), np.diff(bulk.indptr))
                rows, cols = np.r_[rows, bulk_rows], np.r_[cols, bulk_cols]
            pattern = placement.cache["csc"] = csc_pattern(rows, cols, n_y)
        place, indices, indptr = pattern
        jac = sps.csc_matrix((weighted_sum(place, data, indices.size), indices, indptr), shape=(n_y, n_y))
        jac.eliminate_zeros()  # the pattern's structural zeros (open contacts...) would cost the sparse LU
        return jac

    # --- scaling and start of the iteration ----------------------------------------------------
    def scale_multipliers(self, y) -> float:
        """:attr:`mass_scale`, set at ``y`` if not yet: the mean of the mass matrix's own
        diagonal (the iteration matrix's also holds beta h^2 K, which on the stiff
        cross-section gradients of a beam3d wire exceeds the mass by orders)."""
        if self.mass_scale is None:
            diag = np.abs(self.mass(y).diagonal())
            self.mass_scale = float(diag.mean()) if diag.size and diag.mean() > 0 else 1.0
        return self.mass_scale

    def start(self, y0, p, tol: float) -> np.ndarray:
        """The Newton iteration's start from the integrator's predictor ``y0``: under the
        stabilized form, ``nu`` and the positions' shift ``G^T nu`` (which the converged
        positions hold) extrapolated from the last steps (:class:`.alpha_history.StartHistory`); ``y0`` itself
        where the history does not reach."""
        if self.variant != "stabilized":
            return y0
        n_u, n_c = self.n_u, self.n_c
        found = self.history.predict(y0, p, n_u, self.mode, tol)
        if found is None:
            return y0
        y = y0.copy()
        y[n_u + n_c : n_u + 2 * n_c], y[:n_u] = found[0], y[:n_u] + found[1]
        return y
