"""Statics, modes and Cholesky coordinates on assembled systems."""
from __future__ import annotations

import importlib

import numpy as np
import pytest
import scipy.sparse as sps

from symcat.analysis import modes, solve_static
from symcat.assembly import CholeskyCoordinates, assemble
from symcat.errors import SolverError
from symcat.scene import AncfBody, Material, NodalForce, Scene, Section


def _wire(element="cable3d", n=12, prestrain=1e-3, gravity=(0.0, 0.0, 0.0)):
    dim = 2 if element == "cable2d" else 3
    end = np.zeros(dim)
    end[0] = 10.0
    wire = AncfBody.straight("w", element, np.zeros(dim), end, n, Material(1e11, 8900), Section.circle(0.012), prestrain=prestrain)
    wire.pin(0).pin(-1)
    scene = Scene(gravity=gravity)
    scene.add(wire)
    return scene, wire


def test_cholesky_coordinates_make_the_mass_matrix_the_identity(rng):
    scene, _ = _wire("beam3d", 6)
    system = assemble(scene)
    free = system.dofs.free
    m = system.mass_matrix[free][:, free]
    chol = CholeskyCoordinates(m)
    u = chol.factor().toarray()
    assert np.allclose(np.triu(u), u)
    np.testing.assert_allclose(u.T @ u, m.toarray(), rtol=1e-12, atol=1e-12 * abs(m).max())
    e_dot = rng.standard_normal(free.size)
    p_dot = chol.to_cholesky(e_dot)
    assert 0.5 * p_dot @ p_dot == pytest.approx(0.5 * e_dot @ (m @ e_dot), rel=1e-12)  # identity mass
    np.testing.assert_allclose(chol.from_cholesky(p_dot), e_dot, rtol=1e-9, atol=1e-9)
    q_e = rng.standard_normal(free.size)
    # Virtual work is invariant: Q_p . dp = Q_e . de.
    assert chol.force_to_cholesky(q_e) @ p_dot == pytest.approx(q_e @ e_dot, rel=1e-9)
    assert chol.bandwidth < 2 * 24  # banded along the chain: the factor is sparse


def test_mass_matrix_total_mass_and_sparsity():
    scene, wire = _wire("cable3d", 10)
    system = assemble(scene)
    m = system.mass_matrix
    v = np.zeros(system.n)
    v[0::6] = 1.0  # rigid x translation: position x-coordinates only
    assert v @ (m @ v) == pytest.approx(wire.mass(), rel=1e-12)
    assert sps.issparse(m) and m.nnz < 0.2 * system.n**2
    # the SciPy assembly against the elements' matrices scattered by the CasADi graph that
    # assembles the stiffness
    import casadi as ca

    from symcat.assembly.sparse import to_scipy

    es = system.element_sets[0]
    blocks = es._map(f"{es.element.name}_mass")(es._p)
    scattered = to_scipy(ca.Function("mass", [ca.MX.sym("q", 0)], [es._scatter_matrix(blocks)])(ca.DM(0, 1)))
    assert abs(es.mass_matrix() - scattered).max() <= 1e-15 * abs(scattered).max()


def test_sparse_and_dense_eigensolvers_agree(monkeypatch):
    scene, _ = _wire("cable2d", 30)
    system = assemble(scene)
    q = solve_static(system).q
    dense = modes(system, q, 6).frequencies_hz
    monkeypatch.setattr(importlib.import_module("symcat.analysis.modes"), "DENSE_LIMIT", 0)
    sparse = modes(system, q, 6).frequencies_hz
    np.testing.assert_allclose(sparse, dense, rtol=1e-9)


def test_gravity_sag_balances_the_weight():
    """Support reactions of a sagging wire sum to its weight (global equilibrium)."""
    scene, wire = _wire("cable3d", 16, prestrain=2e-4, gravity=(0.0, 0.0, -9.81))
    system = assemble(scene)
    q = solve_static(system).q
    residual = system.eval_static(q, 1.0)[0]  # zero on free coordinates; minus the reactions on fixed ones
    assert np.abs(residual[system.dofs.free]).max() < 1e-6
    vertical = [system.dofs.index(wire, node, "z") for node in (0, -1)]
    assert -residual[vertical].sum() == pytest.approx(wire.mass() * 9.81, rel=1e-9)


def test_a_mechanism_fails_with_a_clear_error_and_keeps_the_partial_result():
    wire = AncfBody.straight("w", "cable2d", [0, 0], [1, 0], 4, Material(1e9, 1000), Section.circle(0.01))
    wire.pin(0)  # free to swing: no static equilibrium under a transverse load
    scene = Scene()
    scene.add(wire)
    scene.add(NodalForce("w", -1, (0.0, -1.0)))
    with pytest.raises(SolverError) as info:
        solve_static(assemble(scene), max_iterations=8, min_step=0.05)
    assert "load factor" in str(info.value) and info.value.partial is not None
    assert info.value.partial.load_factor < 1


def test_wire_pulled_by_a_prescribed_end_tension():
    """One end pinned, the other free to slide along the axis under a dead force T: the wire
    stretches by T L / EA and carries T (checked through the strain kernel)."""
    section = Section.circle(0.012)
    material = Material(1.2e11, 8900)
    wire = AncfBody.straight("w", "cable3d", [0, 0, 0], [20.0, 0, 0], 10, material, section)
    wire.pin(0).fix(-1, ["y", "z"])
    scene = Scene()
    scene.add(wire)
    scene.add(NodalForce("w", -1, (15e3, 0.0, 0.0)))
    system = assemble(scene)
    q = solve_static(system).q
    ea = material.E * section.A
    assert q[system.dofs.index(wire, -1, "x")] == pytest.approx(20.0 * (1 + 15e3 / ea), rel=1e-12)
    eps = system.body_set("w").lib["cable3d_strain"](q[system.dofs.element_indices(wire)[3]], 0.3, wire.params[3])[0]
    assert float(eps) * ea == pytest.approx(15e3, rel=1e-9)


def _cantilever(element="cable2d", n=64, alpha=3.0):
    """Clamped 2 m steel beam, square 0.1 m section, tip load alpha E I / L^2 in -y."""
    dim = 2 if element == "cable2d" else 3
    section = Section.rectangle(0.1, 0.1)
    end = np.zeros(dim)
    end[0] = 2.0
    beam = AncfBody.straight("b", element, np.zeros(dim), end, n, Material(2.07e11, 7850.0), section)
    beam.clamp(0)
    force = np.zeros(dim)
    force[1] = -alpha * 2.07e11 * section.Iz / 4.0
    scene = Scene()
    scene.add(beam)
    scene.add(NodalForce("b", -1, tuple(force)))
    return assemble(scene), beam


@pytest.mark.parametrize("element", ["cable2d", "cable3d"])
def test_cantilever_converges_in_one_load_step_of_plain_newton(element):
    """The large-deflection cantilever (alpha = 3) from straight in one load step of plain
    Newton (the damped iteration with its line search needs many more), on the extensible
    elastica (exudyn-peers.md, problem 3)."""
    system, beam = _cantilever(element)
    result = solve_static(system)
    assert result.load_steps == 1 and result.newton_iterations < 10
    tip = result.q[system.dofs.node_indices(beam, -1)][:2]
    np.testing.assert_allclose(tip, [2.0 - 0.5085373043, -1.2072398545], atol=1e-8)


def test_the_damped_newton_takes_over_when_plain_newton_fails(monkeypatch):
    statics = importlib.import_module("symcat.analysis.statics")
    system, beam = _cantilever(n=16)
    plain = solve_static(system).q
    monkeypatch.setattr(statics, "_plain_newton", lambda newton, q, *args: (False, q, 1, "forced failure"))
    damped = solve_static(system)
    assert damped.newton_iterations > 1  # the damped iteration did the work
    np.testing.assert_allclose(damped.q, plain, atol=1e-9)


def test_banded_and_general_sparse_newton_steps_agree(rng):
    """The band LU (reverse Cuthill-McKee order) and SuperLU solve the same free tangent as
    the full system's Jacobian restricted to the free coordinates."""
    statics = importlib.import_module("symcat.analysis.statics")
    system, _ = _cantilever("cable3d", n=12)
    q = system.dofs.q0 + 1e-3 * rng.standard_normal(system.n)
    free = system.dofs.free
    newton = statics._FreeNewton(system, free)
    assert newton.banded
    r, jac_nz = newton.evaluate(q, 0.7)
    r_full, jac_full = system.eval_static(q, 0.7)
    np.testing.assert_allclose(r, r_full[free], rtol=1e-12, atol=1e-6)
    rhs = rng.standard_normal(free.size)
    expected = np.linalg.solve(jac_full[free][:, free].toarray(), rhs)
    np.testing.assert_allclose(newton.solve(jac_nz, rhs), expected, rtol=1e-8, atol=1e-14)
    newton.banded = False
    np.testing.assert_allclose(newton.solve(jac_nz, rhs), expected, rtol=1e-8, atol=1e-14)


def test_a_solved_system_is_freed_with_its_last_reference():
    """The static solver's set-up is kept with its system, not in a table that outlives it: a
    process that builds and solves many systems (a study's worker, the line's form finding)
    keeps none of them (each of a line's held some 140 MB)."""
    import gc
    import weakref

    scene, _ = _wire("cable3d", 16, prestrain=2e-4, gravity=(0.0, 0.0, -9.81))
    system = assemble(scene)
    solve_static(system)
    gone = weakref.ref(system)
    del system
    gc.collect()
    assert gone() is None
