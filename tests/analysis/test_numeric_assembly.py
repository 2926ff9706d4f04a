"""The numeric (NumPy/SciPy) evaluation of an assembled system against its CasADi graphs:
forces, tangent stiffness, damping matrices and slope moments, on element types with dense
and sparse element matrices, linearized wires and moments."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from symcat.assembly import assemble
from symcat.assembly.sparse import to_scipy
from symcat.scene import AncfBody, Material, Scene, Section, SlopeMoment


def _scene(element: str, damped: bool, moment: bool, linear: bool) -> Scene:
    dim = 2 if element == "cable2d" else 3
    end = np.zeros(dim)
    end[0] = 6.0
    extra = dict(damping_axial=1e-3, damping_bending=2e-3) if damped else {}
    wire = AncfBody.straight("w", element, np.zeros(dim), end, 5, Material(1e10, 7800), Section.circle(0.01),
                             prestrain=1e-3, **extra)
    wire.pin(0)
    scene = Scene(gravity=(0.0, 0.0, -9.81)[:dim] if dim == 3 else (0.0, -9.81), linear_wires=linear)
    scene.add(wire)
    if moment:
        scene.add(SlopeMoment("w", -1, 40.0, (0.0, 0.0, 1.0)))
    return scene


CASES = [("cable3d", True, False, False), ("beam3d", True, False, False), ("cable2d", False, True, False),
         ("cable3d", False, False, True), ("beam3d", False, True, False)]


@pytest.mark.parametrize("element, damped, moment, linear", CASES)
def test_numeric_forces_and_jacobians_equal_the_graphs(element, damped, moment, linear, rng):
    system = assemble(_scene(element, damped, moment, linear))
    n = system.n
    q = np.array(system.dofs.q0, float) + 1e-2 * rng.standard_normal(n)
    v = rng.standard_normal(n)
    qs, vs = ca.MX.sym("q", n), ca.MX.sym("v", n)
    f = system.internal_force(qs, vs) + system.external_force(qs)
    graph = ca.Function("g", [qs, vs], [f, -ca.jacobian(f, qs), -ca.jacobian(f, vs), system.tangent_stiffness(qs)])
    f_ref, k_ref, c_ref, kt_ref = (to_scipy(ca.DM(x)) for x in graph(q, v))
    f_num = system.eval_internal_force(q, v) + system.external_force_value(q)
    scale = np.abs(f_ref.toarray()).max()
    np.testing.assert_allclose(f_num, f_ref.toarray().ravel(), rtol=0, atol=1e-12 * scale)
    k, c = system.eval_force_jacobians(q, v)
    k_scale = abs(k_ref).max()
    assert abs(k - k_ref).max() <= 1e-12 * k_scale
    if damped:
        assert abs(c - c_ref).max() <= 1e-12 * abs(c_ref).max()
    else:
        assert abs(c).max() == 0.0 and abs(c_ref).max() == 0.0
    assert abs(system.eval_tangent_stiffness(q) - kt_ref).max() <= 1e-12 * k_scale
    # the patterns are fixed: a state where values cancel keeps them
    sums = system.force_jacobian_patterns(True)
    assert k.nnz == sums[0].nnz and np.array_equal(k.indices, sums[0].indices)
    # the static Jacobian (no velocities, a load factor on the external forces)
    k_static, none = system.eval_force_jacobians(q, load_factor=0.3)
    f_static = system.internal_force(qs) + 0.3 * system.external_force(qs)
    ref = to_scipy(ca.DM(ca.Function("s", [qs], [-ca.jacobian(f_static, qs)])(q)))
    assert none is None and abs(k_static - ref).max() <= 1e-12 * k_scale


def test_pattern_sum_keeps_the_union_of_the_patterns_when_values_cancel():
    """PatternSum: the sum of sparse terms on the fixed union of their patterns (an entry whose
    values cancel stays, explicit), equal to SciPy's sum; one, several and empty terms."""
    import scipy.sparse as sps

    from symcat.assembly.sparse import PatternSum

    shape = (40, 30)
    terms = [sps.random(*shape, density=d, random_state=k, format="csc") for k, d in enumerate((0.1, 0.2, 0.0, 0.05))]
    for t in terms:
        t.sort_indices()
    terms.append(-terms[0])  # cancels the first term's values: its entries stay in the pattern
    for chosen in ([0], [0, 1], [0, 1, 2, 3, 4], [2]):
        picked = [terms[i] for i in chosen]
        s = PatternSum([(t.indptr, t.indices) for t in picked], shape)
        union = sum(sps.csc_matrix((np.ones(t.nnz), t.indices, t.indptr), shape=shape) for t in picked)
        got = s.csc([t.data for t in picked])
        assert got.nnz == s.nnz == sps.csc_matrix(union).nnz  # the union, explicit zeros included
        pattern = sps.csc_matrix((np.ones(s.nnz), s.indices, s.indptr), shape=shape).toarray()
        assert np.array_equal(pattern > 0, np.asarray(union.todense()) > 0)
        np.testing.assert_allclose(got.toarray(), sum(t.toarray() for t in picked), atol=1e-15)
