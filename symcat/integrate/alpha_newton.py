"""The modified Newton iteration of one generalized-alpha step (:func:`solve_step`) over its
equations and linear solve (:class:`.alpha_step.StepEquations`): when it updates its matrix,
when it has converged, when it has failed."""
from __future__ import annotations

import numpy as np

from .alpha_step import StepEquations

#: A Newton iteration that contracts by less than this per iteration updates its matrix.
SLOW_CONTRACTION = 0.3
#: With the step matrix factorized whole (:attr:`.alpha_step.StepEquations.direct`) and kept
#: over steps, an update of the matrix (the rest's Jacobian and a sparse LU) costs as much as
#: some ten iterations: the iteration updates its matrix when it contracts by less than
#: ``DIRECT_SLOW_CONTRACTION`` from its third update on, or when its second update exceeds its
#: first by ``DIRECT_FIRST_CONTRACTION``. The first ratio is no measure of the rate: an error of
#: the kept matrix in a soft direction (the torsion of a beam3d wire's cross-sections under the
#: contact) shows as an overshoot in the first update that the second undoes, after which the
#: iteration converges fast.
DIRECT_SLOW_CONTRACTION = 0.5
DIRECT_FIRST_CONTRACTION = 1.0


def solve_step(st: StepEquations, y0, p, tol, max_iterations, stats, refreshed: bool = False):
    """Modified Newton iteration of one step from the predictor ``y0`` (with ``nu`` from the
    last steps, :meth:`.alpha_step.StepEquations.start`), with the bulk matrix kept and the rest's exact
    Jacobian at the predictor: when the iteration contracts by less than
    :data:`SLOW_CONTRACTION` per iteration the rest is re-evaluated at the current iterate,
    the second time the bulk is refactorized there (a step matrix factorized whole: kept over
    steps with secant updates, and updated by the thresholds of :data:`DIRECT_SLOW_CONTRACTION`).
    Converged when the last update, with the
    remaining error estimated from the contraction rate, is below ``tol``: an absolute
    tolerance on the coordinates and contact arc lengths (m, or the dimensionless slopes and
    Euler parameters), so that it means the same anywhere along a line (a tolerance relative to
    ``|u|`` would be 100 times looser 100 m down the line than at its start); the scaled
    multipliers ``beta h^2 lambda`` count as the position change ``beta h^2 lambda / m`` they
    cause on a mass ``m`` (the mean diagonal of ``M``), and ``nu`` as a position change.
    Returns ``(y, a, v, v_dot)`` or None."""
    n_u, n_c = st.n_u, st.n_c
    y = st.start(y0, p, tol).copy()
    bh2 = float(p[3 * n_u + 1])
    fresh = refreshed
    if not st.bulk.valid_for(bh2) or st.mass_scale is None:
        st.linear.factorize(y, p)
        fresh = True
    elif not refreshed and not st.linear.keeps_coupling(p):
        st.linear.prepare(y, p)
    scale = np.full_like(y, tol)
    scale[n_u : n_u + n_c] = tol * st.mass_scale
    weights = scale**-2
    # the contraction below which the iteration updates its matrix, at the second update and later
    slow_contraction = ((0.0, DIRECT_FIRST_CONTRACTION, DIRECT_SLOW_CONTRACTION) if st.direct else
                        (0.0, SLOW_CONTRACTION, SLOW_CONTRACTION))
    previous = None
    step = None  # the last update, made with the current iteration matrix (see StepSolve.secant)
    slow = 0
    st.last_iterations = max_iterations + 1  # unless it converges
    for iteration in range(max_iterations):
        r = st.residual(y, p)
        dy = st.linear.solve(-r)
        if step is not None:
            dy = st.linear.secant(dy, step, weights)
        step = dy
        y += dy
        stats["newton_iterations"] += 1
        err = np.abs(dy / scale).max(initial=0.0)
        theta = err / previous if previous else 0.0
        if not np.isfinite(err):
            return None
        if err <= 1.0 and theta < 1.0 and theta / (1.0 - theta) * err <= 1.0 or err <= 1e-3:
            st.last_iterations = iteration + 1
            a, v, v_dot = st.update(y, p)
            if st.variant == "stabilized":
                st.history.converged(a, y[n_u + n_c : n_u + 2 * n_c], st.last_shift, p, n_u, st.mode)
            return y, a, v, v_dot
        if previous is not None and theta > slow_contraction[min(iteration, 2)]:
            if fresh and theta >= 1.0:
                return None  # diverging with an up-to-date matrix
            slow += 1
            if slow == 1:  # the contact moved on: the rest at the current iterate first
                st.linear.prepare(y, p)
            else:
                st.linear.factorize(y, p)
                fresh = True
            previous = step = None
            continue
        previous = err
    if not fresh:  # a last attempt with an up-to-date matrix from the predictor
        st.linear.factorize(y0, p)
        return solve_step(st, y0, p, tol, max_iterations, stats, refreshed=True)
    return None

