"""Generalized-alpha steps compiled many to a call (:mod:`symcat.integrate.alpha_chunk`): the
same steps as from Python, to the Newton tolerance, on wires, bodies and joints; their band and
border factorization against NumPy; what stays in Python and why."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import scipy.sparse as sps

from symcat.assembly.multibody import MultibodyModel
from symcat.integrate.alpha_chunk import unsupported
from symcat.integrate.bordered_band import BorderedBand
from symcat.integrate.generalized_alpha import generalized_alpha
from symcat.scene import AncfBody, Material, Scene, Section
from tests.dynamics.test_generalized_alpha import _defaults, _scene_module
from tests.dynamics.test_sliding import ring


def cable_pendulum(n_elements=4):
    """A 1 m cable pinned at one end, swinging and spinning (the peer bench's problem 4)."""
    section = Section.from_stiffness(40.0, 7.9577e-5, 1e9)
    wire = AncfBody.straight("cable", "cable3d", [0, 0, 0], [1.0, 0, 0], n_elements,
                             Material(E=1e9, rho=8e-3 / section.A), section)
    wire.pin(0)
    scene = Scene(gravity=(0.0, -9.81, 0.0))
    scene.add(wire)
    model = MultibodyModel(scene)
    for k in range(wire.n_nodes):
        model.v0[model.ancf.dofs.node_indices(wire, k)[2]] = -4.0 * wire.q0[k, 0]
    return model


def slider(window=16):
    module = _scene_module("slider_on_wire")
    return MultibodyModel(module.build(_defaults(module)), window=window)


def _both(make, t_end, dt, **kwargs):
    return [generalized_alpha(make(), t_end, dt, n_out=20, progress=False, multipliers="integrator",
                              compiled=compiled, **kwargs) for compiled in (False, True)]


@pytest.mark.parametrize("seed", [0, 1])
def test_band_and_border_solve_as_numpy(seed):
    """A band (scrambled, so the ordering must find it) with a border whose own block has
    zeros on its diagonal (multipliers): the factor solves like a dense solve."""
    rng = np.random.default_rng(seed)
    n_b, n_r = 30, 4
    a = np.zeros((n_b + n_r,) * 2)
    for i in range(n_b):
        for j in range(max(0, i - 2), min(n_b, i + 3)):
            a[i, j] = rng.normal()
        a[i, i] += 8.0
    order = rng.permutation(n_b)
    a[:n_b, :n_b] = a[np.ix_(order, order)]
    a[:n_b, n_b:] = rng.normal(size=(n_b, n_r)) * (rng.random((n_b, n_r)) < 0.5)
    a[n_b:, :n_b] = a[:n_b, n_b:].T
    a[n_b:, n_b:] = np.diag([0.0, 1.0, 0.0, 2.0])
    m = sps.csc_matrix(a)
    layout = BorderedBand(ca.Sparsity(*m.shape, m.indptr.tolist(), m.indices.tolist()), n_b)
    assert layout.bw == 2  # the band found again
    nz, rhs = ca.MX.sym("nz", m.nnz), ca.MX.sym("rhs", n_b + n_r)
    solve = ca.Function("solve", [nz, rhs], [layout.solve(layout.factorize(nz), rhs)])
    b = rng.normal(size=n_b + n_r)
    assert np.abs(np.array(solve(m.data, b)).ravel() - np.linalg.solve(a, b)).max() < 1e-12


@pytest.mark.parametrize("seed", [0, 1])
def test_a_border_coupled_to_the_band_in_part_solves_as_numpy(seed):
    """Border columns without entries in the band's rows and rows without entries in its
    columns (a body's coordinates beside a wire): left out of ``E`` and ``F``, the factor is
    smaller and solves like a dense solve; leaving out a column that has entries does not."""
    rng = np.random.default_rng(seed)
    n_b, n_r = 24, 5
    a = np.zeros((n_b + n_r,) * 2)
    for i in range(n_b):
        for j in range(max(0, i - 2), min(n_b, i + 3)):
            a[i, j] = rng.normal()
        a[i, i] += 8.0
    e_cols, f_rows = np.array([0, 2, 3]), np.array([1, 2])
    a[:n_b, n_b + e_cols] = rng.normal(size=(n_b, e_cols.size))
    a[n_b + f_rows, :n_b] = rng.normal(size=(f_rows.size, n_b))
    a[n_b:, n_b:] = rng.normal(size=(n_r, n_r)) + 5 * np.eye(n_r)
    # the pattern holds the whole border (as the compiled steps' does), zeros included
    pattern = np.ones_like(a, bool)
    pattern[:n_b, :n_b] = a[:n_b, :n_b] != 0
    rows, cols = np.nonzero(pattern.T)  # column-major: CasADi's nonzero order
    sparsity = ca.Sparsity.triplet(*a.shape, cols.tolist(), rows.tolist())
    values = a.T[pattern.T]
    b = rng.normal(size=n_b + n_r)
    full = BorderedBand(sparsity, n_b)
    part = BorderedBand(sparsity, n_b, e_cols, f_rows)
    assert part.size == full.size - n_b * (2 * n_r - e_cols.size - f_rows.size)
    nz, rhs = ca.MX.sym("nz", values.size), ca.MX.sym("rhs", n_b + n_r)
    for layout in (full, part):
        solve = ca.Function("solve", [nz, rhs], [layout.solve(layout.factorize(nz), rhs)])
        assert np.abs(np.array(solve(values, b)).ravel() - np.linalg.solve(a, b)).max() < 1e-12
    wrong = BorderedBand(sparsity, n_b, e_cols[:-1], f_rows)
    solve = ca.Function("solve", [nz, rhs], [wrong.solve(wrong.factorize(nz), rhs)])
    assert np.abs(np.array(solve(values, b)).ravel() - np.linalg.solve(a, b)).max() > 1e-6


def test_the_border_couplings_are_the_step_jacobians(record_property):
    """The border columns and rows the compiled steps keep in ``E`` and ``F``
    (:meth:`ChunkResidual.couplings`) hold every nonzero of the step's iteration matrix there
    (evaluated at a state with the load on an element), and the ones left out are zero."""
    from symcat.codegen.library import symbolic_kernels
    from symcat.dae.formulation import Formulation
    from symcat.integrate.alpha_chunk_residual import ChunkResidual
    from symcat.integrate.alpha_step import StepEquations

    model = moving_load()
    model.center_windows()
    form = Formulation(model, "augmented", "1")
    st = StepEquations(form, "stabilized")
    with symbolic_kernels():
        residual = ChunkResidual(st, expand=True)
        n_b, n_y, n_u = st.bulk.n_b, st.n_y, st.n_u
        y_b, y_r, p = ca.MX.sym("y_b", n_b), ca.MX.sym("y_r", n_y - n_b), ca.MX.sym("p", 3 * n_u + 4)
        jac = ca.Function("j", [y_b, y_r, p], [residual.jacobian(y_b, y_r, p)])
    e_cols, f_rows = residual.couplings()
    rng = np.random.default_rng(0)
    y = np.zeros(n_y)
    y[:n_u] = np.r_[model.q0[model.free], model.s0] + 1e-3 * rng.normal(size=n_u)
    y[n_u:] = rng.normal(size=n_y - n_u)
    y[form.n_f] = 3.4  # the load's arc length: inside element 3
    data = np.r_[y[:n_u], np.zeros(2 * n_u), 0.01, 1e-6, 1e-3, 1.0]
    m = np.array(jac(y[:n_b], y[n_b:], data))
    record_property("couplings", [e_cols.tolist(), f_rows.tolist()])
    e_out = np.setdiff1d(np.arange(n_y - n_b), e_cols)
    f_out = np.setdiff1d(np.arange(n_y - n_b), f_rows)
    assert np.all(m[:n_b, n_b + e_out] == 0) and np.all(m[n_b + f_out, :n_b] == 0)
    assert np.all(np.abs(m[:n_b, n_b + e_cols]).max(axis=0) > 0)
    assert np.all(np.abs(m[n_b + f_rows, :n_b]).max(axis=1) > 0)
    assert e_out.size >= 2  # the driving's multipliers act on the body alone


def test_compiled_steps_of_a_spinning_cable_match_the_python_steps(record_property):
    """Wires only: the compiled steps refactorize their band in the code when the iteration
    slows, as the Python steps do; the two runs agree to the Newton tolerance."""
    python, compiled = _both(cable_pendulum, 0.5, 1e-3, rho_inf=0.8, tol=1e-10)
    apart = np.abs(compiled.q - python.q).max()
    record_property("apart_m", apart)
    assert compiled.stats["compiled_steps"] == compiled.stats["steps"] == 500
    assert "compiled_steps" not in python.stats
    assert apart < 1e-7
    assert compiled.stats["factorizations"] >= 1


def test_the_factor_renewed_in_a_call_is_the_next_calls(monkeypatch):
    """The compiled steps renew their factor in the caller's memory: a call that refactorized
    leaves it changed (the next call starts from it), one that did not leaves it as it was."""
    from symcat.integrate.alpha_chunk import CompiledSteps

    seen = []
    call = CompiledSteps._call

    def watched(self, s, t, n, states=None):
        renew, before = self._renew, self._factor.copy()
        count = self.integ.compiled_factorizations
        done = call(self, s, t, n, states)
        inside = self.integ.compiled_factorizations - count - renew
        if not renew:
            seen.append((inside, not np.array_equal(before, self._factor)))
        return done

    monkeypatch.setattr(CompiledSteps, "_call", watched)
    generalized_alpha(cable_pendulum(), 0.5, 1e-3, rho_inf=0.8, tol=1e-10, n_out=20, progress=False,
                      multipliers="integrator", compiled=True)
    assert any(inside for inside, _ in seen) and not all(inside for inside, _ in seen)
    assert all(bool(inside) == changed for inside, changed in seen)


def test_loaded_libraries_are_kept_for_the_next_runs_of_two_models(monkeypatch, tmp_path):
    """A run finds the functions (and their buffers) a former run of its model loaded; a third
    model's library puts out the least recently used one."""
    from symcat.integrate import alpha_chunk_cache as cache

    monkeypatch.setattr(cache, "_LOADED", {})
    a, b, c = (tmp_path / f"{name}.so" for name in "abc")  # (functions load at first use: none here)
    first = cache.loaded(a)
    assert cache.loaded(a) is first and first.path == a
    cache.loaded(b)
    cache.loaded(a)  # a used last: b goes first
    cache.loaded(c)
    assert cache.loaded(a) is first
    assert list(cache._LOADED) == [c, a]


def test_compiled_steps_of_a_body_on_a_sliding_joint_match_the_python_steps(record_property):
    """A body, its sliding joint's arc length and multipliers in the border of the matrix."""
    python, compiled = _both(slider, 0.2, 1e-3, rho_inf=0.9, tol=1e-10)
    apart = np.abs(compiled.q - python.q).max()
    s_apart = np.abs(compiled.s_m - python.s_m).max()
    record_property("apart_m", [apart, s_apart])
    assert compiled.stats["compiled_steps"] == 200
    assert apart < 1e-7 and s_apart < 1e-7
    assert np.abs(compiled.multipliers - python.multipliers).max() < 1e-5 * np.abs(python.multipliers).max()


def test_a_bead_crossing_element_ends_in_the_compiled_steps(record_property):
    """No free wire coordinate (a clamped ring: the matrix is all border); the bead crosses
    element ends inside the compiled calls, whose code holds the whole ring."""
    python, compiled = _both(lambda: ring(8, window=8), 0.4, 1e-3, rho_inf=0.9, tol=1e-10)
    assert compiled.s_m[-1, 0] - compiled.s_m[0, 0] > 2.0 * np.radians(350.0) / 8  # two element ends
    assert compiled.stats["compiled_steps"] == 400
    # both stop Newton within 1e-10 m of the step's solution; over 400 steps that adds up
    assert np.abs(compiled.s_m - python.s_m).max() < 1e-6


def test_steps_the_compiled_code_cannot_take_are_taken_in_python():
    """Steps so large that Newton fails even on a fresh matrix: those steps (halved) are the
    Python steps', the others compiled, and the run ends where the Python run ends."""
    python, compiled = _both(cable_pendulum, 0.2, 5e-3, rho_inf=0.8, tol=1e-8)
    assert 0 < compiled.stats["compiled_steps"] <= compiled.stats["steps"]
    assert np.abs(compiled.q[-1] - python.q[-1]).max() < 1e-2  # both at the step's error
    assert np.isfinite(compiled.q).all()


def moving_load(n_elements=12, window=3, speed=40.0, force=100.0):
    """A 1 g body driven along a taut 12 m wire on a sliding joint, carrying 100 N down (the
    peer bench's problem 2, shorter): it crosses an element every 25 ms."""
    from symcat.scene import Driving, PointLoad, RigidBody, SlidingJoint

    section = Section.from_stiffness(1.8e7, 195.0, 1e11)
    wire = AncfBody.straight("wire", "cable3d", [0, 0, 0], [12.0, 0, 0], n_elements,
                             Material(E=1e11, rho=1.35 * (1 + 2e4 / 1.8e7) / section.A), section, prestrain=2e4 / 1.8e7)
    wire.pin(0).pin(-1)
    scene = Scene(gravity=(0.0, 0.0, 0.0))
    scene.add(wire)
    scene.add(RigidBody("load", 1e-3, (1e-6,) * 3, (0.5, 0.0, 0.0), held=("rotation",)))
    scene.add(SlidingJoint("slider", "wire", "load", s0=0.5, at=(0.5, 0.0, 0.0), reference_direction=(0, 0, 1)))
    scene.add(Driving("drive", "load", direction=(1.0, 0.0, 0.0), velocity=speed))
    scene.add(PointLoad("force", "load", force=(0.0, -force, 0.0)))
    return MultibodyModel(scene, window=window)


@pytest.mark.parametrize("variant", ["stabilized", "index3"])
def test_a_load_crossing_elements_whose_window_moves(variant, record_property):
    """A window of 3 of 12 elements that moves with the load: the compiled code holds one proxy
    element, into whose places it writes the element holding the load, and a matrix border
    whose wire rows and columns follow it; the load crosses eight element ends. Both forms:
    the index-3 one has no velocity multipliers to move back from the proxy."""
    python, compiled = _both(moving_load, 0.2, 1e-3, rho_inf=1.0, tol=1e-10, variant=variant)
    crossed = compiled.s_m[-1, 0] - compiled.s_m[0, 0]
    apart = np.abs(compiled.q - python.q).max()
    record_property("apart_m", apart)
    assert crossed > 7.5  # metres: elements of 1 m
    assert compiled.stats["compiled_steps"] == 200
    assert apart < 1e-7 and np.abs(compiled.s_m - python.s_m).max() < 1e-7


def test_what_stays_in_python_says_why():
    """Wheel/rail contacts, or windows that move without proxy elements; and compiled=False."""
    from types import SimpleNamespace

    wheels = SimpleNamespace(model=SimpleNamespace(wheelrail=[object()]))
    assert "wheel/rail" in unsupported(wheels)
    no_proxy = SimpleNamespace(model=slider(window=2), stepper=SimpleNamespace(proxies=None))
    assert "without proxy elements" in unsupported(no_proxy)
    run = generalized_alpha(cable_pendulum(), 0.01, 1e-3, n_out=2, progress=False, compiled=False)
    assert "compiled_steps" not in run.stats


def test_compiled_steps_of_a_penalty_contact_that_opens_and_closes(record_property):
    """A head launched down from a wire (penalty contact, damped wire): the contact's arc length
    is an unknown of the step and its tangency a row; the contact opens and closes inside the
    compiled calls; index-3 variant."""
    from tests.dynamics.test_contact import head_under_wire

    def make():
        return head_under_wire(v0=-2.0)[0]

    python, compiled = _both(make, 0.15, 5e-4, rho_inf=0.9, tol=1e-10, variant="index3")
    apart = np.abs(compiled.q - python.q).max()
    record_property("apart_m", apart)
    assert compiled.stats["compiled_steps"] > 0.9 * compiled.stats["steps"]
    assert apart < 1e-6
    gap = compiled.contacts["contact"]["gap_m"]
    assert (gap > 0).any() and (gap <= 0).any()  # it opened and closed


def test_a_per_step_monitor_on_compiled_steps(record_property):
    """A per-step monitor (what a passage records at every step) with the steps compiled, the
    steps of an output interval in one call that records each step's state: the same records,
    step for step, as the Python steps' (positions, velocities, accelerations, contact gap and
    force), within the Newton tolerance; the contact opens and closes in between."""
    from unittest import mock

    from symcat.integrate.alpha_chunk import CompiledSteps
    from tests.dynamics.test_contact import head_under_wire

    def monitor(s):
        return {"gap_m": s.gap_m.copy(), "force_N": s.force_N.copy(), "head_z_m": s.q[:, -1],
                "head_vz_m_s": s.v[:, -1], "head_az_m_s2": s.a[:, -1]}

    calls = []
    original = CompiledSteps._call

    def counted(self, *args):
        calls.append(args[2])
        return original(self, *args)

    runs = []
    for compiled in (False, True):
        with mock.patch.object(CompiledSteps, "_call", counted):
            runs.append(generalized_alpha(head_under_wire(v0=-2.0)[0], 0.15, 5e-4, rho_inf=0.9, n_out=20,
                                          progress=False, multipliers="integrator", tol=1e-10, variant="index3",
                                          monitor=monitor, compiled=compiled))
    python, compiled = (np.asarray(r.monitored["gap_m"]).ravel() for r in runs)
    assert runs[1].stats["compiled_steps"] == runs[1].stats["steps"] == 300
    assert len(calls) == 20  # one call per output interval of 15 steps, each step recorded
    assert len(runs[1].monitored["t_s"]) == 301
    assert np.allclose(runs[1].monitored["t_s"], runs[0].monitored["t_s"], rtol=0, atol=1e-12)
    apart = np.abs(compiled - python).max()
    record_property("apart_m", apart)
    assert apart < 1e-6
    for key, scale in (("head_z_m", 1e-6), ("head_vz_m_s", 1e-3), ("head_az_m_s2", 1.0), ("force_N", 0.1)):
        a, b = (np.asarray(r.monitored[key]).ravel() for r in runs)
        record_property(f"{key}_apart", float(np.abs(a - b).max()))
        assert a.shape == b.shape == (301,)
        assert np.abs(a - b).max() < scale, key
    assert np.abs(runs[1].monitored["force_N"]).max() > 10.0  # (the forces compared are not all zero)
    assert (compiled > 0).any() and (compiled <= 0).any()
