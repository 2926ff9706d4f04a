"""The generalized-alpha step's split equations (symcat.integrate.alpha_step): the bulk/rest
Jacobian against central differences of the residual, and the Woodbury solve against a direct
sparse solve with that Jacobian, on a lumped pantograph pressing on a form-found catenary (bulk:
the wires; rest: the pantograph's bodies, joints, penalty contact or sliding joint on the wire, and
multipliers)."""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary import benchmark2015, find_form
from symcat.catenary.scene import catenary_scene
from symcat.dae.formulation import Formulation
from symcat.integrate.alpha_coefficients import AlphaCoefficients
from symcat.integrate.alpha_step import StepEquations
from symcat.pantograph import benchmark2015_pantograph
from symcat.pantograph.lumped_scene import add_lumped_pantograph, loaded_wire_height

SPEED = 200 / 3.6


@pytest.fixture(scope="module", params=["penalty", "bilateral"])
def line(request):
    form = find_form(benchmark2015(2), 6, progress=False)
    panto = benchmark2015_pantograph(200.0)
    scene = catenary_scene(form)
    z = loaded_wire_height(form, 40.0, float(panto.static_force(SPEED).sum()))
    add_lumped_pantograph(scene, panto, "contact", 40.0, SPEED, contact=request.param, head_z=z)
    model = MultibodyModel(scene, window=4)  # the contact sees 4 of the 12 elements
    solve_equilibrium(model).apply(model)
    return model


def _point(st, line, rng):
    """Unknowns ``y`` near the static state and step data ``p`` (dt = 1 ms, rho_inf = 0.8) of a
    step of ``st`` on ``line``."""
    c, h, n_u = AlphaCoefficients(0.8), 1e-3, st.n_u
    u0 = np.r_[line.q0[line.free], line.s0]
    p = np.r_[u0, rng.normal(0, 1e-2, n_u), rng.normal(0, 1.0, n_u), 0.0, c.beta * h * h, c.gamma * h,
              (1 - c.alpha_m) / (1 - c.alpha_f)]
    y = np.zeros(st.n_y)
    y[:n_u] = u0 + rng.normal(0, 1e-5, n_u)
    y[n_u : n_u + st.n_c] = rng.normal(0, 1e-5, st.n_c)
    if st.n_sc:
        y[-st.n_sc :] = line.sc0
    return y, p


@pytest.mark.parametrize("variant", ["stabilized", "index3"])
def test_split_jacobian_and_woodbury_solve(line, variant):
    form = Formulation(line, "augmented", "1")
    st = StepEquations(form, variant)
    assert 0 < st.bulk.n_b < st.n_y and st.rest_columns.size < st.n_y / 2
    rng = np.random.default_rng(3)
    y, p = _point(st, line, rng)
    jac = st.jacobian(y, p).toarray()
    fd = np.empty_like(jac)
    for j in range(st.n_y):
        e = np.zeros(st.n_y)
        e[j] = 1e-7 * max(1.0, abs(y[j]))
        fd[:, j] = (st.residual(y + e, p) - st.residual(y - e, p)) / (2 * e[j])
    scale = np.abs(fd).max(axis=0, initial=0.0) + 1e-12
    # nu (stabilized) enters the bulk rows through the shift of a: the Jacobian carries its
    # linear part with the Rayleigh matrix, exact here (no element damping)
    assert np.abs((jac - fd) / scale).max() < 1e-5
    st.linear.factorize(y, p)
    rhs = rng.normal(size=st.n_y)
    exact = spla.spsolve(st.jacobian(y, p).tocsc(), rhs)
    assert np.abs(st.linear.solve(rhs) - exact).max() < 1e-8 * np.abs(exact).max()


def test_proxy_element_equals_the_window(line):
    """The rest built once on a stand-in element gives the residual, update and Jacobian of the
    rest built on the element window around the contact (to round-off), with the contact on
    another element than the proxy."""
    form = Formulation(line, "augmented", "1")
    proxied, windowed = StepEquations(form, "stabilized"), StepEquations(form, "stabilized", proxies=False)
    assert proxied.proxies is not None and windowed.proxies is None
    (sl, j, *_), = proxied.proxies.items
    y, p = _point(proxied, line, np.random.default_rng(5))
    s = y[proxied.proxies.items[0][-1]]
    assert not sl.element_start[j] <= s < sl.element_start[j + 1]  # the contact is elsewhere
    scale = np.abs(windowed.residual(y, p)).max()
    np.testing.assert_allclose(proxied.residual(y, p), windowed.residual(y, p), atol=1e-12 * scale)
    for a, b in zip(proxied.update(y, p), windowed.update(y, p)):
        np.testing.assert_allclose(a, b, atol=1e-12 * max(1.0, np.abs(b).max()))
    ja, jb = proxied.jacobian(y, p), windowed.jacobian(y, p)
    assert abs(ja - jb).max() < 1e-10 * abs(jb).max()


@pytest.mark.parametrize("wires", ["nonlinear", "linear"])
def test_bulk_residual_is_the_step_formula(wires):
    """The bulk's residual, evaluated as one step matrix times the unknowns plus the forces that
    are not affine, equals ``beta h^2 (M (c_m a + b) - f(q, v, t))`` evaluated whole in CasADi
    (``f`` with Rayleigh damping; linearized wires: their affine forces folded into the matrix)."""
    import casadi as ca

    form_found = find_form(benchmark2015(2), 6, progress=False)
    model = MultibodyModel(catenary_scene(form_found, wires=wires))
    form = Formulation(model, "augmented", "1")
    st = StepEquations(form, "index3")
    bulk, n_b, n_u = st.bulk, st.bulk.n_b, st.n_u
    rng = np.random.default_rng(11)
    c, h = AlphaCoefficients(0.8), 1e-3
    u0 = model.q0[model.free]
    p = np.r_[u0, rng.normal(0, 1e-2, n_u), rng.normal(0, 1.0, n_u), 0.3, c.beta * h * h, c.gamma * h,
              (1 - c.alpha_m) / (1 - c.alpha_f)]
    y_b = u0[:n_b] + rng.normal(0, 1e-4, n_b)
    shift = np.zeros(n_b)
    bh2, gh, cm = p[3 * n_u + 1 :]
    a = (y_b - p[:n_b]) / bh2
    v = p[n_u : n_u + n_b] + gh * a
    q_sym, v_sym = ca.MX.sym("q", model.n_q), ca.MX.sym("v", model.n_q)
    f = ca.Function("f", [q_sym, v_sym], [model.forces(q_sym, v_sym, 0.3, "bulk")])
    q_full, v_full = model.q0.copy(), np.zeros(model.n_q)
    q_full[model.free[:n_b]], v_full[model.free[:n_b]] = y_b, v
    forces = np.array(f(q_full, v_full)).ravel()[model.free[:n_b]]
    expected = bh2 * (bulk.mass_matrix @ (cm * a + p[2 * n_u : 2 * n_u + n_b]) - forces)
    got = bulk.residual(y_b, p, shift)
    assert np.abs(got - expected).max() < 1e-9 * np.abs(expected).max()
    # the next step's data (the affine part is cached per step data) and a shift
    p2 = p.copy()
    p2[:n_u] += 1e-6
    shift[:5] = 1e-7
    a2 = (y_b - p2[:n_b] - shift) / bh2
    v_full[model.free[:n_b]] = p2[n_u : n_u + n_b] + gh * a2
    forces = np.array(f(q_full, v_full)).ravel()[model.free[:n_b]]
    expected = bh2 * (bulk.mass_matrix @ (cm * a2 + p2[2 * n_u : 2 * n_u + n_b]) - forces)
    assert np.abs(bulk.residual(y_b, p2, shift) - expected).max() < 1e-9 * np.abs(expected).max()


def test_banded_columns_are_the_solves():
    """Columns of the inverse solved on a window of the band equal whole solves (a line-like
    matrix: a chain whose columns decay away from their index), also past the window's first
    width and at the matrix's ends."""
    import scipy.sparse as sps

    from symcat.assembly.banded import BandedCholesky

    n = 3000
    rng = np.random.default_rng(2)
    chain = sps.diags([np.full(n - 1, -1.0), np.full(n, 2.05), np.full(n - 1, -1.0)], [-1, 0, 1])
    shuffle = rng.permutation(n)
    matrix = chain.tocsr()[shuffle][:, shuffle]
    lu = BandedCholesky(matrix)
    for index in ([0, 1, 2], shuffle[[1500, 1501]], shuffle[[n - 1]], shuffle[[10, 2990]]):
        index = np.asarray(index)
        e = np.zeros((n, index.size))
        e[index, np.arange(index.size)] = 1.0
        exact = lu.solve(e)
        np.testing.assert_allclose(lu.columns(index), exact, rtol=0, atol=1e-14 * np.abs(exact).max())


def test_kept_patterns_give_a_fresh_builds_jacobian(line):
    """The Jacobian assembled on the pattern kept from an earlier evaluation (and the shift
    coupling's dense block kept for the step coefficients) equals that of equations built afresh,
    at another point and another step size."""
    form = Formulation(line, "augmented", "1")
    used, fresh = StepEquations(form, "stabilized"), StepEquations(form, "stabilized")
    rng = np.random.default_rng(8)
    used.jacobian(*_point(used, line, rng))
    y, p = _point(used, line, rng)
    p[3 * used.n_u + 1 :] *= [0.25, 0.5, 1.0]  # half the step
    ja, jb = used.jacobian(y, p), fresh.jacobian(y, p)
    assert abs(ja - jb).max() <= 1e-12 * abs(jb).max()


def test_whole_bulk_residual_equals_the_pieces():
    """The bulk residual as one expanded function (:class:`~symcat.integrate.alpha_bulk.Bulk`
    with ``whole``, for step matrices factorized whole) equals its evaluation in pieces, with
    and without a stabilization shift."""
    from symcat.integrate.alpha_bulk import Bulk

    form_found = find_form(benchmark2015(2), 6, progress=False)
    model = MultibodyModel(catenary_scene(form_found))
    form = Formulation(model, "augmented", "1")
    n_u = form.n_f + form.n_s
    pieces, whole = Bulk(form, n_u, True), Bulk(form, n_u, True, whole=True)
    n_b = pieces.n_b
    rng = np.random.default_rng(5)
    c, h = AlphaCoefficients(0.8), 1e-3
    u0 = model.q0[model.free]
    p = np.r_[u0, rng.normal(0, 1e-2, n_u), rng.normal(0, 1.0, n_u), 0.3, c.beta * h * h, c.gamma * h,
              (1 - c.alpha_m) / (1 - c.alpha_f)]
    y_b = u0[:n_b] + rng.normal(0, 1e-4, n_b)
    for shift in (np.zeros(n_b), rng.normal(0, 1e-7, n_b)):
        expected = pieces.residual(y_b, p, shift)
        assert np.abs(whole.residual(y_b, p, shift) - expected).max() < 1e-9 * np.abs(expected).max()


def test_secants_apply_the_product_form():
    """:class:`Secants` applies ``(I + s_k c_k^T) ... (I + s_1 c_1^T) z`` at once, as the
    updates applied one after another."""
    from symcat.integrate.alpha_secant import MAX_SECANTS, Secants

    rng = np.random.default_rng(3)
    n = 30
    sec = Secants(n)
    pairs = [(rng.normal(size=n), rng.normal(size=n) / n) for _ in range(MAX_SECANTS)]
    z0 = rng.normal(size=n)
    for k, (s, c) in enumerate(pairs):
        sec.add(s, c)
        z = z0.copy()
        for s_j, c_j in pairs[: k + 1]:
            z = z + s_j * (c_j @ z)
        np.testing.assert_allclose(sec.apply(z0), z, rtol=1e-10, atol=1e-10 * np.abs(z).max())
    sec.clear()
    assert np.array_equal(sec.apply(z0), z0)


def test_start_history_extrapolates_only_a_continued_chain():
    """:class:`StartHistory` extrapolates ``nu`` and the shift linearly when the step's predictor
    continues its last two steps (the integrator's linear prediction of ``a`` from them), and
    starts over otherwise (another step size, or a state it did not end with)."""
    from symcat.integrate.alpha_history import StartHistory

    n_u, tol, bh2 = 4, 1e-8, 2.5e-7
    rng = np.random.default_rng(9)
    mode = np.zeros(2)
    hist = StartHistory()

    def p_of(bh2_):
        return np.r_[rng.normal(size=3 * n_u), 0.0, bh2_, 1e-3, 1.0]

    a = [rng.normal(size=n_u) for _ in range(3)]
    nu = [np.full(3, k + 1.0) for k in range(3)]
    shift = [np.full(n_u, 10.0 * (k + 1)) for k in range(3)]
    for k in range(2):  # two steps: a chain of two
        p = p_of(bh2)
        assert hist.predict(p[:n_u].copy(), p, n_u, mode, tol) is None
        hist.converged(a[k], nu[k], shift[k], p, n_u, mode)
    p = p_of(bh2)
    y0 = p[:n_u] + bh2 * (a[1] + (a[1] - a[0]))  # the integrator's predictor from the chain's end
    nu_pred, shift_pred = hist.predict(y0, p, n_u, mode, tol)
    np.testing.assert_allclose(nu_pred, 3.0)
    np.testing.assert_allclose(shift_pred, 30.0)
    hist.converged(a[2], nu[2], shift[2], p, n_u, mode)
    # a state the chain did not end with (a restart): no extrapolation, and the chain starts over
    p = p_of(bh2)
    assert hist.predict(p[:n_u] + bh2 * a[2], p, n_u, mode, tol) is None
    assert hist.a == [] and hist.key is None
    # another step size
    for k in range(2):
        p = p_of(bh2)
        hist.predict(p[:n_u].copy(), p, n_u, mode, tol)
        hist.converged(a[k], nu[k], shift[k], p, n_u, mode)
    assert len(hist.a) == 2
    p = p_of(bh2 / 4)
    assert hist.predict(p[:n_u] + bh2 / 4 * (a[1] + (a[1] - a[0])), p, n_u, mode, tol) is None


def test_a_singular_capacitance_is_reported(line, monkeypatch):
    """A rest whose exact Jacobian is singular (here: zero, as a redundant constraint's rows
    would leave it) stops the step with the solver's message, not with NaNs or LAPACK's."""
    from symcat.errors import SolverError

    form = Formulation(line, "augmented", "1")
    st = StepEquations(form, "index3")
    y, p = _point(st, line, np.random.default_rng(5))
    st.linear.factorize(y, p)  # regular
    triplets = st._rest_triplets
    monkeypatch.setattr(st, "_rest_triplets", lambda y, p: (triplets(y, p)[0], np.zeros_like(triplets(y, p)[1])))
    with pytest.raises(SolverError, match="singular iteration matrix"):
        st.linear.prepare(y, p)
