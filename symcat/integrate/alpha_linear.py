"""The linear solve of a generalized-alpha step's modified Newton iteration
(:mod:`.alpha_newton`) over the step equations of :mod:`.alpha_step`, whose module docstring
says why it is split so: the bulk matrix ``A`` (factorized once and kept) corrected by the
rest's exact Jacobian through a Woodbury (capacitance) update on the few unknowns it touches,
or, when the wires are not the larger part of the unknowns, the whole step matrix factorized
(sparse LU) and kept over steps with Broyden's secant updates."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..errors import SolverError
from .alpha_placement import weighted_sum
from .alpha_secant import Secants

#: Unknowns of the rest above which its capacitance is factorized sparse (a vehicle's bodies,
#: joints and contacts: hundreds of unknowns, a few nonzeros per row) instead of dense.
DENSE_CAPACITANCE = 200
#: A kept coupling (:meth:`StepSolve.keeps_coupling`) is prepared afresh after a step that
#: took more Newton iterations than this.
KEPT_ITERATIONS = 4
#: With the step matrix factorized whole (:attr:`.alpha_step.StepEquations.direct`) and kept
#: over steps, a step after one of more than this many iterations starts from an updated
#: matrix (see :data:`.alpha_newton.DIRECT_SLOW_CONTRACTION`).
DIRECT_KEPT_ITERATIONS = 5
#: SuperLU's options for the step matrix factorized whole: a symmetric ordering (the pattern is
#: structurally symmetric but for the constraints' rows: less fill than the default column
#: ordering, so faster solves) and threshold partial pivoting that keeps a diagonal pivot within
#: a factor 10 of its column's largest entry.
DIRECT_LU = {"permc_spec": "MMD_AT_PLUS_A", "diag_pivot_thresh": 0.1}

_GETRF, _GETRS = sla.get_lapack_funcs(("getrf", "getrs"), dtype=np.float64)
_SINGULAR = ("generalized-alpha: singular iteration matrix (redundant constraints, or a sliding joint at a point "
             "where its wire has no tangent?)")


class StepSolve:
    """The iteration matrix of one :class:`~.alpha_step.StepEquations` and its solves: the
    factorized bulk (held by the equations' :class:`~.alpha_bulk.Bulk`, carried over when a
    window moves), the rest's coupling prepared on it, and the secant updates of a step matrix
    factorized whole."""

    def __init__(self, equations):
        self.eq = equations
        self._coupling = None
        # (beta h^2, open flags) of a sparse capacitance that later steps may keep (see
        # :meth:`keeps_coupling`), else None.
        self._prepared = None
        self._secants = Secants(equations.n_y if equations.direct else 0)  # see secant()

    def clear(self) -> None:
        """Forget the prepared coupling and the secant updates (a new run)."""
        self._coupling, self._prepared = None, None
        self._secants.clear()

    def factorize(self, y, p) -> None:
        """Refactorize the bulk matrix at ``(y, p)`` and prepare the rest's coupling there."""
        eq = self.eq
        eq.scale_multipliers(y)
        if eq.direct:  # prepare factorizes everything
            eq.bulk.lu, eq.bulk.bh2 = True, float(p[3 * eq.n_u + 1])
        else:
            eq.bulk.set(y, p, eq._rest_values(y, p)[1])
        self.prepare(y, p)

    def prepare(self, y, p) -> None:
        """The Woodbury update of the rest's exact Jacobian at ``(y, p)``: the unknowns ``K`` it
        touches (every non-bulk unknown and the bulk ones in a nonzero row or column), the
        columns ``Z = P^-1 E_K`` (``P`` = bulk matrix, identity elsewhere), and the factorized
        capacitance ``I + Delta Z_K`` with ``Delta = J_rest[K, K] - I`` on the non-bulk part."""
        eq = self.eq
        if eq.direct:
            self._secants.clear()
            try:
                self._coupling = spla.splu(eq.jacobian(y, p), **DIRECT_LU)
            except RuntimeError:
                raise SolverError(_SINGULAR) from None
            eq.bulk.factorizations += 1
            self._prepared = (float(p[3 * eq.n_u + 1]), eq.mode.copy())
            return
        n_b, n_y = eq.bulk.n_b, eq.n_y
        placement, data = eq._rest_triplets(y, p)
        keys, flat, k = placement.touched(n_b)
        n_t = k - (n_y - n_b)
        touched = keys[:n_t]
        z_bulk = eq.bulk.columns(touched) if n_t else np.zeros((n_b, 0))
        if k > DENSE_CAPACITANCE:
            # Bodies with many coordinates (a vehicle on a line): the capacitance is the rest's
            # sparse Jacobian but for the block of the touched wire unknowns.
            delta = sps.csr_matrix((data, (flat // k, flat % k)), shape=(k, k))
            delta = (delta - sps.diags(np.r_[np.zeros(n_t), np.ones(k - n_t)])).tocsr()
            z_k = sps.block_diag([sps.csr_matrix(z_bulk[touched]), sps.identity(k - n_t)], format="csr")
            try:
                cap = spla.splu((sps.identity(k) + delta @ z_k).tocsc())
            except RuntimeError:
                raise SolverError(_SINGULAR) from None
            self._coupling = (keys, n_t, delta, z_bulk, cap)
            self._prepared = (float(p[3 * eq.n_u + 1]), eq.mode.copy())
            return
        delta = weighted_sum(flat, data, k * k).reshape(k, k)
        delta[n_t:, n_t:] -= np.eye(k - n_t)
        z_k = np.eye(k)
        if n_t:
            z_k[:n_t, :n_t] = z_bulk[touched]
        cap = None  # (nothing touched: solve() needs no capacitance)
        if k:  # LAPACK directly, as in solve(): lu_factor's checks cost as much as this small factorization
            lu, piv, info = _GETRF(np.eye(k) + delta @ z_k, overwrite_a=1)
            if info != 0:  # > 0: an exactly zero pivot (< 0, a wrong argument, cannot happen here)
                raise SolverError(_SINGULAR)
            cap = (lu, piv)
        self._coupling = (keys, n_t, delta, z_bulk, cap)
        self._prepared = None

    def secant(self, z: np.ndarray, step: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """The Newton update ``z = -H F(y)`` (``H`` the inverse iteration matrix, :meth:`solve`)
        after the update ``step`` made with the same ``H``, corrected by Broyden's secant update
        of ``H`` (:meth:`.alpha_secant.Secants.update`), kept for the later iterations and steps
        until the next factorization.

        With the step matrix factorized whole and kept over steps
        (:attr:`.alpha_step.StepEquations.direct`), what the kept matrix misses is mostly a few
        directions (on the seed's complete scene, the
        torsion of the wire's cross-sections near the contact, whose small stiffness turns a
        slight drift of their coupling terms into an overshooting update). A secant update
        learns them from the iterations themselves: fewer slow iterations and refactorizations."""
        return self._secants.update(z, step, weights) if self.eq.direct else z

    def keeps_coupling(self, p) -> bool:
        """Whether the next step may keep the rest's coupling prepared at an earlier step: a
        rest of many unknowns (:data:`DENSE_CAPACITANCE`, or a step matrix factorized whole: a
        vehicle's bodies and contacts, whose Jacobian and sparse factorization cost several
        residuals and change little from step to step), the same step size and open contacts,
        and a last step that converged in at most :data:`KEPT_ITERATIONS` iterations
        (:data:`DIRECT_KEPT_ITERATIONS` for a step matrix factorized whole). A rest of a few
        pantograph unknowns on a line is prepared every step: its contact crosses elements, and a kept coupling cost
        more iterations than it saved."""
        eq = self.eq
        most = DIRECT_KEPT_ITERATIONS if eq.direct else KEPT_ITERATIONS
        if self._prepared is None or eq.last_iterations > most:
            return False
        bh2, mode = self._prepared
        return bh2 == float(p[3 * eq.n_u + 1]) and np.array_equal(mode, eq.mode)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """``J^-1 rhs`` with ``J = P + E_K Delta E_K^T`` (Woodbury), or by the factorized ``J``
        and its secant updates (:meth:`secant`)."""
        if self.eq.direct:
            return self._secants.apply(self._coupling.solve(rhs))
        keys, n_t, delta, z_bulk, cap = self._coupling
        n_b = self.eq.bulk.n_b
        x = rhs.copy()
        x[:n_b] = self.eq.bulk.solve(rhs[:n_b])
        if not keys.size:  # wires only
            return x
        if isinstance(cap, spla.SuperLU):
            w = cap.solve(delta @ x[keys])
        else:  # LAPACK directly: lu_solve's checks cost as much as this small solve
            w = _GETRS(*cap, delta @ x[keys])[0]
        x[:n_b] -= z_bulk @ w[:n_t]
        x[n_b:] -= w[n_t:]
        return x
