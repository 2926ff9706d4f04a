"""The residual of a generalized-alpha step and its iteration matrix as one CasADi graph for
compiled code (:mod:`.alpha_chunk`), wires and rest apart as in :mod:`.alpha_step`.

The wires' rows (:func:`.alpha_bulk.bulk_rows`) are one function of their coordinates. The rest
(bodies, joints, contacts, multipliers: :meth:`.alpha_step.StepEquations._rows` with
``part="rest"``) is built as the Python steps build it: on its element windows when they never
move (a wire no longer than a window), else on a proxy element of each wire
(:class:`.alpha_proxies.Proxies`), into whose places the graph writes, at run time, the
coordinates and step data of the element that holds the point (chosen from its arc length by
parametric gathers from tables of every element's terms) and from whose rows and Jacobian
entries it adds the results back to that element's (the gathers' adjoint, a scatter-add). The
code then holds one element of a long wire per point, not every element.

The iteration matrix is the step's Jacobian but for the wires' own block, which is the bulk's
(elements, Rayleigh damping, force elements between nodes): what a point adds there (a joint's
multiplier times its curvature, a contact's stiffness) sits on the element that holds the point
and is left out, as is the shift's arc-length derivative; the iteration is the modified Newton
one it already is (a joint's term is a fraction of a per cent of the wires' stiffness; a stiff
penalty contact slows the iteration, whose steps then fall back to Python)."""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..assembly.sparse import to_casadi_sparse
from ..codegen.library import merged
from .alpha_bulk import bulk_rows, step_data
from .alpha_chunk_wires import LoopedWires, looped
from .alpha_proxies import element_terms

#: Operations up to which the wires' Jacobian is expanded to scalar operations (a third faster
#: on a 16-element cable, 60k operations, whose iteration matrix is renewed most steps at coarse
#: steps); beyond, it stays a graph of the elements' stiffness kernels (the compiler's time
#: grows with the code: damped elements' Jacobians are several times larger).
EXPANDED_JACOBIAN = 70_000


class ChunkResidual:
    """``rows(y, p)``, ``shift(y, p)`` and ``jacobian(y, p)`` of the step of ``st`` (a
    :class:`~.alpha_step.StepEquations`) as MX expressions; ``expand``: the wires' and the
    rest's functions expanded to scalar operations (inside
    :func:`~symcat.codegen.library.symbolic_kernels`, for the compiled code), but the wires of
    a model with many elements (:func:`.alpha_chunk_wires.looped`; ``loops``: whether to,
    default that), which are built as loops (:class:`.alpha_chunk_wires.LoopedWires`)."""

    def __init__(self, st, expand: bool = False, loops: bool | None = None):
        self.st = st
        form = st.form
        self.n_b, self.n_y, self.n_u = n_b, n_y, n_u = st.bulk.n_b, st.n_y, st.n_u
        n_c = st.n_c if st.variant == "stabilized" else 0
        self._nu = list(range(n_u + n_c, n_u + 2 * n_c))  # the velocity multipliers' places in y
        y, p = ca.MX.sym("y", n_y), ca.MX.sym("p", 3 * n_u + 4)
        shift_b = ca.MX.sym("shift_b", n_b)
        y_b = ca.MX.sym("y_b", n_b)
        r_b = bulk_rows(form, n_b, n_u, y_b, p, shift_b) if n_b else ca.MX(0, 1)
        self._bulk = ca.Function("alpha_chunk_bulk", [y_b, p, shift_b], [r_b])
        self._bulk_graph = (y_b, p, shift_b, r_b)
        self._bulk_jacobian = None  # built by jacobian() (the cache key needs the rows only)
        model = form.model
        items = model.windowed()
        self.proxies = st.proxies
        saved = [sl.window for sl in items]
        w = ca.MX.sym("w", 2 * len(items) if self.proxies is not None else 0)
        try:
            if self.proxies is not None:  # windows that move: one proxy element per point
                self.proxies.install(w)
            else:  # windows that never move: each is its whole wire
                for sl in items:
                    sl.window = (0, len(sl.element_start) - 1)
            rows, shift, *contacts = st._rows(y, p, ca.MX.sym("mode", 0), contacts=bool(st.n_sc), part="rest")
        finally:
            model.element_override.clear()
            for sl, window in zip(items, saved):
                sl.window = window
        self._rest = ca.Function("alpha_chunk_rest", [y, p, w], [rows, shift])
        # the penalty contacts' gaps and forces, for the records of a monitored run
        self._contacts = ca.Function("alpha_chunk_contacts", [y, p, w], contacts) if contacts else None
        self._rest_jacobian = None
        self._expand = expand
        self.looped = expand and n_b > 0 and (looped(model) if loops is None else loops)
        if self.looped:  # the wires' code as loops over their elements, not straight-line code
            self._bulk, self._bulk_jacobian = LoopedWires(st).functions()
        if expand:
            if not self.looped:
                self._bulk = merged(self._bulk.expand())
            # (its rows sparse: dense, a line's code would write each of its thousands of zeros)
            self._rest = merged(_sparsified(self._rest.expand()))
            if self._contacts is not None:
                self._contacts = merged(self._contacts.expand())
            # The rest's border in scalar operations, differentiated where its entries depend
            # on the unknowns: CasADi's derivative of a call in all directions would be the
            # rest's code as many times over as there are directions.
            y_s, p_s, w_s = self._rest.sx_in()
            rows_s, shift_s = self._rest(y_s, p_s, w_s)
            y_r = y_s[n_b:]
            self._rest_jacobian = merged(ca.Function("alpha_chunk_rest_jacobian", [y_s, p_s, w_s], [
                ca.jacobian(rows_s, y_r), ca.jacobian(rows_s[n_b:], y_s[:n_b]),
                ca.jacobian(shift_s[:n_b], y_s[self._nu]), shift_s]))
        self._tables = self._element_tables() if self.proxies is not None else []

    def _wires_jacobian(self) -> ca.Function:
        """``(y_b, p, shift_b) -> d rows_b / d y_b``, expanded (with ``expand``) up to
        :data:`EXPANDED_JACOBIAN` operations."""
        if self._bulk_jacobian is None:
            # differentiated over the kernels' graph (their own stiffness functions), then expanded
            y_b, p, shift_b, r_b = self._bulk_graph
            fn = ca.Function("alpha_chunk_bulk_jacobian", [y_b, p, shift_b], [ca.jacobian(r_b, y_b)])
            if self._expand:
                expanded = fn.expand()
                if expanded.n_instructions() <= EXPANDED_JACOBIAN:
                    fn = merged(expanded)
            self._bulk_jacobian = fn
        return self._bulk_jacobian

    # --- the proxies' substitution ----------------------------------------------------------
    def _element_tables(self):
        """Per proxy: its y places, the place of its point's arc length in y, the starts of its
        wire's elements, and per element (-1 .. n_el: ``k + 1``) two terms per local coordinate
        (sources in y, -1 none; weights), the fixed coordinates' constants, start and length."""
        form, model = self.st.form, self.st.form.model
        y_of_q = np.full(model.n_q, -1)
        y_of_q[model.free] = np.arange(form.n_f)
        q_fixed = np.array(form.q_fixed).ravel()
        tables = []
        for sl, j, index, _, where in self.proxies.items:
            n_el, n_loc = len(sl.element_start) - 1, sl.element_indices.shape[1]
            sources = np.full((n_el + 2, 2 * n_loc), -1)
            weights = np.zeros((n_el + 2, 2 * n_loc))
            constants = np.zeros((n_el + 2, n_loc))
            start_length = np.zeros((n_el + 2, 2))
            for k in range(-1, n_el + 1):
                rows, src, wts, constant, start, length = element_terms(sl, k, y_of_q, q_fixed)
                used = np.zeros(n_loc, int)
                for r, sr, wt in zip(rows, src, wts):  # at most two terms per local coordinate
                    sources[k + 1, 2 * r + used[r]], weights[k + 1, 2 * r + used[r]] = sr, wt
                    used[r] += 1
                constants[k + 1], start_length[k + 1] = constant, (start, length)
            tables.append((index[j], where, np.asarray(sl.element_start, float), sources, weights, constants,
                           start_length))
        return tables

    def _substituted(self, y, p):
        """``(y, p, w, terms)``: the rest's inputs with each proxy's places holding its actual
        element's values (as :meth:`.alpha_proxies.Proxies.placement` maps them), the
        elements' start and length ``w``, and per proxy ``(places, sources, weights)``."""
        n_y, n_u = self.n_y, self.n_u
        y_sub, p_sub, w, terms = y, p, [], []
        for places, where, starts, sources, weights, constants, start_length in self._tables:
            n_loc = places.size
            k = ca.sum1(ca.DM(starts) <= y[where])  # the element holding the point, plus one
            pick = k * (2 * n_loc) + ca.DM(np.arange(2 * n_loc))
            src = ca.MX(ca.DM(sources.ravel()))[pick]
            wts = ca.MX(ca.DM(weights.ravel()))[pick]
            const = ca.MX(ca.DM(constants.ravel()))[k * n_loc + ca.DM(np.arange(n_loc))]
            w.append(ca.MX(ca.DM(start_length.ravel()))[k * 2 + ca.DM([0, 1])])

            def local(vector, size):
                values = wts * ca.vertcat(vector, 0)[ca.if_else(src >= 0, src, size)]  # -1: the zero appended
                return values[0::2] + values[1::2]

            y_sub = _set(y_sub, places, local(y, n_y) + const)
            u_pred, v_pred, b = (p[i * n_u : (i + 1) * n_u] for i in range(3))
            p_sub = _set(p_sub, places, local(u_pred, n_u) + const)
            p_sub = _set(p_sub, places + n_u, local(v_pred, n_u))
            p_sub = _set(p_sub, places + 2 * n_u, local(b, n_u))
            terms.append((places, src, wts))
        return y_sub, p_sub, ca.vertcat(*w), terms

    @staticmethod
    def _moved_back(matrix, terms):
        """Each column of ``matrix`` with each proxy's entries added to its actual element's
        (the substitution's transpose) and removed from its places."""
        size, m = matrix.shape
        if not m or not size:  # nothing to move (the index-3 form's shift derivatives: no nu)
            return matrix
        values = [matrix[places.tolist(), :] for places, _, _ in terms]
        for places, _, _ in terms:
            matrix = _set(matrix, places, ca.MX.zeros(places.size, m))
        flat = ca.vec(matrix)
        for (places, src, wts), v in zip(terms, values):
            # every column at once: one scatter into the flattened matrix
            n_terms = 2 * places.size
            twice = np.repeat(np.arange(places.size), 2).tolist()  # the two term slots of each coordinate
            coefficients = ca.vec(ca.repmat(wts, 1, m) * v[twice, :])
            src_m = ca.repmat(src, 1, m)
            offsets = ca.DM(np.tile(np.arange(m) * size, (n_terms, 1)))
            at = ca.vec(ca.if_else(src_m >= 0, src_m + offsets, size * m))
            flat = flat + _scatter_add(coefficients, at, size * m)
        return ca.reshape(flat, size, m)

    # --- the step's functions -------------------------------------------------------------------
    def parts(self, y, p):
        """``(rest rows, shift)``, moved back from the proxies to the actual elements."""
        if self.proxies is None:
            return self._rest(y, p, ca.MX(0, 1))
        y_sub, p_sub, w, terms = self._substituted(y, p)
        rows, shift = self._rest(y_sub, p_sub, w)
        return self._moved_back(rows, terms), self._moved_back(shift, terms)

    def contacts(self, y, p):
        """The penalty contacts' gaps (m) and normal forces (N) at ``(y, p)`` (on the proxies'
        actual elements), as :meth:`.alpha_step.StepEquations.contacts` evaluates them."""
        if self.proxies is None:
            return self._contacts(y, p, ca.MX(0, 1))
        y_sub, p_sub, w, _ = self._substituted(y, p)
        return self._contacts(y_sub, p_sub, w)

    def rows_and_shift(self, y, p):
        """The step's residual rows and the stabilization's shift ``G^T nu`` at ``(y, p)``."""
        rows, shift = self.parts(y, p)
        n_b = self.n_b
        if n_b:
            rows = rows + ca.vertcat(self._bulk(y[:n_b], p, shift[:n_b]), ca.MX(self.n_y - n_b, 1))
        return rows, shift

    def couplings(self) -> tuple[np.ndarray, np.ndarray]:
        """``(e_cols, f_rows)``: the rest's unknowns (positions after the wires') whose columns,
        and its rows whose entries, in the iteration matrix can be nonzero on the wires' rows
        and columns (:meth:`jacobian`): the structure of the rest's Jacobian on the proxy
        element, which moving it back to the actual element keeps, and the velocity
        multipliers whose shift moves the wires. Built with ``expand``."""
        n_b, jac = self.n_b, self._rest_jacobian
        rows, cols = (np.array(x, int) for x in jac.sparsity_out(0).get_triplet())
        shifted = np.unique(np.array(jac.sparsity_out(2).get_triplet()[1], int))  # the nu whose G^T has wire rows
        e_cols = np.union1d(cols[rows < n_b], np.array(self._nu, int)[shifted] - n_b if self._nu else [])
        return e_cols.astype(int), np.unique(np.array(jac.sparsity_out(1).get_triplet()[0], int))

    def jacobian(self, y_b, y_r, p, wires: bool = True):
        """The iteration matrix at ``y = [y_b, y_r]`` (symbols: wires' coordinates and the
        rest's unknowns), see the module's notes; ``wires=False``: its wires' block zero (for
        a refactorization of the border only). Built with ``expand`` (the rest's border is
        differentiated in scalar operations)."""
        n_b, n_u = self.n_b, self.n_u
        y = ca.vertcat(y_b, y_r)
        if self.proxies is not None:
            y_sub, p_sub, w, terms = self._substituted(y, p)
            j_cols, j_rows, d_shift, shift = self._rest_jacobian(y_sub, p_sub, w)
            # chain rule through the substitution: rows and columns at the proxies' places are
            # the actual element's
            j_cols, d_shift, shift = (self._moved_back(j_cols, terms), self._moved_back(d_shift, terms),
                                      self._moved_back(shift, terms))
            j_rows = self._moved_back(j_rows.T, terms).T
        else:
            j_cols, j_rows, d_shift, shift = self._rest_jacobian(y, p, ca.MX(0, 1))
        if not n_b:
            return j_cols
        j_bb = self._wires_jacobian()(y_b, p, shift[:n_b]) if wires else ca.MX(n_b, n_b)
        # the wires' rows through the stabilization's shift of their accelerations (the
        # velocity multipliers' columns): -(c_m M + gamma h C) G^T, with the constant mass and
        # Rayleigh matrices (the shift's arc-length derivative, nu times a curvature, left out)
        if self._nu:
            *_, gh, cm = step_data(p, n_u)
            bulk = self.st.bulk
            nu = [i - n_b for i in self._nu]
            g_t = d_shift
            through_shift = -(cm * ca.mtimes(to_casadi_sparse(bulk.mass_matrix), g_t)
                              + gh * ca.mtimes(to_casadi_sparse(bulk.rayleigh), g_t))
            upper = ca.MX(j_cols[:n_b, :])
            upper[:, nu] = upper[:, nu] + through_shift
        else:
            upper = j_cols[:n_b, :]
        return ca.blockcat([[j_bb, upper], [j_rows, j_cols[n_b:, :]]])


def _sparsified(fn: ca.Function) -> ca.Function:
    """The SX function ``fn`` with its outputs' constant zeros left out of their sparsity."""
    args = fn.sx_in()
    return ca.Function(fn.name(), args, [ca.sparsify(out) for out in fn.call(args)], fn.name_in(), fn.name_out())


def _scatter_add(values, at, size: int):
    """A vector of ``size`` with ``values`` added at the parametric indices ``at`` (an index
    ``size`` is dropped): the adjoint of the gather ``z[at]``."""
    z = ca.MX.sym("z", size + 1)
    c, i = ca.MX.sym("c", values.shape[0]), ca.MX.sym("i", values.shape[0])
    scatter = ca.Function("alpha_chunk_scatter", [c, i], [ca.gradient(ca.dot(c, z[i]), z)[:size]])
    return scatter(values, at)


def _set(matrix, places: np.ndarray, values):
    """``matrix`` with ``values`` in the rows ``places`` (static)."""
    out = ca.MX(matrix)
    out[places.tolist(), :] = values
    return out
