"""The form-found catenary as a multibody scene: same statics and masses as CatenaryStructure."""
import casadi as ca
import numpy as np
import pytest

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary import CatenaryStructure, benchmark2015, en50318, find_form
from symcat.catenary.scene import catenary_scene, support_forces
from symcat.errors import ParameterError
from symcat.scene import AncfBody, Material, NodalForce, NodalMass, RayleighDamping, RigidBody, Scene, Section

SPANS, ELEMENTS = 3, 10


@pytest.fixture(scope="module")
def form():
    return find_form(benchmark2015(SPANS), ELEMENTS, progress=False)


@pytest.fixture(scope="module")
def solved(form):
    """The scene assembled and solved from the design mesh (contact wire at the target height,
    a parabolic messenger: up to 8 cm away from the static state), not from form.q."""
    scene = catenary_scene(form, rayleigh="omit")
    model = MultibodyModel(scene)
    model.q0 = CatenaryStructure(form.structure.design, ELEMENTS).q0.copy()
    assert np.abs(model.q0 - form.q).max() > 0.05
    return scene, model, solve_equilibrium(model)


def _dropper_tensions(scene, q, st):
    """Tensions (N) of the scene's droppers from their scene data (stiffness, free length)."""
    out = []
    for i, row in enumerate(st.dropper_nodes):
        f = next(e for e in scene.force_elements if e.name == f"dropper_{i}")
        length = np.linalg.norm(q[st.mw_xyz[row]] - q[st.cw_xyz[row]])
        out.append(max(f.stiffness * (length - f.free_length), 0.0))
    return np.array(out)


def _total_mass(mass, st):
    """Translational mass (kg): e^T M e with e = 1 on the x-position coordinates of every node."""
    e = np.zeros(mass.shape[0])
    e[st.cw_xyz[:, 0]] = 1.0
    e[st.mw_xyz[:, 0]] = 1.0
    return float(e @ (mass @ e))


def test_scene_contents(form):
    st, d = form.structure, form.structure.design
    scene = catenary_scene(form, rayleigh="omit")
    assert [b.name for b in scene.bodies] == ["contact", "messenger"]
    assert all(isinstance(b, AncfBody) and b.element.name == "cable3d" for b in scene.bodies)
    for mine, theirs in zip(scene.bodies, st.scene.bodies):
        np.testing.assert_array_equal(mine.params, theirs.params)  # form-found prestrain and density
        assert mine.fixed == theirs.fixed
    droppers = [f for f in scene.force_elements if f.name.startswith("dropper_")]
    assert len(droppers) == SPANS * len(d.dropper_positions)
    assert all(f.tension_only for f in droppers)
    np.testing.assert_allclose([f.free_length for f in droppers], form.dropper_length_m, rtol=0, atol=0)
    np.testing.assert_allclose([f.stiffness for f in droppers], d.dropper_EA / form.dropper_length_m)
    supports = [f for f in scene.force_elements if not f.name.startswith("dropper_")]
    assert len(supports) == 2 * (SPANS - 1) and not any(f.tension_only for f in supports)
    masses = [x for x in scene.loads if isinstance(x, NodalMass)]
    assert len(masses) == 2 * len(droppers)  # clamps with half droppers; no steady-arm mass here
    tensions = [x for x in scene.loads if isinstance(x, NodalForce)]
    assert sorted(x.force[0] for x in tensions) == [d.messenger_wire.tension, d.contact_wire.tension]
    # stagger: the contact wire zigzags +/- 0.2 m between supports
    np.testing.assert_allclose(scene.bodies[0].q0[st.cw_supports.nodes, 1], d.stagger * (-1.0) ** np.arange(1, SPANS))


def test_static_state_is_an_equilibrium_of_the_scene(form):
    model = MultibodyModel(catenary_scene(form, rayleigh="omit"))
    assert model.coordinate_names()[: form.structure.n] == form.structure.system.dofs.names()
    eq = solve_equilibrium(model)
    assert eq.iterations == 0 and eq.residual_N < 1e-5
    np.testing.assert_array_equal(eq.q, form.q)


def test_equilibrium_equals_form_found_state(form, solved):
    st = form.structure
    scene, _, eq = solved
    q = eq.q[: st.n]
    rows = np.concatenate([st.dropper_nodes, st.cw_supports.nodes])
    heights = q[st.cw_xyz[rows, 2]]
    assert np.abs(heights - form.q[st.cw_xyz[rows, 2]]).max() < 1e-7
    assert np.abs(heights - st.target_z[rows]).max() < 1e-7
    assert np.abs(q - form.q).max() < 1e-7  # every coordinate, messenger included
    tension = _dropper_tensions(scene, q, st)
    np.testing.assert_allclose(tension, form.dropper_tension_N, rtol=1e-6)


def test_total_vertical_reaction_is_the_total_weight(form, solved):
    st = form.structure
    scene, model, eq = solved
    qs, vs = ca.MX.sym("q", model.n_q), ca.MX.sym("v", model.n_q)
    f = np.asarray(ca.Function("f", [qs, vs], [model.forces(qs, vs, ca.MX(0.0))])(eq.q, np.zeros(model.n_q))).ravel()
    z = np.r_[st.cw_xyz[:, 2], st.mw_xyz[:, 2]]
    pins = -f[np.setdiff1d(z, model.free)].sum()  # reactions of the wire ends
    unbalanced = f[np.intersect1d(z, model.free)].sum()  # what the solver's tolerance leaves (~1e-5 N)
    springs = support_forces(form, scene, eq.q).sum()
    weight = _total_mass(st.mass_matrix, st) * st.design.gravity
    assert pins + springs == pytest.approx(weight, rel=1e-7)
    assert pins + springs - unbalanced == pytest.approx(weight, rel=1e-12)
    # the springs carry the form-found preloads at the design height
    preloads = np.r_[st.cw_supports.preload, st.mw_supports.preload]
    np.testing.assert_allclose(support_forces(form, scene, eq.q), preloads, rtol=1e-6)


def test_mass_matrix_equals_the_structure(form, solved):
    st, d = form.structure, form.structure.design
    _, model, _ = solved
    diff = model.ancf.mass_matrix - st.mass_matrix
    assert abs(diff).max() < 1e-12 * abs(st.mass_matrix).max()
    wires = sum(b.mass() for b in st.scene.bodies)
    lumped = st.dropper_nodes.size * (d.clamp_mass_contact + d.clamp_mass_messenger) \
        + d.dropper_mass_per_length * form.dropper_length_m.sum() + d.steady_arm_mass * st.cw_supports.nodes.size
    assert _total_mass(model.ancf.mass_matrix, st) == pytest.approx(wires + lumped, rel=1e-12)


def test_forces_and_stiffness_equal_the_structure(form):
    """At the static state the assembled scene's generalized forces and tangent stiffness are
    the structure's, except the leaning of the support springs: a horizontal stiffness
    force / anchor at each support node (the structure's supports act in z only)."""
    from symcat.assembly.sparse import to_scipy
    from symcat.catenary.scene import SUPPORT_ANCHOR

    st = form.structure
    scene = catenary_scene(form, rayleigh="omit")
    model = MultibodyModel(scene)
    qs, vs = ca.MX.sym("q", model.n_q), ca.MX.sym("v", model.n_q)
    f = model.forces(qs, vs, ca.MX(0.0))
    jac, force = ca.Function("jf", [qs, vs], [ca.jacobian(f, qs), f])(form.q, np.zeros(model.n_q))
    np.testing.assert_allclose(np.asarray(force).ravel(), st.forces(form.q), rtol=0, atol=1e-8)
    diff = -to_scipy(jac).toarray() - st.stiffness(form.q).toarray()
    rows = np.r_[st.cw_xyz[st.cw_supports.nodes], st.mw_xyz[st.mw_supports.nodes]]
    for r, force_up in zip(rows, support_forces(form, scene, form.q)):
        for axis in (0, 1):
            diff[r[axis], r[axis]] -= force_up / SUPPORT_ANCHOR
    assert np.abs(diff).max() < 1e-8 * np.abs(st.stiffness(form.q)).max()


@pytest.mark.parametrize("design, element, start", [
    (en50318(3), "cable3d", "mesh"),                                 # constant dropper stiffness, no clamps
    (benchmark2015(3), "beam3d", "mesh"),                            # beam wires (torsion fixed at node 0)
    (benchmark2015(6).with_(n_sections=2), "cable3d", "mesh"),       # two tension sections, overlap
], ids=["en50318", "beam3d", "two_sections"])
def test_other_designs(design, element, start):
    form = find_form(design, ELEMENTS, element, progress=False)
    st = form.structure
    scene = catenary_scene(form, start=start, rayleigh="omit")
    if design.n_sections == 2:
        assert [b.name for b in scene.bodies] == ["contact_1", "messenger_1", "contact_2", "messenger_2"]
    model = MultibodyModel(scene)
    eq = solve_equilibrium(model)
    q = eq.q[: st.n]
    rows = np.concatenate([st.dropper_nodes, st.cw_supports.nodes])
    assert np.abs(q[st.cw_xyz[rows, 2]] - form.q[st.cw_xyz[rows, 2]]).max() < 1e-7
    np.testing.assert_allclose(_dropper_tensions(scene, q, st), form.dropper_tension_N, rtol=1e-6)
    assert _total_mass(model.ancf.mass_matrix, st) == pytest.approx(_total_mass(st.mass_matrix, st), rel=1e-12)


def test_unsupported_and_bad_inputs(form):
    with pytest.raises(ParameterError, match="rayleigh="):
        catenary_scene(form, rayleigh="keep")
    with pytest.raises(ParameterError, match="start="):
        catenary_scene(form, start="guess", rayleigh="omit")
    with pytest.raises(ParameterError, match="FormFindingResult"):
        catenary_scene(form.structure, rayleigh="omit")
    with pytest.raises(ParameterError, match="gravity"):
        catenary_scene(form, rayleigh="omit", scene=Scene())
    st = form.structure
    st.linearize_wires(form.q)
    try:
        with pytest.raises(ParameterError, match="linearized"):
            catenary_scene(form, rayleigh="omit")
    finally:
        st.linearize_wires(None)
    scene = Scene()
    scene.add(AncfBody.straight("w", "cable3d", [0, 0, 0], [1, 0, 0], 2, Material(1e9, 1e3), Section.rectangle(0.01, 0.01)))
    with pytest.raises(ParameterError, match="mass"):
        scene.add(NodalMass("w", 1, -1.0))
    with pytest.raises(ParameterError, match="node"):
        scene.add(NodalMass("w", 5, 1.0))


def test_nodal_mass_adds_mass_and_weight():
    scene = Scene(gravity=(0.0, 0.0, -9.81))
    wire = AncfBody.straight("w", "cable3d", [0, 0, 0], [1, 0, 0], 2, Material(1e9, 1e3), Section.rectangle(0.01, 0.01))
    scene.add(wire)
    bare = MultibodyModel(scene).ancf
    m0, f0 = bare.mass_matrix.toarray(), bare._constant_load.copy()
    scene.add(NodalMass("w", 1, 2.5))
    system = MultibodyModel(scene).ancf
    dm = system.mass_matrix.toarray() - m0
    idx = system.dofs.node_indices(wire, 1)[:3]
    np.testing.assert_allclose(np.diag(dm)[idx], 2.5)
    assert abs(dm).sum() == pytest.approx(7.5)
    np.testing.assert_allclose((system._constant_load - f0)[idx], [0.0, 0.0, -2.5 * 9.81])


# --- Rayleigh damping --------------------------------------------------------------------------
def _jacobians(model, q):
    """``-dQ/dq`` and ``-dQ/dv`` of the assembled forces at ``(q, v = 0)`` (dense, all coordinates)."""
    from symcat.assembly.sparse import to_scipy

    qs, vs = ca.MX.sym("q", model.n_q), ca.MX.sym("v", model.n_q)
    f = model.forces(qs, vs, ca.MX(0.0))
    jq, jv = ca.Function("j", [qs, vs], [ca.jacobian(f, qs), ca.jacobian(f, vs)])(q, np.zeros(model.n_q))
    return -to_scipy(jq).toarray(), -to_scipy(jv).toarray()


def _structure_damping(st, q):
    """The structure's own Rayleigh matrix ``alpha M + beta K0`` (its mass matrix and its
    stiffness at ``q`` with every dropper taut, all coordinates)."""
    d = st.design
    return (d.rayleigh_alpha * st.mass_matrix + d.rayleigh_beta * st.stiffness(q, droppers_taut=True)).toarray()


def test_rayleigh_damping_matrix_equals_the_structure(form):
    st, d = form.structure, form.structure.design
    assert d.rayleigh_alpha > 0 and d.rayleigh_beta > 0
    scene = catenary_scene(form)  # default: carries the design's damping
    (ray,) = scene.damping
    assert ray.bodies == ("contact", "messenger") and (ray.alpha, ray.beta) == (d.rayleigh_alpha, d.rayleigh_beta)
    _, c_scene = _jacobians(MultibodyModel(scene), form.q)
    _, c_bare = _jacobians(MultibodyModel(catenary_scene(form, rayleigh="omit")), form.q)
    c = c_scene - c_bare  # the dropper dampers (none in this design) cancel
    c_st = _structure_damping(st, form.q)
    f = st.free
    assert np.abs(c_st).max() > 1.0
    assert np.abs(c[np.ix_(f, f)] - c_st[np.ix_(f, f)]).max() <= 1e-12 * np.abs(c_st).max()
    # the same matrix whatever the start: K0 is the structure's at the static state
    _, c_mesh = _jacobians(MultibodyModel(catenary_scene(form, start="mesh")), form.q)
    assert np.abs(c_mesh - c_scene).max() <= 1e-12 * np.abs(c_st).max()


def test_rayleigh_free_decay(form):
    """A small velocity along a ~10 Hz mode (IDAS, 0.5 s): the energy the run loses is the work
    of ``v^T C v``, and the mode's energy decays at ``alpha + beta omega^2`` (twice the
    amplitude rate ``alpha / 2 + beta omega^2 / 2``)."""
    import scipy.linalg

    from symcat.integrate.simulate import simulate

    d = form.structure.design
    model = MultibodyModel(catenary_scene(form))
    f = model.free
    k_all, c_all = _jacobians(model, form.q)
    k, c = k_all[np.ix_(f, f)], c_all[np.ix_(f, f)]
    m = model.ancf.mass_matrix.toarray()[np.ix_(f, f)]
    w2, phi = scipy.linalg.eigh(0.5 * (k + k.T), m)
    mode = int(np.argmin(np.abs(np.sqrt(np.abs(w2)) / (2 * np.pi) - 10.0)))
    rate = d.rayleigh_alpha + d.rayleigh_beta * w2[mode]
    assert phi[:, mode] @ c @ phi[:, mode] == pytest.approx(rate, rel=1e-6)  # nearly a modal damping
    model.v0 = np.zeros(model.n_q)
    model.v0[f] = 1e-3 * phi[:, mode] / np.abs(phi[:, mode]).max()
    res = simulate(model, 0.5, rtol=1e-8, atol=1e-10, n_out=100, progress=False)
    dq, v = res.q[:, f] - form.q[f], res.v[:, f]
    energy = 0.5 * np.einsum("ti,ij,tj->t", v, m, v) + 0.5 * np.einsum("ti,ij,tj->t", dq, k, dq)
    power = np.einsum("ti,ij,tj->t", v, c, v)
    dissipated = np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(res.t_s))
    assert power[0] == pytest.approx(model.v0[f] @ _structure_damping(form.structure, form.q)[np.ix_(f, f)] @ model.v0[f],
                                     rel=1e-12)
    assert energy[0] - energy[-1] == pytest.approx(dissipated, rel=2e-3)
    assert dissipated > 0.1 * energy[0]
    assert -np.polyfit(res.t_s, np.log(energy), 1)[0] == pytest.approx(rate, rel=1e-2)


def test_rayleigh_at_initial_state_of_a_wire():
    """``stiffness_at='initial'`` (the bodies' element stiffness at q0) and a given state."""
    from symcat.assembly.sparse import to_scipy

    scene = Scene(gravity=(0.0, 0.0, -9.81))
    wire = AncfBody.straight("w", "cable3d", [0, 0, 0], [2, 0, 0], 4, Material(1e9, 1e3), Section.rectangle(0.01, 0.01),
                             prestrain=1e-3)
    scene.add(wire)
    scene.add(NodalMass("w", 2, 0.5))
    scene.add(RayleighDamping(("w",), 0.3, 2e-3))
    model = MultibodyModel(scene)
    sys_ = model.ancf
    qs = ca.MX.sym("q", sys_.n)
    k_fn = ca.Function("k", [qs], [sys_.tangent_stiffness(qs)])
    expected = 0.3 * sys_.mass_matrix.toarray() + 2e-3 * to_scipy(ca.DM(k_fn(sys_.dofs.q0))).toarray()
    _, c = _jacobians(model, model.q0)
    assert np.abs(c - expected).max() <= 1e-12 * np.abs(expected).max()
    bent = sys_.dofs.q0.copy()
    bent[2::6] += 0.01 * np.sin(np.linspace(0, np.pi, bent[2::6].size))
    at = Scene(gravity=scene.gravity)
    at.add(wire)
    at.add(RayleighDamping(("w",), 0.0, 2e-3, stiffness_at=bent))
    np.testing.assert_allclose(MultibodyModel(at).ancf.rayleigh_matrix.toarray(),
                               2e-3 * to_scipy(ca.DM(k_fn(bent))).toarray(), rtol=0, atol=1e-12 * np.abs(expected).max())


def test_rayleigh_bad_inputs():
    scene = Scene()
    scene.add(AncfBody.straight("w", "cable3d", [0, 0, 0], [1, 0, 0], 2, Material(1e9, 1e3), Section.rectangle(0.01, 0.01)))
    n = scene.bodies[0].q0.size
    bad = [
        (RayleighDamping((), 0.1, 0.0), "bodies=()"),
        (RayleighDamping("w", 0.1, 0.0), "bodies='w'"),
        (RayleighDamping(("w", "w"), 0.1, 0.0), "twice"),
        (RayleighDamping(("x",), 0.1, 0.0), "body='x'"),
        (RayleighDamping(("w",), -0.1, 0.0), "alpha=-0.1"),
        (RayleighDamping(("w",), float("nan"), 0.0), "alpha=nan"),
        (RayleighDamping(("w",), 0.1, -1e-3), "beta=-0.001"),
        (RayleighDamping(("w",), 0.1, "0.1"), "beta='0.1'"),
        (RayleighDamping(("w",), 0.1, 1e-3, stiffness=np.eye(3)), r"stiffness: shape \(3, 3\)"),
        (RayleighDamping(("w",), 0.1, 1e-3, stiffness=np.full((n, n), np.inf)), "non-finite"),
        (RayleighDamping(("w",), 0.1, 1e-3, stiffness_at="static"), "stiffness_at='static'"),
        (RayleighDamping(("w",), 0.1, 1e-3, stiffness_at=np.zeros(3)), "stiffness_at=\\(3,\\)"),
    ]
    for item, message in bad:
        with pytest.raises(ParameterError, match=message):
            scene.add(item)
    scene.add(RigidBody("r", 1.0, (1.0, 1.0, 1.0), (0.0, 0.0, 1.0)))
    with pytest.raises(ParameterError, match="'r' is a rigid body"):
        scene.add(RayleighDamping(("r",), 0.1, 0.0))
    scene.add(RayleighDamping(("w",), 0.1, 0.0))
    with pytest.raises(ParameterError, match="already damped"):
        scene.add(RayleighDamping(("w",), 0.2, 0.0))
    assert len(scene.damping) == 1
