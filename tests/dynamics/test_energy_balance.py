"""The energy balance of a multibody scene (symcat.assembly.energy): the potential's slope is
minus the conservative forces the kernels compute (two independent computations), and over a
passage the energy changes by the driving's work, to second order in the step."""
import numpy as np
import pytest

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.energy import EnergyTerms, penalty_law
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary import benchmark2015, find_form
from symcat.catenary.scene import catenary_scene
from symcat.integrate import generalized_alpha
from symcat.pantograph import benchmark2015_pantograph
from symcat.pantograph.lumped_scene import add_lumped_pantograph, loaded_wire_height

SPEED = 320 / 3.6


@pytest.fixture(scope="module")
def line():
    form = find_form(benchmark2015(4), 10, progress=False)
    scene = catenary_scene(form)
    panto = benchmark2015_pantograph(320)
    z = loaded_wire_height(form, 40.0, float(panto.static_force(SPEED).sum()))
    add_lumped_pantograph(scene, panto, "contact", 40.0, SPEED, head_z=z)
    model = MultibodyModel(scene)
    solve_equilibrium(model).apply(model)
    return model, EnergyTerms(model)


def test_penalty_potential_is_the_integral_of_the_law():
    k, d = 5.0e4, 1.0e-5
    pen = np.linspace(-d, 5 * d, 2001)
    v, f = penalty_law(pen, k, d)
    # trapezoidal integral of the force against the potential, through the three pieces of the law
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(pen))])
    np.testing.assert_allclose(v, integral, atol=1e-6 * k * d**2)
    assert f[-1] == pytest.approx(k * (pen[-1] - d))


def test_potential_slope_is_minus_the_conservative_forces(line):
    """Without dampers every force has its potential: d/de V(q + e w) = Q . w for the forces the
    kernels compute (wires, droppers, supports, the pantograph's springs and loads, the penalty
    contact), in any direction w of the free coordinates, wires and bodies apart."""
    import casadi as ca

    from symcat.assembly.contact import contact_terms

    model, energy = line
    q_sym, v_sym = ca.MX.sym("q", model.n_q), ca.MX.sym("v", model.n_q)
    sc_sym = ca.MX.sym("sc", len(model.contacts))
    forces = ca.Function("f", [q_sym, v_sym, sc_sym], [model.forces(q_sym, v_sym, 0.0, rayleigh=False)
                                                      + contact_terms(model, q_sym, v_sym, sc_sym)["Q"]])
    rng = np.random.default_rng(1)
    q, sc, rest = model.q0.copy(), model.sc0, np.zeros(model.n_q)
    q[model.free] += 2e-3 * rng.standard_normal(model.free.size)  # off the equilibrium: forces of all kinds
    f = np.asarray(forces(q, rest, sc)).ravel()
    for part in (model.free[model.free < model.ancf.n], model.free[model.free >= model.ancf.n]):
        w = np.zeros(model.n_q)
        w[part] = rng.standard_normal(part.size) * 1e-3
        eps = 1e-3
        slope = (sum(energy.energy(q + eps * w, rest, sc)) - sum(energy.energy(q - eps * w, rest, sc))) / (2 * eps)
        scale = np.abs(f[part]).max() * np.abs(w).max()
        assert slope == pytest.approx(-(f @ w), abs=1e-3 * scale)
    # no dampers but Rayleigh's: the rest of the non-conservative power is the contact force's
    # normal held fixed, a small fraction
    w = np.zeros(model.n_q)
    w[model.free] = rng.standard_normal(model.free.size) * 1e-2
    _, other = energy.power(q, w, sc, np.zeros(len(model.row_names)), 0.0)
    from symcat.assembly.sparse import to_scipy

    rayleigh = float(w @ (to_scipy(model._rayleigh_dm()) @ w))  # the whole matrix (power: its triangle)
    assert rayleigh > 1.0 and abs(other + rayleigh) < 1e-3 * rayleigh


def _balance_error(model, energy, dt):
    power, total = [], []

    def monitor(s):  # the states after several steps
        power.extend(sum(energy.powers(s.q, s.v, s.sc_m, s.multipliers, s.t_s)))
        total.extend(sum(energy.energy(s.q[i], s.v[i], s.sc_m[i])) for i in range(len(s)))
        return {}

    generalized_alpha(model, 0.2, dt, 1.0, variant="index3", n_out=4, tol=1e-9, progress=False,
                      multipliers="integrator", monitor=monitor)
    p, e = np.array(power), np.array(total)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * dt)])
    return np.abs(e - e[0] - work).max(), np.abs(work).max()


def test_passage_energy_balance_converges_at_second_order(line):
    """No numerical dissipation (rho_inf = 1): the energy changes by the work of the prescribed
    speed (the horizontal contact force on the pan-head), to O(dt^2)."""
    model, energy = line
    coarse, work = _balance_error(model, energy, 1e-3)
    fine, _ = _balance_error(model, energy, 5e-4)
    assert work > 2.0
    assert coarse < 2e-3 * work
    assert coarse / fine > 2.8


def test_powers_of_several_states_are_each_states_power(line):
    """A monitor's batch of states (one row per step, the contact's point on different elements
    and penetrations, one state off the wire) has the powers each state has alone."""
    model, energy = line
    rng = np.random.default_rng(2)
    k = 5
    q = np.tile(model.q0, (k, 1))
    v = np.zeros((k, model.n_q))
    q[:, model.free] += 1e-3 * rng.standard_normal((k, model.free.size))
    v[:, model.free] = 1e-2 * rng.standard_normal((k, model.free.size))
    starts = model.contacts[0].element_start
    sc = np.array([[model.sc0[0]], [model.sc0[0] + 1.3], [starts[3] + 0.1], [starts[-1] + 1.0], [model.sc0[0]]])
    lam = rng.standard_normal((k, len(model.row_names)))
    t = np.linspace(0.0, 0.1, k)
    driving, other = energy.powers(q, v, sc, lam, t)
    alone = np.array([energy.power(q[i], v[i], sc[i], lam[i], t[i]) for i in range(k)])
    np.testing.assert_allclose(driving, alone[:, 0], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(other, alone[:, 1], rtol=1e-12, atol=1e-9)
    assert np.ptp(other) > 1.0  # (states whose powers differ)
