"""The Jacobian IDAS factorizes, against central differences of the residual it solves.

What is checked
---------------
CasADi's IDAS integrates ``F(y, y') = [ode(t, x, z, p) - x'; alg(t, x, z, p)] = 0`` with
``y = [x; z]`` (``x`` the differential states, ``z`` the accelerations, multipliers and
algebraic arc lengths) and, at every Newton set-up, factorizes
``dF/dy + cj dF/dy' = [[ode_x - cj I, ode_z], [alg_x, alg_z]]``, whose four blocks it takes from
one function, ``jacF``, that it requests from the DAE's ``factory``. That function is fetched
here from an IDAS integrator itself (through :class:`symcat.integrate.shifted.SharedDerivatives`,
which caches what the factory returned), on the DAE the drivers give IDAS:

* the rigid pendulum and the slider on a wire (:func:`symcat.integrate.simulate`'s own
  calls): ``Formulation.dae_function()``, a CasADi graph over the compiled kernels;
* the wheelset (the contact driver, :mod:`symcat.integrate.event_stepping`): the DAE in the
  state's scaled departure from its linear extrapolation over a call, in normalized, warped
  time (:func:`symcat.integrate.shifted.shifted_dae`), over the compiled whole-model DAE and its
  compiled Jacobian companion ``jac_dae`` (:mod:`symcat.codegen.model_dae`) in the augmented
  form, over the graph in the embedded form (what ``simulate`` picks by default); and that DAE
  unshifted (the driver's IDACalcIC fallback), also with one contact lifted off (its gap row
  released).

``dF/dy`` (states, accelerations, multipliers, algebraic arc lengths) and ``dF/dy'`` are
compared, whole, with central differences of ``F`` evaluated numerically at perturbed points,
for every formulation (augmented, embedded) and index (1, GGL), at a generic state: consistent
positions and velocities with random velocities, then every block (multipliers included)
perturbed at random. The slider is checked just before and just after an element end inside
its element window (the step stays within one element), and once exactly at the end, where the
derivative is one-sided (see :func:`test_slider_exactly_at_an_element_end_is_one_sided`).

Why the tolerance is what it is
-------------------------------
A central difference with step ``h`` errs by ``h^2 |F'''| / 6`` (truncation) plus about
``eps S / h`` (rounding, ``S`` the magnitude of the terms that make up the residual row). The
step is ``h_j = eps^(1/3) max(1, |y_j|)`` (balances the two; for the shifted DAE's
``xi = (x - x_a - t x_dot_a) / D``, the same rule in ``x``: ``unit_j = max(1, |x_j|) / D_j``
instead of 1); the truncation error is estimated per entry by Richardson's comparison of steps
``h`` and ``2h`` (``|D_2h - D_h| / 3``, or one octave up, ``|D_4h - D_2h| / 12``, if larger: one
comparison can vanish by chance where the steps are not yet asymptotic), the rounding term from
the row's terms (``S_i = |F_i| + sum_k |J_ik| max(unit_k, |y_k|)``), and an entry passes if the AD value lies
within :data:`SAFETY` times their sum. The whole matrix is compared (errors are reported
relative to the largest entry of their column), and every finite-difference entry above its
tolerance must also lie in AD's sparsity pattern.

The checker can fail: the mutation tests drop one term from the AD Jacobian (the derivative of
the constraint forces ``C_q^T lambda``, or ``H^T lambda``, with respect to ``q``; the derivative
of the applied forces ``Q`` with respect to ``v``) and require the same
:func:`check_jacobian` to report a failure, in the dropped block.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
import pytest

from symcat.assembly.multibody import MultibodyModel
from symcat.codegen.model_dae import compiled_dae
from symcat.dae.formulation import Formulation
from symcat.dae.initial import consistent_state
from symcat.errors import ParameterError
from symcat.integrate.shifted import SharedDerivatives, shifted_dae
from symcat.model import load_model
from tests.codegen.test_model_dae import _wheelset

EPS = np.finfo(float).eps
#: The multiple of the estimated difference error an entry may differ by. The estimates are of
#: the error's size, not bounds (Richardson's is itself only O(h^2) accurate, the rounding term
#: a typical accumulation): measured here, the worst |AD - FD| is 2.5 times the estimate (rows
#: where rounding dominates), and about 1 time where truncation dominates.
SAFETY = 10.0
#: Distance (m) of the slider's arc length from the element end: more than the difference
#: stencils' reach (4 h = 4 eps^(1/3) max(1, s) = 2.4e-5 m at s = 1 m), so none straddles it.
END_OFFSET_M = 1e-4
#: The element end the slider is checked at (6 elements on 2 m; a window of 4 elements, 1-5).
ELEMENT_END_M = 1.0

SCENES = ("slider", "pendulum", "wheelset")
FORMULATIONS = ("augmented", "embedded")
INDICES = ("1", "ggl")
CASES = [(s, f, i) for s in SCENES for f in FORMULATIONS for i in INDICES]
#: Terms dropped by the mutation tests: (residual block, differentiated variable).
MUTATIONS = ("constraint_force_q", "applied_force_v")


# --- the checker ------------------------------------------------------------------------------
@dataclass
class JacobianCheck:
    """The outcome of :func:`check_jacobian`."""

    passed: bool
    worst_ratio: float          # max |AD - FD| / tolerance
    worst: tuple                # (row, column) of worst_ratio
    error_rel: float            # |AD - FD| there, relative to the column's scale (max |FD| in it)
    tolerance_rel: float        # the tolerance there, relative to the same scale
    max_error_rel: float        # max |AD - FD| / column scale over the whole matrix
    uncovered: list = field(default_factory=list)  # FD entries above tolerance outside AD's pattern
    failing: np.ndarray = None  # boolean mask of the entries out of tolerance

    def summary(self) -> str:
        return (f"worst |AD-FD|/tol = {self.worst_ratio:.3g} at {self.worst} "
                f"(error {self.error_rel:.3g}, tolerance {self.tolerance_rel:.3g}, relative to the column scale); "
                f"max relative error {self.max_error_rel:.3g}; {len(self.uncovered)} FD entries outside AD's pattern")


def check_jacobian(residual, y0, jac_ad, pattern, one_sided=(), unit=None) -> JacobianCheck:
    """Compare ``jac_ad`` (dense, with its structural ``pattern``) with differences of ``residual``.

    Parameters
    ----------
    residual : callable
        ``(n, m) array -> (n_F, m) array``: the residual at ``m`` points (columns).
    y0 : ndarray (n,)
        The point.
    jac_ad : ndarray (n_F, n)
        The Jacobian to check.
    pattern : ndarray (n_F, n) of bool
        Its structural nonzeros.
    one_sided : sequence of int
        Columns differenced forwards only (``y_j >= y0_j``): where the residual is smooth on
        that side only (second-order forward stencil, same error model, 4x the rounding term).
    unit : ndarray (n,), optional
        What a magnitude of 1 is in each column (default 1): the step is
        ``eps^(1/3) max(unit_j, |y0_j|)`` (a variable scaled by ``D`` has ``unit = 1 / D``).

    Returns
    -------
    JacobianCheck
    """
    y0 = np.asarray(y0, float)
    n = len(y0)
    unit = np.ones(n) if unit is None else np.asarray(unit, float)
    size = np.maximum(unit, np.abs(y0))
    h = EPS ** (1 / 3) * size
    forward = np.zeros(n, bool)
    forward[list(one_sided)] = True
    # Offsets per column (multiples of h): central +-1, +-2, +-4; forward 1, 2, 4, 8 (with F(y0)).
    central, fwd = np.array([-4.0, -2.0, -1.0, 1.0, 2.0, 4.0]), np.array([1.0, 2.0, 4.0, 8.0, 0.0, 0.0])
    steps = np.where(forward[None, :], fwd[:, None], central[:, None])
    points = np.repeat(y0[:, None], 6 * n + 1, axis=1)
    for k in range(6):
        points[np.arange(n), k * n + np.arange(n)] += steps[k] * h
    values = residual(points)
    f0 = values[:, -1:]
    f = [values[:, k * n : (k + 1) * n] for k in range(6)]
    # d[m]: the difference with step 2^m h (both stencils O(h^2)).
    d_central = [(f[3 + m] - f[2 - m]) / (2 ** (m + 1) * h) for m in range(3)]
    d_forward = [(-3 * f0 + 4 * f[m] - f[m + 1]) / (2 ** (m + 1) * h) for m in range(3)]
    d = [np.where(forward, a, b) for a, b in zip(d_forward, d_central)]
    d_h = d[0]
    # Steps h and 2h err by c h^2 and 4 c h^2: (d_2h - d_h) / 3 estimates d_h's error, and so
    # does (d_4h - d_2h) / 12 one octave up. The larger of the two: either can vanish by chance
    # where the steps are not yet asymptotic (a feature of the residual on the scale of the step).
    truncation = np.maximum(np.abs(d[1] - d[0]) / 3, np.abs(d[2] - d[1]) / 12)
    # Rounding: each evaluation of row i errs by about eps times the size of its terms, each
    # variable counted at no less than its unit (a state near zero still enters as an offset
    # plus a departure, e.g. the shifted DAE's x_a + D xi, or as a sum that cancels).
    terms = np.abs(f0[:, 0]) + np.abs(d_h) @ size
    rounding = EPS * terms[:, None] / h * np.where(forward, 4.0, 1.0)
    tol = SAFETY * (truncation + rounding)
    err = np.abs(jac_ad - d_h)
    ratio = err / np.maximum(tol, np.finfo(float).tiny)
    worst = np.unravel_index(np.argmax(ratio), ratio.shape)
    scale = np.abs(d_h).max(axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    uncovered = [tuple(map(int, rc)) for rc in np.argwhere((np.abs(d_h) > tol) & ~pattern)]
    failing = ratio > 1.0
    return JacobianCheck(passed=not failing.any() and not uncovered, worst_ratio=float(ratio[worst]),
                         worst=tuple(map(int, worst)), error_rel=float(err[worst] / scale[worst[1]]),
                         tolerance_rel=float(tol[worst] / scale[worst[1]]),
                         max_error_rel=float((err / scale).max()), uncovered=uncovered, failing=failing)


# --- scenes -----------------------------------------------------------------------------------
def _slider_model():
    """A body hanging from a sliding joint on a pinned, pretensioned wire of 6 elements (cable3d,
    damped), its window 4 elements (1-5), the joint at the node between elements 2 and 3."""
    slider = load_model("slider_on_wire")
    scene = slider.run.__globals__["build"](slider.resolve({"n_elements": 6, "s0": ELEMENT_END_M}))
    model = MultibodyModel(scene, window=4)
    assert model.sliding[0].window == (1, 5)  # the end lies inside: the masks select the element
    assert model.sliding[0].element_start[3] == ELEMENT_END_M
    return model


def _pendulum_model():
    """The planar double pendulum of rigid rods on revolute joints (Euler parameters)."""
    pendulum = load_model("pendulum")
    return MultibodyModel(pendulum.run.__globals__["build"](pendulum.resolve({})))


def _wheelset_model():
    """A wheelset rolling at 10 m/s, 2 mm off centre, with Polach creep forces: the scene of
    tests/codegen/test_model_dae.py (so its compiled model DAE is the same library)."""
    return _wheelset("s1002_uic60", "polach")


@functools.cache
def _model(scene: str) -> MultibodyModel:
    return {"slider": _slider_model, "pendulum": _pendulum_model, "wheelset": _wheelset_model}[scene]()


#: Size of the random perturbation of each block of the state (SI units of the block); the
#: multipliers also by 1 % of their value. Small enough to stay in the contact patch's smooth
#: neighbourhood, large enough that no term vanishes (GGL's mu is zero on a consistent state).
PERTURBATION = {"q": 1e-4, "s": 1e-4, "v": 1e-2, "w": 1e-2, "a": 1e-1, "s_dd": 1e-1, "lambda": 1.0, "mu": 1e-3,
                "sc": 1e-4}
#: Random velocities added before the projection (m/s, rad/s, per coordinate): the pendulum
#: and the slider move in every direction; the wheelset only wobbles about its rolling.
START_VELOCITY = {"slider": 0.3, "pendulum": 1.0, "wheelset": 1e-2}


def _generic_state(form: Formulation, scene: str, seed: int):
    """``(x, z)``: consistent positions and velocities (random ones projected), the
    accelerations and multipliers they imply, then every block perturbed at random."""
    rng = np.random.default_rng(seed)
    model = form.model
    q = form.to_internal(model.q0[model.free])
    v = form.to_internal(model.v0[model.free]) + START_VELOCITY[scene] * rng.standard_normal(form.n_f)
    start = {"q": q, "v": v, "s": model.s0.copy(), "w": np.zeros(form.n_s), "sc": model.sc0.copy()}
    x, z = consistent_state(form, 0.0, start=start)
    xb, zb = form.blocks()
    for vec, blocks in ((x, xb), (z, zb)):
        for name, b in blocks.items():
            scale = PERTURBATION[name] + (1e-2 * np.abs(vec[b.slice]) if name in ("lambda", "mu") else 0.0)
            vec[b.slice] += scale * rng.standard_normal(b.size)
    return x, z


def _set_slider_s(form: Formulation, x, z, s: float):
    """Put the slider's arc length at ``s`` (a differential state in the augmented form, an
    algebraic one in the embedded form)."""
    xb, zb = form.blocks()
    vec, b = (x, xb["s"]) if "s" in xb else (z, zb["s"])
    vec[b.start] = s


@dataclass
class Point:
    """One evaluation point of a DAE IDAS integrates, and how its state maps to the model's."""

    label: str
    fn: ca.Function        # the DAE as IDAS takes it: (t, x, z, p, u) -> (ode, alg, quad, zero)
    jac: ca.Function       # IDAS's jacF of it: (t, x, z, p, u) -> (ode_x, alg_x, ode_z, alg_z)
    x: np.ndarray          # IDAS's differential state (the shifted DAE's xi for the wheelset)
    z: np.ndarray
    t: float               # IDAS's time
    p: np.ndarray          # IDAS's parameters
    x_model: np.ndarray    # the model's differential state there
    t_model: float         # the model's time there (s)
    x_scale: np.ndarray    # d x_model / d x (diagonal)


@dataclass
class Case:
    scene: str
    form: Formulation
    points: list


def _idas_jacobian(dae: ca.Function) -> ca.Function:
    """The ``jacF`` function an IDAS integrator of ``dae`` builds and factorizes (fetched from
    the factory cache of :class:`SharedDerivatives`, as the contact driver's integrators use it)."""
    shared = SharedDerivatives(dae)
    ca.integrator("idas", "idas", shared, 0.0, [1.0], {"calc_ic": False, "linear_solver": "csparse"})
    jacs = [fn for key, fn in shared.derived.items() if key[0] == "jacF"]
    assert len(jacs) == 1, sorted(k[0] for k in shared.derived)
    assert jacs[0].name_out() == ["jac_ode_x", "jac_alg_x", "jac_ode_z", "jac_alg_z"]
    return jacs[0]


@functools.cache
def _case(scene: str, formulation: str, index: str) -> Case:
    model = _model(scene)
    try:
        form = Formulation(model, formulation, index)
    except ParameterError as exc:
        pytest.skip(f"{scene}, {formulation}, index {index}: {exc}")
    seed = 1000 * SCENES.index(scene) + 10 * FORMULATIONS.index(formulation) + INDICES.index(index)
    x, z = _generic_state(form, scene, seed)
    n_p = len(model.wheelrail) + 1
    p = np.r_[0.0, np.zeros(n_p - 1)]
    if scene != "wheelset":
        dae = form.dae_function()
        jac = _idas_jacobian(dae)
        t = 0.013  # a generic time: IDAS's t is relative to the call's start p[0]
        points = []
        offsets = [("before", -END_OFFSET_M), ("after", END_OFFSET_M)] if scene == "slider" else [("generic", None)]
        for label, offset in offsets:
            xs, zs = x.copy(), z.copy()
            if offset is not None:
                _set_slider_s(form, xs, zs, ELEMENT_END_M + offset)
            points.append(Point(label, dae, jac, xs, zs, t, p, xs, t, np.ones(len(xs))))
        return Case(scene, form, points)
    # The contact driver's DAE: compiled in the augmented form (simulate's default for wheel/rail
    # models without element windows; the embedded form's linear solve does not expand to SX).
    base = compiled_dae(form.dae_function) if formulation == "augmented" else form.dae_function()
    if formulation == "augmented":
        assert base.class_name() == "External"  # with its compiled Jacobian companion
    dae = shifted_dae(base, normalized=True)
    # A call of h = 1 ms from x_a (the generic state, with its own x_dot: the driver's start),
    # scaled as the driver scales it (rtol 1e-6, atol 1e-8: D up to 2e3 on the spin), in warped
    # time, at tau = 0.4, with xi off its consistent zero by a departure D xi of the size a call's
    # states take (at most 1e-6 D: 5e-5 m on the height, 2e-3 rad/s on the spin).
    rng = np.random.default_rng(seed + 1)
    x_dot = np.asarray(base(0.0, x, z, p, ca.DM(0, 1))[0]).ravel()
    d = 1.0 + 1e-6 * np.abs(x) / 1e-8
    h, warp, tau = 1e-3, 0.3, 0.4
    xi = 1e-6 * rng.standard_normal(len(x))
    t_model = h * (tau + warp * tau * (1 - tau))
    shifted = Point("shifted", dae, _idas_jacobian(dae), xi, z, tau, np.r_[p, x, x_dot, d, h, warp],
                    x + t_model * x_dot + d * xi, t_model, d)
    # The driver's fallback (a failed short call): the DAE itself, with IDACalcIC; also with the
    # left contact lifted off (its gap row released: replaced by its multiplier).
    jac = _idas_jacobian(base)
    plain = Point("plain", base, jac, x, z, t_model, p, x, t_model, np.ones(len(x)))
    lifted = Point("plain, left contact open", base, jac, x, z, t_model, np.r_[p[0], 1.0, p[2:]], x, t_model,
                   np.ones(len(x)))
    return Case(scene, form, [shifted, plain, lifted])


# --- the residual F(y, y') and its AD Jacobian ---------------------------------------------------
def _residual(point: Point):
    """``F(y, y') = [ode - x'; alg]`` at the columns of ``Y = [y; y']`` (numeric, batched)."""
    n_x, n_z = len(point.x), len(point.z)
    cache = {}

    def evaluate(cols):
        m = cols.shape[1]
        if m not in cache:
            cache[m] = point.fn.map(m)
        ode, alg = cache[m](point.t, cols[:n_x], cols[n_x : n_x + n_z], point.p, ca.DM(0, m))[:2]
        return np.vstack([np.asarray(ode) - cols[n_x + n_z :], np.asarray(alg)])

    return evaluate


def _ad_jacobian(point: Point):
    """``(J, pattern)``: ``[dF/dy, dF/dy']`` from IDAS's ``jacF`` (dense) and its structure;
    ``dF/dy' = [-I; 0]`` is IDAS's own (it adds ``-cj I`` to ``ode_x``)."""
    n_x, n_z = len(point.x), len(point.z)
    blocks = point.jac(point.t, point.x, point.z, point.p, ca.DM(0, 1))
    ode_x, alg_x, ode_z, alg_z = blocks
    dense = np.block([[_dense(ode_x), _dense(ode_z)], [_dense(alg_x), _dense(alg_z)]])
    pattern = np.block([[_mask(ode_x), _mask(ode_z)], [_mask(alg_x), _mask(alg_z)]])
    d_yp = np.vstack([-np.eye(n_x), np.zeros((n_z, n_x))])
    return np.hstack([dense, d_yp]), np.hstack([pattern, d_yp != 0])


def _dense(m) -> np.ndarray:
    return np.asarray(ca.densify(ca.DM(m)))


def _mask(m) -> np.ndarray:
    sp = ca.DM(m).sparsity()
    out = np.zeros(sp.shape, bool)
    rows, cols = sp.get_triplet()
    out[rows, cols] = True
    return out


def _y(point: Point, rng_seed: int = 7) -> np.ndarray:
    """``[x; z; x']``: ``x'`` generic (``F`` is linear in it)."""
    rng = np.random.default_rng(rng_seed)
    return np.r_[point.x, point.z, rng.standard_normal(len(point.x))]


# --- dropped terms -----------------------------------------------------------------------------
def _dropped_block(case: Case, point: Point, mutation: str) -> np.ndarray:
    """The AD derivative of one term of the dynamics rows ``M a + C_q^T lambda - Q`` (augmented;
    ``H^T lambda`` embedded), in the layout of :func:`_ad_jacobian`'s matrix: the term is
    rebuilt alone from the formulation's pieces and differentiated by CasADi."""
    form = case.form
    xb, zb = form.blocks()
    n_x, n_z = len(point.x), len(point.z)
    xs, zs, t = ca.MX.sym("x", n_x), ca.MX.sym("z", n_z), ca.MX.sym("t")
    X = {k: xs[b.slice] for k, b in xb.items()}
    Z = {k: zs[b.slice] for k, b in zb.items()}
    sc = Z.get("sc")
    if form.formulation == "augmented":
        w = X["w"] if "w" in X else Z["w"]
        k = form.terms(X["q"], X["v"], X["s"], w, t, sc)
        lam_force = ca.mtimes(k["Cq"].T, Z["lambda"])
    else:
        k = form.embedded_terms(X["q"], X["v"], Z["s"], t, sc)
        lam_force = ca.mtimes(k["H"].T, Z["lambda"])
    term, wrt = {"constraint_force_q": (lam_force, "q"), "applied_force_v": (-k["Q"], "v")}[mutation]
    jac = ca.Function("term_jac", [xs, zs, t], [ca.jacobian(term, xs)])
    block = np.asarray(ca.densify(jac(point.x_model, point.z, point.t_model)))
    cols = np.zeros(n_x, bool)
    cols[xb[wrt].slice] = True
    block[:, ~cols] = 0.0
    full = np.zeros((n_x + n_z, 2 * n_x + n_z))
    # The dynamics are the first n_f algebraic rows; IDAS's x columns are the model's scaled.
    full[n_x : n_x + form.n_f, :n_x] = block * point.x_scale[None, :]
    return full


# --- tests -------------------------------------------------------------------------------------
def _unit(point: Point) -> np.ndarray:
    """Unit magnitudes of ``[x; z; x']``: the step rule applies to the model's variables, so
    IDAS's ``x = (x_model - ...) / D`` (the wheelset's shifted DAE) has ``max(1, |x_model|) / D``."""
    x_unit = np.maximum(1.0, np.abs(point.x_model)) / point.x_scale
    return np.r_[x_unit, np.ones(len(point.z)), x_unit]


def _check(point: Point, jac_ad, pattern, one_sided=()) -> JacobianCheck:
    return check_jacobian(_residual(point), _y(point), jac_ad, pattern, one_sided, _unit(point))


@pytest.mark.parametrize("scene, formulation, index", CASES)
def test_idas_jacobian_matches_central_differences(scene, formulation, index):
    case = _case(scene, formulation, index)
    for point in case.points:
        jac, pattern = _ad_jacobian(point)
        result = _check(point, jac, pattern)
        print(f"{scene} {formulation} {index} {point.label}: n = {len(point.x) + len(point.z)}; {result.summary()}")
        assert result.passed, f"{point.label}: {result.summary()}"


@pytest.mark.parametrize("mutation", MUTATIONS)
@pytest.mark.parametrize("scene, formulation, index", CASES)
def test_checker_fails_when_a_term_is_dropped(scene, formulation, index, mutation):
    case = _case(scene, formulation, index)
    for point in case.points:
        jac, pattern = _ad_jacobian(point)
        dropped = _dropped_block(case, point, mutation)
        assert np.abs(dropped).max() > 0, "the term has no derivative here: the mutation would prove nothing"
        result = _check(point, jac - dropped, pattern)
        print(f"{scene} {formulation} {index} {point.label} without d({mutation}): {result.summary()}")
        assert not result.passed
        # The failures are where the term was dropped.
        assert (result.failing & (dropped != 0)).any()
        assert not (result.failing & (dropped == 0)).any()


@pytest.mark.parametrize("formulation, index", [(f, i) for f in FORMULATIONS for i in INDICES])
def test_slider_exactly_at_an_element_end_is_one_sided(formulation, index):
    """At ``s = S_k`` the masks select element ``k`` (``S_k <= s < S_k+1``): AD gives the
    derivative from the right. The residual is not differentiable in ``s`` there: the ANCF
    wire is C1 across nodes, so ``r'(s)`` (in ``C_s``) is continuous but ``r''(s)`` (in
    ``dC_s/ds`` and in ``C_q``'s ``s``-derivative) jumps. Every column but ``s`` matches central
    differences; the ``s`` column matches forward differences and not central ones."""
    case = _case("slider", formulation, index)
    after = case.points[1]
    x, z = after.x.copy(), after.z.copy()
    _set_slider_s(case.form, x, z, ELEMENT_END_M)
    point = Point("at the end", after.fn, after.jac, x, z, after.t, after.p, x, after.t, after.x_scale)
    xb, zb = case.form.blocks()
    s_col = xb["s"].start if "s" in xb else len(point.x) + zb["s"].start
    jac, pattern = _ad_jacobian(point)
    right = _check(point, jac, pattern, one_sided=[s_col])
    print(f"slider {formulation} {index} at the end, s forward: {right.summary()}")
    assert right.passed, right.summary()
    central = _check(point, jac, pattern)
    print(f"slider {formulation} {index} at the end, s central: {central.summary()}")
    assert not central.passed
    assert np.flatnonzero(central.failing.any(axis=0)).tolist() == [s_col]
