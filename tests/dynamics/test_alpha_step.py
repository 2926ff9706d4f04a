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
    st.factorize(y, p)
    rhs = rng.normal(size=st.n_y)
    exact = spla.spsolve(st.jacobian(y, p).tocsc(), rhs)
    assert np.abs(st.solve(rhs) - exact).max() < 1e-8 * np.abs(exact).max()


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
