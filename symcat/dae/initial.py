"""Consistent initial conditions by projection (not IDAS's own initial-condition solver).

Positions and arc lengths are projected onto ``C = 0`` by minimum-norm Gauss-Newton steps,
velocities onto ``C_q v + C_s w + C_t = 0`` by one minimum-norm correction (the arc lengths
and their rates weighted 1e-6 times less, so that they follow the bodies), and the
accelerations and multipliers solve the linear KKT system of the chosen formulation.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..assembly.sparse import to_scipy
from ..errors import SolverError
from .formulation import Formulation, normal_forces_numeric


def _terms_function(form: Formulation) -> ca.Function:
    """The terms of ``form`` as one function, built once per element window (a contact driver
    projects after every jump: building it took 40 ms each time on the vehicle) and kept for
    the next model of the same digest (:func:`~symcat.integrate.alpha_chunk_cache.model_memo`)."""
    from ..integrate.alpha_chunk_cache import model_memo

    key = tuple(sl.window for sl in form.model.windowed())
    cached = getattr(form, "_initial_terms", None)
    if cached is None or cached[0] != key:
        # (and once per process for models of one digest: a run's model is built anew)
        fn = model_memo(form.model, form, ("initial terms", key), lambda: _build_terms_function(form))
        cached = form._initial_terms = (key, fn)
    return cached[1]


def _build_terms_function(form: Formulation) -> ca.Function:
    n_f, n_s = form.n_f, form.n_s
    q, v, s, w, t = ca.MX.sym("q", n_f), ca.MX.sym("v", n_f), ca.MX.sym("s", n_s), ca.MX.sym("w", n_s), ca.MX.sym("t")
    sc = ca.MX.sym("sc", form.n_sc)
    k = form.terms(q, v, s, w, t, sc)
    names = ["C", "Cq", "Cs", "Ct", "Qd", "M", "Q", "T"]
    outs = [k[n] for n in names] + [ca.diag(ca.jacobian(k["T"], sc)) if form.n_sc else ca.MX(0, 1)]
    return ca.Function("terms", [q, v, s, w, t, sc], outs, ["q", "v", "s", "w", "t", "sc"], names + ["T_sc"])


def _kkt_pattern(form: Formulation, fn: ca.Function, closed) -> "KKTPattern":
    """The :class:`KKTPattern` of the terms function ``fn`` with the ``closed`` rows, kept on
    ``form`` (a contact driver makes the state consistent after every jump, with a few sets of
    closed rows; assembling the matrix by ``scipy.sparse.bmat`` cost ten times the factorization)."""
    cached = getattr(form, "_kkt_patterns", None)
    if cached is None or cached[0] is not fn:  # a new terms function (a window moved)
        cached = form._kkt_patterns = (fn, {})
    patterns, key = cached[1], closed.tobytes()
    if key not in patterns:
        patterns[key] = KKTPattern(fn.sparsity_out("M"), fn.sparsity_out("Cq"), fn.sparsity_out("Cs"), closed)
    return patterns[key]


def locate_contacts(fn: ca.Function, q, v, s, w, t, sc, tol: float = 1e-12, max_iterations: int = 50) -> np.ndarray:
    """Contact arc lengths solving the tangency conditions for given coordinates (scalar Newton
    per contact; each tangency depends on its own arc length only)."""
    sc = np.array(sc, dtype=float)
    for _ in range(max_iterations):
        out = fn(q, v, s, w, t, sc)
        res, slope = np.asarray(out[7]).ravel(), np.asarray(out[8]).ravel()
        if np.abs(res).max(initial=0.0) <= tol:
            return sc
        sc = sc - res / slope
    raise SolverError(f"the contact points could not be located on their wires (tangency residual {np.abs(res).max():.3g} m)")


def consistent_state(form: Formulation, t0: float = 0.0, tol: float = 1e-12, max_iterations: int = 30,
                     start: dict | None = None, positions: bool = True, open_rows=(), impulse: bool = False):
    """Consistent ``(x0, z0)`` for ``form`` at time ``t0`` from the scene's initial state, or from
    ``start = {"q", "v", "s", "w", "sc"}`` (internal free coordinates; e.g. after a contact jump).
    With ``positions=False`` the positions and arc lengths are kept as given (their constraint
    drift is left to the Baumgarte terms) and only velocities, accelerations and multipliers are
    made consistent. ``open_rows`` (model row numbers: the gap rows of lifted wheel/rail
    contacts, :meth:`Formulation.open_rows`) are left out, their multipliers zero. With
    ``impulse`` the velocities change by a plastic impact (``M dv = -C_q^T Lambda``: the
    mass-weighted least change) instead of the least change in coordinates.

    Raises
    ------
    SolverError
        Naming the joints involved when the constraints are redundant or cannot be satisfied.
    """
    model = form.model
    fn = _terms_function(form)
    q = form.to_internal(model.q0[model.free].copy())
    v = form.to_internal(model.v0[model.free].copy())
    s = model.s0.copy()
    w = np.zeros(form.n_s)
    sc = model.sc0.copy()
    if start is not None:
        q, v, s, w, sc = (np.array(start[k], float) for k in ("q", "v", "s", "w", "sc"))
    closed = np.setdiff1d(np.arange(form.n_c), np.asarray(open_rows, int))
    names = [model.row_names[r] for r in closed]
    n_f = form.n_f

    raw = {}  # the last evaluation's M, C_q, C_s (casadi, all rows), for the KKT pattern

    def evaluate(q, v, s, w):
        """The closed rows' terms."""
        out = fn(q, v, s, w, t0, sc)
        c, cq, cs, ct, qd, m, f = out[:7]
        raw.update(m=m, cq=cq, cs=cs)
        cq = to_scipy(ca.DM(cq)).tocsr()[closed].tocsc()
        cs = np.asarray(ca.densify(cs))[closed]
        return (np.asarray(c).ravel()[closed], sps.hstack([cq, sps.csc_matrix(cs)]).tocsc(),
                np.asarray(ct).ravel()[closed], np.asarray(qd).ravel()[closed], to_scipy(m), np.asarray(f).ravel(),
                cq, cs)

    # The arc lengths are not generalized coordinates: they move first (a tiny weight), so a
    # body keeps its given position and velocity and s follows it.
    w_inv = sps.diags(np.r_[np.ones(n_f), np.full(form.n_s, 1e6)])
    if closed.size:
        terms = evaluate(q, v, s, w)
        c, jac = terms[:2]
        _check_rank(jac, names)
        scale = 1.0 + np.abs(np.r_[q, s]).max(initial=0.0)
        for _ in range(max_iterations):
            if not positions or np.abs(c).max() <= tol * scale:
                break
            u = np.r_[q, s] - w_inv @ (jac.T @ _solve(jac @ w_inv @ jac.T, c))
            q, s = u[:n_f], u[n_f:]
            terms = evaluate(q, v, s, w)
            c, jac = terms[:2]
        else:
            worst = int(np.argmax(np.abs(c)))
            raise SolverError(
                f"initial conditions cannot be made consistent: after {max_iterations} projections the "
                f"constraint {names[worst]} is still violated by {c[worst]:.3g}; check the joint positions"
            )
        c, jac, ct, _, m, _, cq, cs = terms  # at the final q, s (the velocities have not moved yet)
        if impulse:
            dv, w, _ = kkt_solve(m, np.zeros(n_f), cq, cs, cq @ v + ct)
            v = v + dv
        else:
            u_dot = np.r_[v, w]
            u_dot -= w_inv @ (jac.T @ _solve(jac @ w_inv @ jac.T, jac @ u_dot + ct))
            v, w = u_dot[:n_f], u_dot[n_f:]
    if form.n_sc:
        sc = locate_contacts(fn, q, v, s, w, t0, sc)
    c, jac, ct, qd, m, f, cq, cs = evaluate(q, v, s, w)
    xb, zb = form.blocks()
    x0 = np.zeros(sum(b.size for b in xb.values()))
    z0 = np.zeros(sum(b.size for b in zb.values()))
    creep = CreepCoupling(form, q, v, s, w)
    if form.formulation == "augmented":
        # One factorization for every creep pass, the matrix assembled by the pattern's index maps.
        solve = _kkt_pattern(form, fn, closed).solver(*(np.asarray(raw[k].nonzeros()) for k in ("m", "cq", "cs")))
        a, s_dd, lam = creep.solve(lambda force: solve(force, qd), f)
        values_x = {"q": q, "s": s, "v": v, "w": w}
        values_z = {"a": a, "s_dd": s_dd, "w": w, "lambda": lam, "mu": np.zeros(form.n_c), "sc": sc}
    else:
        # Positions among the closed rows (the tangency rows never open).
        at = {r: i for i, r in enumerate(closed)}
        tr = [at[r] for r in form.rows_t]
        rr = [at[r] for r in form.rows_r if r in at]
        cq_d = cq.toarray() if form.n_s else cq
        if form.n_s:
            both = np.linalg.solve(cs[tr], np.c_[cq_d[tr], qd[tr]])
            h = sps.csc_matrix(cq_d[rr] - cs[rr] @ both[:, :-1])
            q_cn = qd[rr] - cs[rr] @ both[:, -1]
        else:
            h, q_cn = cq, qd
        kkt = sps.bmat([[m, h.T], [h, None]], format="csc")
        def embedded(force):
            sol = _solve(kkt, np.r_[force, -q_cn])
            lam = np.zeros(form.n_c)
            lam[closed[rr]] = sol[n_f:]
            return sol, lam[form.rows_r]

        sol, lam = creep.solve(embedded, f)
        values_x = {"q": q, "v": v}
        values_z = {"a": sol[:n_f], "s": s, "lambda": lam, "mu": np.zeros(len(form.rows_r)), "sc": sc}
    for name, b in xb.items():
        x0[b.slice] = values_x[name]
    for name, b in zb.items():
        z0[b.slice] = values_z[name]
    return x0, z0


class CreepCoupling:
    """Creep forces depend on the normal forces, which are multipliers: a fixed-point iteration
    over the linear solve ``solve(force) -> (..., multipliers)`` (creep forces are small against
    the normal forces and, for the linear law, independent of them: two or three passes)."""

    def __init__(self, form: Formulation, q, v, s, w):
        from ..assembly.wheelrail import has_creep

        self.active = has_creep(form.model)
        if self.active:
            # The multipliers of solve() are in the form's own layout.
            weights = np.asarray(form.normal_direction_function()(q, s)).ravel()
            rows = form.normal_force_rows()
            self.normal = lambda lam: normal_forces_numeric(weights, np.asarray(lam).ravel(), rows)
            fn = form.creep_function()
            self.force = lambda normal: np.asarray(fn(q, v, s, w, normal)[0]).ravel()

    def solve(self, solve, f, tol: float = 1e-10, max_iterations: int = 50):
        out = solve(f)
        if not self.active:
            return out
        normal = self.normal(out[-1])
        for _ in range(max_iterations):
            out = solve(f + self.force(normal))
            new = self.normal(out[-1])
            if _settled(new, normal, tol):
                return out
            normal = new
        raise _unsettled(max_iterations, new)


def settle_creep(solves, f, creep_force, normal_of, tol: float = 1e-10, max_iterations: int = 50) -> list:
    """:meth:`CreepCoupling.solve` for many states at once, the creep forces of all of them
    evaluated in one call per pass; each state takes the passes it would take alone (the same
    results).

    Parameters
    ----------
    solves : list of callables
        ``solves[i](force) -> (..., multipliers)``: the linear solve of state ``i``.
    f : ndarray (n, n_f)
        The forces without creep.
    creep_force : callable
        ``creep_force(normal) -> (n, n_f)``: the creep forces of every state for its normal
        forces ``normal`` (n, n_w).
    normal_of : callable
        ``normal_of(i, multipliers) -> (n_w,)``: the normal forces of state ``i``.
    tol, max_iterations
        As for :meth:`CreepCoupling.solve`.

    Returns
    -------
    list
        The last ``solves[i]`` output of every state.

    Raises
    ------
    SolverError
        If a state's normal forces do not settle.
    """
    outs = [solve(fi) for solve, fi in zip(solves, f)]
    normal = np.array([normal_of(i, out[-1]) for i, out in enumerate(outs)]).reshape(len(outs), -1)
    pending = list(range(len(outs)))
    for _ in range(max_iterations):
        if not pending:
            break
        force = creep_force(normal)  # every state in one call; the settled ones' are not used
        still = []
        for i in pending:
            outs[i] = solves[i](f[i] + force[i])
            new = normal_of(i, outs[i][-1])
            if not _settled(new, normal[i], tol):
                still.append(i)
            normal[i] = new
        pending = still
    if pending:
        raise _unsettled(max_iterations, normal[pending[0]])
    return outs


def _settled(new, normal, tol) -> bool:
    """Normal forces that a creep pass no longer changes (relative ``tol``)."""
    return np.abs(new - normal).max(initial=0.0) <= tol * (1.0 + np.abs(new).max(initial=0.0))


def _unsettled(max_iterations, normal) -> SolverError:
    return SolverError(f"creep forces and normal forces did not settle in {max_iterations} passes "
                       f"(normal forces {np.array2string(normal, precision=4)} N)")


def kkt_solve_closed(m, f, cq, cs, qd, closed, n_c: int):
    """:func:`kkt_solve` with only the ``closed`` constraint rows (``cq``, ``cs``, ``qd`` are
    theirs); the multipliers come back for all ``n_c`` rows, zero on the open ones (lifted-off
    wheel/rail contacts carry no force)."""
    return kkt_solver_closed(m, cq, cs, closed, n_c)(f, qd)


def kkt_solver_closed(m, cq, cs, closed, n_c: int):
    """``solve(f, qd)`` of :func:`kkt_solve_closed`, the matrix factorized once (the creep
    passes of :class:`CreepCoupling` change the forces only)."""
    return _all_rows(kkt_solver(m, cq, cs), closed, n_c)


def _all_rows(solve, closed, n_c: int):
    """``solve`` with the multipliers of the ``closed`` rows spread over all ``n_c`` (zero on
    the open ones)."""

    def solve_closed(f, qd):
        a, s_dd, lam_closed = solve(f, qd)
        lam = np.zeros(n_c)
        lam[closed] = lam_closed
        return a, s_dd, lam

    return solve_closed


class KKTPattern:
    """The matrix of :func:`kkt_solver_closed` assembled from nonzeros by fixed index maps: for
    many states with the same sparsity patterns of ``M``, ``C_q``, ``C_s`` and the same closed
    rows (``scipy.sparse.bmat`` per state costs ten times the factorization).

    Parameters
    ----------
    m, cq, cs : casadi.Sparsity
        Patterns of the mass matrix (n_f x n_f) and of ``C_q`` (n_c x n_f) and ``C_s``
        (n_c x n_s) over all constraint rows.
    closed : ndarray of int
        The closed rows (:func:`kkt_solver_closed`).
    """

    def __init__(self, m: ca.Sparsity, cq: ca.Sparsity, cs: ca.Sparsity, closed):
        self.n_f, self.n_s, self.n_c = m.size1(), cs.size2(), cq.size1()
        self.closed = np.asarray(closed, int)
        at = np.full(self.n_c, -1)
        at[self.closed] = np.arange(self.closed.size)
        off = self.n_f + self.n_s  # first constraint row of the KKT matrix
        m_r, m_c = (np.asarray(x, int) for x in m.get_triplet())
        cq_r, cq_c = (np.asarray(x, int) for x in cq.get_triplet())
        cs_r, cs_c = (np.asarray(x, int) for x in cs.get_triplet())
        cq_k, cs_k = np.flatnonzero(at[cq_r] >= 0), np.flatnonzero(at[cs_r] >= 0)
        # Entries: M; C_q^T and C_q; C_s^T and C_s (closed rows), as positions in the stacked
        # nonzeros [M, C_q, C_s].
        rows = np.r_[m_r, cq_c[cq_k], off + at[cq_r[cq_k]], self.n_f + cs_c[cs_k], off + at[cs_r[cs_k]]]
        cols = np.r_[m_c, off + at[cq_r[cq_k]], cq_c[cq_k], off + at[cs_r[cs_k]], self.n_f + cs_c[cs_k]]
        n_m, n_cq = m.nnz(), cq.nnz()
        source = np.r_[np.arange(n_m), n_m + cq_k, n_m + cq_k, n_m + n_cq + cs_k, n_m + n_cq + cs_k]
        order = np.lexsort((rows, cols))  # CSC: by column, rows ascending
        self.size = off + self.closed.size
        self._source, self._rows, self._cols = source[order], rows[order].astype(np.int32), cols[order]
        self._indptr = self._column_starts(self._cols)
        # C_s enters as a dense block in kkt_solver: its exact zeros are no entries.
        self._from_cs = np.flatnonzero(self._source >= n_m + n_cq)

    def solver(self, m_nz, cq_nz, cs_nz):
        """``solve(f, qd) -> (a, s_dd, lam)`` of :func:`kkt_solver_closed` (``qd`` of the closed
        rows, ``lam`` over all rows) from the nonzeros of ``M``, ``C_q`` and ``C_s`` in their
        patterns' order; the same matrix, hence the same factorization."""
        data = np.concatenate((m_nz, cq_nz, cs_nz))[self._source]
        rows, indptr = self._rows, self._indptr
        zeros = self._from_cs[data[self._from_cs] == 0.0]
        if zeros.size:
            keep = np.ones(data.size, bool)
            keep[zeros] = False
            data, rows, indptr = data[keep], rows[keep], self._column_starts(self._cols[keep])
        kkt = sps.csc_matrix((data, rows, indptr), shape=(self.size, self.size))
        return _all_rows(_lu_solver(kkt, self.n_f, self.n_s), self.closed, self.n_c)

    def _column_starts(self, cols: np.ndarray) -> np.ndarray:
        """CSC ``indptr`` of entries in columns ``cols`` (sorted)."""
        return np.concatenate(([0], np.cumsum(np.bincount(cols, minlength=self.size)))).astype(np.int32)


def kkt_solve(m, f, cq, cs, qd):
    """Accelerations, arc-length accelerations and multipliers of the augmented form (eq. 25)
    for a consistent state: ``[[M, 0, C_q^T], [0, 0, C_s^T], [C_q, C_s, 0]]``."""
    return kkt_solver(m, cq, cs)(f, qd)


def kkt_solver(m, cq, cs):
    """``solve(f, qd) -> (a, s_dd, lam)`` of :func:`kkt_solve`, with one LU factorization."""
    n_f, n_s = m.shape[0], cs.shape[1]
    kkt = sps.bmat([[m, None, cq.T], [None, sps.csc_matrix((n_s, n_s)), sps.csc_matrix(cs.T)],
                    [cq, sps.csc_matrix(cs), None]], format="csc")
    return _lu_solver(kkt, n_f, n_s)


def _lu_solver(kkt: sps.csc_matrix, n_f: int, n_s: int):
    """``solve(f, qd) -> (a, s_dd, lam)`` for the KKT matrix of :func:`kkt_solver`."""
    try:
        lu = spla.splu(kkt) if kkt.shape[0] else None
    except RuntimeError:  # exactly singular: _solve's message
        lu = None

    def solve(f, qd):
        b = np.concatenate((f, np.zeros(n_s), -np.asarray(qd)))
        if lu is None:
            sol = _solve(kkt, b)
        else:
            with np.errstate(all="ignore"):
                sol = np.atleast_1d(lu.solve(b))
            if not np.all(np.isfinite(sol)):
                raise SolverError("singular system while making the initial conditions consistent (redundant "
                                  "constraints?)")
        return sol[:n_f], sol[n_f : n_f + n_s], sol[n_f + n_s :]

    return solve


def _solve(a: sps.spmatrix, b: np.ndarray) -> np.ndarray:
    if a.shape[0] == 0:
        return np.zeros(0)
    with np.errstate(all="ignore"):
        x = spla.spsolve(sps.csc_matrix(a), b)
    if not np.all(np.isfinite(x)):
        raise SolverError("singular system while making the initial conditions consistent (redundant constraints?)")
    return np.atleast_1d(x)


def _check_rank(jac: sps.spmatrix, names: list[str]) -> None:
    """Raise naming the constraints that are redundant at the initial state."""
    n_c = jac.shape[0]
    if n_c == 0 or n_c > 3000:
        return
    dense = jac.toarray()
    _, r, piv = sla.qr(dense.T, pivoting=True, mode="economic")
    diag = np.abs(np.diag(r))
    tol = max(dense.shape) * np.finfo(float).eps * (diag[0] if diag.size else 1.0) * 1e3
    rank = int(np.sum(diag > tol))
    if rank < n_c:
        dependent = sorted({names[i].split("[")[0] for i in piv[rank:]})
        raise SolverError(
            f"redundant or inconsistent constraints at the initial state: the Jacobian has rank {rank} "
            f"for {n_c} equations; look at {', '.join(dependent)} (a joint that repeats what others impose)"
        )
