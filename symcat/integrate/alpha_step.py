"""The equations of one generalized-alpha step and their modified Newton solve, for
:mod:`symcat.integrate.generalized_alpha` (whose module docstring explains the method, the
unknowns and the scaling)."""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse.linalg as spla

from ..assembly.sparse import to_scipy
from ..dae.formulation import Formulation
from ..errors import SolverError

#: A Newton iteration that contracts by less than this per iteration refactorizes its matrix.
SLOW_CONTRACTION = 0.3


class StepEquations:
    """The step equations of one element window: the scaled residual (with the updated ``a``,
    ``v`` and ``v_dot``) and its Jacobian as CasADi functions of the unknowns ``y`` and the
    step's data ``p``, and the factorized iteration matrix of the modified Newton iteration.

    ``y = [u, beta h^2 lambda (, nu), s_c]`` and the rows ``[dynamics, C_s^T lambda, C (, velocity
    constraints), T]``: the arc lengths ``s_c`` of the penalty contacts are algebraic unknowns of
    the step with their tangency rows ``T(q, s_c) = 0`` (no multiplier; their normal forces are
    in ``Q``)."""

    def __init__(self, form: Formulation, variant: str, expand: bool = False):
        n_f, n_s, n_c, n_sc = form.n_f, form.n_s, form.n_c, form.n_sc
        self.n_u, self.n_c, self.n_s, self.n_sc = n_f + n_s, n_c, n_s, n_sc
        n_u = self.n_u
        n_y = n_u + n_c * (2 if variant == "stabilized" else 1) + n_sc
        self.n_y = n_y
        y = ca.MX.sym("y", n_y)
        # p: u_pred = u_n + h v_n + h^2 (1/2 - beta) a_n, v_pred = v_n + h (1 - gamma) a_n,
        # b = (alpha_m a_n - alpha_f v_dot_n) / (1 - alpha_f), then t_{n+1}, beta h^2, gamma h,
        # (1 - alpha_m) / (1 - alpha_f).
        p = ca.MX.sym("p", 3 * n_u + 4)
        u_pred, v_pred, b = p[:n_u], p[n_u : 2 * n_u], p[2 * n_u : 3 * n_u]
        t, bh2, gh, cm = p[3 * n_u], p[3 * n_u + 1], p[3 * n_u + 2], p[3 * n_u + 3]
        u, lam_s = y[:n_u], y[n_u : n_u + n_c]
        sc = y[n_y - n_sc :] if n_sc else None
        q, s = u[:n_f], u[n_f:]
        shift = ca.MX.zeros(n_u)
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
        r = ca.vertcat(*rows)
        self.residual_fn, self.update_fn, self.jacobian_fn = _step_functions(
            ca.Function("alpha_step", [y, p], [r, a, v, v_dot]), expand)
        self.mass_fn = ca.Function("alpha_mass", [y], [k["M"]])
        self.lu = None
        self.lu_bh2 = None  # the beta h^2 of the factorized matrix (a halved step refactorizes)
        self.factorizations = 0
        self.mass_scale = None  # kg: mean diagonal of M, converts multiplier updates to positions

    @staticmethod
    def _terms(form, q, v, s, w, t, sc=None):
        if form.n_s == 0:  # an empty s would leave Cs 0 x 0 against n_c rows
            k = form.terms(q, v, s, w, t, sc)
            return {**k, "Cs": ca.MX(form.n_c, 0)}
        return form.terms(q, v, s, w, t, sc)

    def residual(self, y, p) -> np.ndarray:
        return self.residual_fn(y, p).full().ravel()

    def update(self, y, p) -> tuple:
        """``a``, ``v`` and ``v_dot`` at the end of the step whose unknowns are ``y``."""
        return tuple(x.full().ravel() for x in self.update_fn(y, p))

    def mass(self, y) -> np.ndarray:
        """The mass matrix (free coordinates, scipy sparse) at the positions of ``y``."""
        return to_scipy(self.mass_fn(y))

    def factorize(self, y, p) -> None:
        jac = to_scipy(self.jacobian_fn(y, p))
        if self.mass_scale is None:
            # The mass matrix's own diagonal: the iteration matrix's also holds beta h^2 K, which
            # on the stiff cross-section gradients of a beam3d wire exceeds the mass by orders.
            diag = np.abs(self.mass(y).diagonal())
            self.mass_scale = float(diag.mean()) if diag.size and diag.mean() > 0 else 1.0
        try:
            self.lu = spla.splu(jac.tocsc())
        except RuntimeError:
            raise SolverError("generalized-alpha: singular iteration matrix (redundant constraints, or a sliding "
                              "joint at a point where its wire has no tangent?)") from None
        self.lu_bh2 = float(p[3 * self.n_u + 1])
        self.factorizations += 1


def _step_functions(step: ca.Function, expand: bool) -> tuple[ca.Function, ca.Function, ca.Function]:
    """From ``step(y, p) -> (r, a, v, v_dot)``: the residual ``r``, the update ``(a, v, v_dot)``
    and the Jacobian ``dr/dy`` as separate functions (an iteration evaluates the residual only),
    with ``expand`` each expanded to scalar operations when the graph allows it (a kernel outside
    the SX build does not)."""
    y, p = step.mx_in()
    r, a, v, v_dot = step(y, p)
    fns = (ca.Function("alpha_residual", [y, p], [r]), ca.Function("alpha_update", [y, p], [a, v, v_dot]),
           ca.Function("alpha_jacobian", [y, p], [ca.jacobian(r, y)]))
    if not expand:
        return fns
    try:
        return tuple(fn.expand() for fn in fns)
    except RuntimeError:
        return fns


def solve_step(st: StepEquations, y0, p, n_u, n_c, n_sc, tol, max_iterations, stats, refreshed: bool = False):
    """Modified Newton iteration of one step from the predictor ``y0``: the factorized matrix is
    kept while the iteration contracts by at least :data:`SLOW_CONTRACTION` per iteration, else
    refactorized at the current iterate. Converged when the last update, with the remaining
    error estimated from the contraction rate, is below ``tol`` relative to the coordinates
    (``1 + |u|``, and ``1 + |s_c|`` for the contact arc lengths); the scaled multipliers
    ``beta h^2 lambda`` count as the position change ``beta h^2 lambda / m`` they cause on a mass
    ``m`` (the mean diagonal of ``M``), and ``nu`` as a position change. Returns
    ``(y, a, v, v_dot)`` or None."""
    y = y0.copy()
    fresh = refreshed or st.lu is None
    if st.lu is None:
        st.factorize(y, p)
    n_y = y.size
    scale = np.empty_like(y)
    scale[:n_u] = tol * (1.0 + np.abs(y[:n_u]))
    scale[n_u : n_u + n_c] = tol * st.mass_scale
    scale[n_u + n_c : n_y - n_sc] = tol
    scale[n_y - n_sc :] = tol * (1.0 + np.abs(y[n_y - n_sc :]))
    previous = None
    for _ in range(max_iterations):
        r = st.residual(y, p)
        dy = st.lu.solve(-r)
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
            st.factorize(y, p)
            fresh, previous = True, None
            continue
        previous = err
    if not fresh:  # a last attempt with an up-to-date matrix from the predictor
        st.factorize(y0, p)
        return solve_step(st, y0, p, n_u, n_c, n_sc, tol, max_iterations, stats, refreshed=True)
    return None
