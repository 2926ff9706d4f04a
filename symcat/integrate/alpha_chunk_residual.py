"""The residual of a generalized-alpha step and its iteration matrix as one CasADi graph for
compiled code (:mod:`.alpha_chunk`), wires and rest apart as in :mod:`.alpha_step`: the wires'
rows (:func:`.alpha_bulk.bulk_rows`), and the rest (bodies, joints, contacts, multipliers:
:meth:`.alpha_step.StepEquations._rows` with ``part="rest"``) on element windows that are their
whole wires (the compiled steps take models whose windows never move).

The iteration matrix is the step's Jacobian but for the wires' own block, which is the bulk's
(elements, Rayleigh damping, force elements between nodes): what a point adds there (a joint's
multiplier times its curvature, a contact's stiffness) would make that block dense in
structure, every element's coordinates with every other's through the point's element
selection, although in value only the element holding the point has it. Left out, the
iteration is the modified Newton one it already is (a joint's term is a fraction of a per cent
of the wires' stiffness; a stiff penalty contact slows the iteration, whose steps then fall
back to Python)."""
from __future__ import annotations

import casadi as ca

from ..codegen.library import merged
from .alpha_bulk import bulk_rows, step_data

#: Operations up to which the wires' Jacobian is expanded to scalar operations (a third faster
#: on a 16-element cable, 60k operations, whose iteration matrix is renewed most steps at coarse
#: steps); beyond, it stays a graph of the elements' stiffness kernels (the compiler's time
#: grows with the code: damped elements' Jacobians are several times larger).
EXPANDED_JACOBIAN = 70_000


class ChunkResidual:
    """``rows(y, p)``, ``shift(y, p)`` and ``jacobian(y, p)`` of the step of ``st`` (a
    :class:`~.alpha_step.StepEquations`) as MX expressions; ``expand``: the wires' and the
    rest's functions expanded to scalar operations (inside
    :func:`~symcat.codegen.library.symbolic_kernels`, for the compiled code)."""

    def __init__(self, st, expand: bool = False):
        self.st = st
        form = st.form
        self.n_b, self.n_y, self.n_u = n_b, n_y, n_u = st.bulk.n_b, st.n_y, st.n_u
        y, p = ca.MX.sym("y", n_y), ca.MX.sym("p", 3 * n_u + 4)
        shift_b = ca.MX.sym("shift_b", n_b)
        y_b = ca.MX.sym("y_b", n_b)
        r_b = bulk_rows(form, n_b, n_u, y_b, p, shift_b) if n_b else ca.MX(0, 1)
        self._bulk = ca.Function("alpha_chunk_bulk", [y_b, p, shift_b], [r_b])
        self._bulk_jacobian = ca.Function("alpha_chunk_bulk_jacobian", [y_b, p, shift_b],
                                          [ca.jacobian(r_b, y_b)])
        model = form.model
        items = model.windowed()
        saved = [sl.window for sl in items]
        try:  # windows that never move: each is its whole wire
            for sl in items:
                sl.window = (0, len(sl.element_start) - 1)
            rows, shift = st._rows(y, p, ca.MX.sym("mode", 0), part="rest")
        finally:
            for sl, window in zip(items, saved):
                sl.window = window
        self._rest = ca.Function("alpha_chunk_rest", [y, p], [rows, shift])
        self._rest_jacobian = None
        if expand:
            self._bulk, self._rest = merged(self._bulk.expand()), merged(self._rest.expand())
            expanded = self._bulk_jacobian.expand()
            if expanded.n_instructions() <= EXPANDED_JACOBIAN:
                self._bulk_jacobian = merged(expanded)
            # The rest's border in scalar operations, differentiated where its entries depend
            # on the unknowns: CasADi's derivative of a call in all directions would be the
            # rest's code as many times over as there are directions.
            y_s, p_s = self._rest.sx_in()
            rows_s, shift_s = self._rest(y_s, p_s)
            y_r = y_s[n_b:]
            self._rest_jacobian = merged(ca.Function("alpha_chunk_rest_jacobian", [y_s, p_s], [
                ca.jacobian(rows_s, y_r), ca.jacobian(rows_s[n_b:], y_s[:n_b]), ca.jacobian(shift_s[:n_b], y_r)]))

    # --- the step's functions -------------------------------------------------------------------
    def parts(self, y, p):
        """``(rest rows, shift)``."""
        return self._rest(y, p)

    def rows_and_shift(self, y, p):
        """The step's residual rows and the stabilization's shift ``G^T nu`` at ``(y, p)``."""
        rows, shift = self.parts(y, p)
        n_b = self.n_b
        if n_b:
            rows = rows + ca.vertcat(self._bulk(y[:n_b], p, shift[:n_b]), ca.MX(self.n_y - n_b, 1))
        return rows, shift

    def jacobian(self, y_b, y_r, p, wires: bool = True):
        """The iteration matrix at ``y = [y_b, y_r]`` (symbols: wires' coordinates and the
        rest's unknowns), see the module's notes; ``wires=False``: its wires' block zero (for
        a refactorization of the border only)."""
        n_b, n_u = self.n_b, self.n_u
        y = ca.vertcat(y_b, y_r)
        if self._rest_jacobian is not None:
            j_cols, j_rows, d_shift = self._rest_jacobian(y, p)
        else:
            rows, shift = self.parts(y, p)
            j_cols, j_rows, d_shift = (ca.jacobian(rows, y_r), ca.jacobian(rows[n_b:], y_b),
                                       ca.jacobian(shift[:n_b], y_r))
        if not n_b:
            return j_cols
        shift = self.parts(y, p)[1]
        j_bb = self._bulk_jacobian(y_b, p, shift[:n_b]) if wires else ca.MX(n_b, n_b)
        # the wires' rows through the stabilization's shift of their accelerations:
        # -(c_m M + gamma h C) d shift / d y_r, with the constant mass and Rayleigh matrices
        *_, gh, cm = step_data(p, n_u)
        bulk = self.st.bulk
        through_shift = -(cm * ca.mtimes(_dm(bulk.mass_matrix), d_shift) + gh * ca.mtimes(_dm(bulk.rayleigh), d_shift))
        return ca.blockcat([[j_bb, j_cols[:n_b, :] + through_shift], [j_rows, j_cols[n_b:, :]]])


def _dm(matrix) -> ca.DM:
    """A SciPy sparse matrix as a CasADi DM (same pattern)."""
    m = matrix.tocsc()
    return ca.DM(ca.Sparsity(m.shape[0], m.shape[1], m.indptr.tolist(), m.indices.tolist()), m.data.tolist())
