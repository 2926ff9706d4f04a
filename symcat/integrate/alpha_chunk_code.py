"""The code of the compiled generalized-alpha steps (:mod:`.alpha_chunk`): the steps of a
run, many per call, as CasADi functions for C (:func:`chunk_functions`), and the packed state
they carry from call to call.

A call holds one call of the step per step, a loop of calls (CasADi's ``mapaccum`` would copy
the inputs common to the steps once per step, which cost more than the steps). A step is the
Python step's (:mod:`.alpha_newton`): predictor, modified Newton iterations on the scaled
residual of :class:`.alpha_chunk_residual.ChunkResidual` with the kept factor of its iteration
matrix (:class:`.bordered_band.BorderedBand`), renewed at its border then whole when the
iteration contracts slowly, the same convergence test."""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..codegen.band_c import store_function
from .alpha_bulk import step_data
from .alpha_chunk_residual import ChunkResidual
from .alpha_step import StepEquations
from .bordered_band import step_layout

#: The compiled calls' lengths in steps (the code holds one call of the step per step; a call
#: takes the shortest that covers an output interval and skips the steps past it, so one
#: library serves every step size and output interval; a skipped step still copies the state).
LENGTHS = (1, 2, 4, 8, 16, 32)
MAX_STEPS = LENGTHS[-1]
#: Newton iterations of a compiled step before it counts as failed (the iteration matrix is
#: factorized afresh at most :data:`ROUNDS` - 1 times in a step).
MAX_ITERATIONS = 18
ROUNDS = 3
def packed_cuts(n_u: int, n_c: int, n_sc: int) -> list[int]:
    """Where the packed state's parts start: ``u v v_dot a lam sc a_prev lam_prev sc_prev``,
    then ``h`` and the failed flag (one entry each)."""
    return np.cumsum([0, n_u, n_u, n_u, n_u, n_c, n_sc, n_u, n_c, n_sc, 1, 1]).tolist()



def chunk_functions(st: StepEquations, coef) -> list:
    """``alpha_chunk_<per>(x0, t (per), h, n, factor, renew, scale) -> (x, iterations (per),
    factorizations)`` for each ``per`` of :data:`LENGTHS`: up to ``n`` steps of ``h`` from the
    packed state ``x0`` at the times ``t``, with the iteration matrix's ``factor`` (``renew``:
    made at the first step's predictor, by ``alpha_chunk_renew``); ``x`` is the state after
    the last step that converged; a step's iterations are 0 (not taken: past ``n`` or after a
    failure) or -1 (failed). ``factor`` is the caller's memory, read where it is and renewed
    in place (:func:`~symcat.codegen.band_c.store_function`): after the call it holds the
    factor the steps ended with, the next call's. Then ``alpha_chunk_renew(x0, t0, h) ->
    factor``: the matrix at the predictor of the step from ``x0`` at ``t0``, which the caller
    runs, into the same memory, before a call that renews it. ``alpha_chunk_recorded_<per>``:
    the same with a fourth output, each step's record (:func:`_record_function`, one column per
    step), for a monitored run (its own functions: the records cost a copy of the state per
    step, which an unmonitored run does not pay)."""
    n_u, n_c, n_sc, n_y = st.n_u, st.n_c, st.n_sc, st.n_y
    n_x = 5 * n_u + 2 * (n_c + n_sc) + 2
    y, p = ca.MX.sym("y", n_y), ca.MX.sym("p", 3 * n_u + 4)
    # The wires' and the rest's functions expanded to scalar operations, shared subexpressions
    # merged: as MX graphs their code spends most of its time on sparse bookkeeping.
    residual = ChunkResidual(st, expand=True)
    rows, shift = residual.rows_and_shift(y, p)
    rows_of = ca.Function("alpha_chunk_rows", [y, p], [rows])
    shift_of = ca.Function("alpha_chunk_shift", [y, p], [shift]) if st.variant == "stabilized" and n_c else None
    y_b, y_r = ca.MX.sym("y_b", st.bulk.n_b), ca.MX.sym("y_r", n_y - st.bulk.n_b)
    jacobian = ca.Function("alpha_chunk_jacobian", [y_b, y_r, p], [residual.jacobian(y_b, y_r, p)])
    layout = step_layout(st, residual.couplings())
    jacobian_border = ca.Function("alpha_chunk_jacobian_border", [y_b, y_r, p],
                                  [residual.jacobian(y_b, y_r, p, wires=False)])
    jac = ca.project(jacobian(y[: st.bulk.n_b], y[st.bulk.n_b :], p), layout.pattern)
    # The factor's memory is an input the caller owns (read in place, renewed by stores into
    # it, never copied); the token of its last store orders the functions that read it after
    # that store (see band_c.store_function).
    factor, token = ca.MX.sym("factor", layout.size), ca.MX.sym("token")
    factorization = ca.Function("alpha_chunk_factorization", [y, p], [layout.factorize(_nonzeros(jac))])
    store = store_function(layout.size, 0, layout.size)
    factorize = ca.Function("alpha_chunk_factorize", [y, p, factor, token], [store(factor, factorization(y, p))])
    keep_factor = ca.Function("alpha_chunk_keep_factor", [y, p, factor, token], [token])
    refresh = ca.Function.if_else("alpha_chunk_refresh", factorize, keep_factor)
    # the border alone (bodies, joints, contacts: what moves with a point), the band's LU kept
    border = layout.n_r > 0
    if border:
        jac_border = ca.project(jacobian_border(y[: st.bulk.n_b], y[st.bulk.n_b :], p), layout.pattern)
        store_border = store_function(layout.size, layout.band_entries, layout.size - layout.band_entries)
        refactorize_border = ca.Function("alpha_chunk_border", [y, p, factor, token],
                                         [store_border(factor, layout.border(factor, _nonzeros(jac_border)))])
        refresh_border = ca.Function.if_else("alpha_chunk_refresh_border", refactorize_border, keep_factor)
    rhs = ca.MX.sym("rhs", n_y)
    solve = ca.Function("alpha_chunk_solve", [factor, rhs], [layout.solve(factor, rhs)])

    # The step's predictor: (packed state, t0, h) -> (y, p)
    xk, t0, h = ca.MX.sym("x", n_x), ca.MX.sym("t0"), ca.MX.sym("h")
    parts = ca.vertsplit(xk, packed_cuts(n_u, n_c, n_sc))
    u, v, v_dot, a, lam, sc, a_prev, lam_prev, sc_prev, h_prev, _ = parts
    c = coef
    bh2 = c.beta * h * h
    p_k = ca.vertcat(u + h * v + h * h * (0.5 - c.beta) * a, v + h * (1 - c.gamma) * a,
                     (c.alpha_m * a - c.alpha_f * v_dot) / (1 - c.alpha_f), t0 + h, bh2, c.gamma * h,
                     (1 - c.alpha_m) / (1 - c.alpha_f))
    ratio = h / h_prev
    y_k = ca.vertcat(p_k[:n_u] + bh2 * (a + ratio * (a - a_prev)), bh2 * (lam + ratio * (lam - lam_prev)),
                     ca.MX(n_y - n_u - n_c - n_sc, 1), sc + ratio * (sc - sc_prev))
    predictor = ca.Function("alpha_chunk_predictor", [xk, t0, h], [y_k, p_k])
    # the matrix afresh at a step's predictor (run by the caller before a call that renews it)
    renew_matrix = ca.Function("alpha_chunk_renew", [xk, t0, h], [factorization(y_k, p_k)])

    # One Newton iteration: (y, previous error, status, count, fresh) -> (y, error, status,
    # count); status 0 running, 1 converged, 2 failed, 3 slow (wants a fresh matrix): the
    # tests of solve_step. fresh: the matrix was factorized in this step. scale: the Newton
    # tolerance of each unknown, then the contraction above which the iteration is slow.
    scale = ca.MX.sym("scale", n_y + 1)
    prev, status, count, fresh = ca.MX.sym("prev"), ca.MX.sym("status"), ca.MX.sym("count"), ca.MX.sym("fresh")
    dy = -solve(factor, rows_of(y, p))
    err = ca.mmax(ca.fabs(dy / scale[:n_y]))
    theta = ca.if_else(prev > 0, err / prev, 0)
    finite = err < np.inf
    converged = ca.logic_and(finite, ca.logic_or(
        ca.logic_and(ca.logic_and(err <= 1, theta < 1), theta / ca.fmax(1 - theta, 1e-300) * err <= 1), err <= 1e-3))
    slow = ca.logic_and(prev > 0, theta > scale[n_y])
    diverging = ca.logic_and(fresh > 0, theta >= 1)  # on a fresh matrix: the step fails
    failed = ca.logic_or(ca.logic_or(ca.logic_not(finite), ca.logic_and(slow, diverging)),
                         count + 1 >= MAX_ITERATIONS)
    new_status = ca.if_else(converged, 1, ca.if_else(failed, 2, ca.if_else(slow, 3, 0)))
    args = [y, prev, status, count, fresh, p, scale, factor, token]
    iterate = ca.Function("alpha_chunk_iteration", args, [y + dy, err, new_status, count + 1])
    keep = ca.Function("alpha_chunk_keep", args, [y, prev, status, count])
    newton = ca.Function.if_else("alpha_chunk_newton", keep, iterate)
    # One step: (packed state, factor, token, (renew,) t0, h, scale) -> (state, token,
    # iterations, factorizations); renew: the factor was made at this step's predictor (the
    # first step's input; the later steps' is 0). A call's arguments are never constants:
    # CasADi's call of a function on a line's sizes with a constant argument takes tens of
    # milliseconds, each of the hundreds of calls here.
    def step_function(first: bool) -> ca.Function:
        xk, t0, h = ca.MX.sym("x", n_x), ca.MX.sym("t0"), ca.MX.sym("h")
        scale = ca.MX.sym("scale", n_y + ROUNDS)  # then per round the contraction that is slow
        renew = ca.MX.sym("renew")
        parts = ca.vertsplit(xk, packed_cuts(n_u, n_c, n_sc))
        u, v, v_dot, a, lam, sc, a_prev, lam_prev, sc_prev, h_prev, was_failed = parts
        bh2 = coef.beta * h * h
        y_k, p_k = predictor(xk, t0, h)
        active = was_failed == 0  # (a step past the call's steps is skipped, see below)
        fr = ca.logic_and(active, renew) if first else ca.MX(0)
        e, stat, cnt = ca.MX(0), ca.if_else(active, 0, 1), ca.MX(0)  # an inactive step: "converged" untouched
        tk, factorizations = token, ca.MX(0)
        for round_ in range(ROUNDS):
            round_scale = ca.vertcat(scale[:n_y], scale[n_y + round_])
            for _ in range(MAX_ITERATIONS // ROUNDS):
                y_k, e, stat, cnt = newton(stat != 0, y_k, e, stat, cnt, fr, p_k, round_scale, factor, tk)
            wanted = stat == 3
            if round_ == ROUNDS - 1:
                continue
            # slow: the border afresh at the current iterate first, then the whole matrix
            if border and round_ == 0:
                tk = refresh_border(wanted, y_k, p_k, factor, tk)
            else:
                tk = refresh(wanted, y_k, p_k, factor, tk)
                fr, factorizations = ca.logic_or(fr, wanted), factorizations + wanted
            stat, e = ca.if_else(wanted, 0, stat), ca.if_else(wanted, 0, e)
        ok = ca.logic_and(active, stat == 1)
        u_pred, v_pred, b, _, _, gh, cm = step_data(p_k, n_u)
        a_new = (y_k[:n_u] - u_pred - (shift_of(y_k, p_k) if shift_of is not None else 0)) / bh2
        stepped = ca.vertcat(y_k[:n_u], v_pred + gh * a_new, cm * a_new + b, a_new, y_k[n_u : n_u + n_c] / bh2,
                             y_k[n_y - n_sc :], a, lam, sc, h, 0)
        new_x = ca.if_else(ok, stepped, ca.vertcat(xk[:-1], ca.logic_or(was_failed, active)))
        iterations = ca.if_else(ok, cnt, ca.if_else(active, -1, 0))
        inputs = [xk, factor, token] + ([renew] if first else []) + [t0, h, scale]
        name = "alpha_chunk_step" + ("_first" if first else "")
        step = ca.Function(name, inputs, [new_x, tk, iterations, factorizations])
        skip = ca.Function(name + "_skip", inputs, [xk, token, 0, 0])
        return ca.Function.if_else(name + "_or_skip", step, skip)

    first_step, step = step_function(True), step_function(False)
    record = _record_function(residual, n_u, n_c, n_sc, n_y)
    # A loop of calls, not mapaccum: its code copies the inputs common to the steps once per
    # step, which cost more than the steps.
    functions = []
    h, n, renew, scale = ca.MX.sym("h"), ca.MX.sym("n"), ca.MX.sym("renew"), ca.MX.sym("scale", n_y + ROUNDS)
    for recorded in (False, True):
        for per in LENGTHS:
            x0, times = ca.MX.sym("x0", n_x), ca.MX.sym("t", per)
            # (the first token: any input, no store precedes the first step)
            x, tk, counts, total, records = x0, h, [], 0, []
            for k in range(per):  # a failed step leaves the state as it was: x is the last good one
                if k == 0:
                    x, tk, count, fk = first_step(k < n, x, factor, tk, renew, times[k], h, scale)
                else:
                    x, tk, count, fk = step(k < n, x, factor, tk, times[k], h, scale)
                counts.append(count)
                total += fk
                if recorded:
                    records.append(record(x, times[k] + h))
            outputs = [x, ca.vertcat(*counts), total] + ([ca.horzcat(*records)] if recorded else [])
            name = f"alpha_chunk_{'recorded_' if recorded else ''}{per}"
            functions.append(ca.Function(name, [x0, times, h, n, factor, renew, scale], outputs))
    return functions + [renew_matrix]


def _record_function(residual: ChunkResidual, n_u: int, n_c: int, n_sc: int, n_y: int) -> ca.Function:
    """``alpha_chunk_record(x, t) -> [u, v, v_dot, lam, sc, gap, force]``: what a monitored
    run records of the packed state ``x`` at time ``t`` (:meth:`CompiledSteps.advance`), the
    penalty contacts' gaps and forces as :meth:`.alpha_step.StepEquations.contacts` has them
    (the rest at ``y = [u, 0, sc]``, step data whose velocity is ``v``)."""
    x, t = ca.MX.sym("x", 5 * n_u + 2 * (n_c + n_sc) + 2), ca.MX.sym("t")
    u, v, v_dot, _, lam, sc = ca.vertsplit(x, packed_cuts(n_u, n_c, n_sc))[:6]
    contacts = []
    if n_sc:
        # (dense: the proxies pick their elements from them by parametric indices)
        y = ca.vertcat(u, ca.MX.zeros(n_y - n_u - n_sc, 1), sc)
        p = ca.vertcat(u, v, ca.MX.zeros(n_u, 1), t, 1, 1, 1)
        contacts = [ca.densify(c) for c in residual.contacts(y, p)]
    return ca.Function("alpha_chunk_record", [x, t], [ca.densify(ca.vertcat(u, v, v_dot, lam, sc, *contacts))])


def record_size(n_u: int, n_c: int, n_sc: int) -> int:
    """Numbers a compiled step records per step (:func:`_record_function`)."""
    return 3 * n_u + n_c + 3 * n_sc


def _nonzeros(m: ca.MX) -> ca.MX:
    """The nonzeros of ``m`` as a column (in its CCS order)."""
    return ca.sparsity_cast(m, ca.Sparsity.dense(m.nnz(), 1))
