"""Every kernel: compiled C vs in-memory CasADi vs SymPy evaluation vs finite differences."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import sympy as sp

from symcat.catalog import ELEMENT_TYPES
from symcat.codegen.kernels import gauss_legendre, library_functions
from symcat.codegen.library import kernel_library
from symcat.symbolic import ELEMENTS

from .element_states import deformed, parameters, random_rotation, rigid_motion, straight

ELEMENT_NAMES = sorted(ELEMENT_TYPES)


def _call(f, *args):
    out = f(*[ca.DM(np.atleast_1d(a)) if not isinstance(a, (float, int)) else a for a in args])
    if isinstance(out, (list, tuple)):
        return [np.asarray(ca.densify(o)) for o in out]
    return np.asarray(ca.densify(out))


@pytest.fixture(scope="module", params=ELEMENT_NAMES + ["slope_moment"])
def library(request):
    name = request.param
    return name, kernel_library(name), {f.name(): f for f in library_functions(name)}


def test_compiled_matches_in_memory(library, rng):
    """Compiled externals reproduce the in-memory CasADi functions at random inputs."""
    name, lib, funcs = library
    for fname, f in funcs.items():
        compiled = lib[fname]
        for _ in range(3):
            args = [rng.uniform(0.5, 1.5, f.size_in(k)) for k in range(f.n_in())]
            ref = _call(f, *args)
            got = _call(compiled, *args)
            for r, g in zip(ref if isinstance(ref, list) else [ref], got if isinstance(got, list) else [got]):
                np.testing.assert_allclose(g, r, rtol=1e-12, atol=1e-12 * (1 + np.abs(r).max()), err_msg=fname)


def _fd_jacobian(fun, x, h):
    cols = []
    for k in range(x.size):
        dx = np.zeros_like(x)
        dx[k] = h * max(1.0, abs(x[k]))
        cols.append((fun(x + dx) - fun(x - dx)) / (2 * dx[k]))
    return np.column_stack(cols)


@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_force_and_stiffness_against_finite_differences(name, rng):
    lib = kernel_library(name)
    p = parameters(name, rng, prestrain=0.01)
    e = deformed(name, p[0], rng)
    energy = lambda x: _call(lib[f"{name}_energy"], x, p).item()
    force = lambda x: _call(lib[f"{name}_force"], x, p).ravel()
    f = force(e)
    f_fd = -_fd_jacobian(lambda x: np.array([energy(x)]), e, 1e-6).ravel()
    np.testing.assert_allclose(f, f_fd, rtol=1e-5, atol=1e-6 * np.abs(f).max())
    k = _call(lib[f"{name}_stiffness"], e, p)
    k_fd = -_fd_jacobian(force, e, 1e-6)
    np.testing.assert_allclose(k, k_fd, rtol=1e-5, atol=1e-6 * np.abs(k).max())
    np.testing.assert_allclose(k, k.T, atol=1e-10 * np.abs(k).max())
    jac = _call(lib[f"jac_{name}_force"], e, p, np.zeros(e.size))
    np.testing.assert_allclose(jac[0], -k, rtol=1e-12, atol=1e-12 * np.abs(k).max())
    jac_p_fd = _fd_jacobian(lambda pp: _call(lib[f"{name}_force"], e, pp).ravel(), p, 1e-7)
    np.testing.assert_allclose(jac[1], jac_p_fd, rtol=1e-4, atol=1e-6 * np.abs(jac_p_fd).max())


@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_damping_against_finite_differences(name, rng):
    lib = kernel_library(name)
    p = parameters(name, rng, damping=(0.01, 0.02))
    e = deformed(name, p[0], rng)
    e_dot = rng.standard_normal(e.size)
    fd = lambda x, v: _call(lib[f"{name}_damping"], x, v, p).ravel()
    d, c = _call(lib[f"{name}_damping_matrices"], e, e_dot, p)
    np.testing.assert_allclose(d, -_fd_jacobian(lambda x: fd(x, e_dot), e, 1e-6), rtol=1e-5, atol=1e-6 * np.abs(d).max())
    np.testing.assert_allclose(c, -_fd_jacobian(lambda v: fd(e, v), e_dot, 1e-6), rtol=1e-5, atol=1e-6 * np.abs(c).max())
    # Linear in the velocities and dissipative.
    np.testing.assert_allclose(fd(e, e_dot), -c @ e_dot, rtol=1e-10, atol=1e-10 * np.abs(c).max())
    assert e_dot @ fd(e, e_dot) < 0
    assert np.all(np.linalg.eigvalsh((c + c.T) / 2) > -1e-9 * np.abs(c).max())


@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_energy_against_sympy_evaluation(name, rng):
    """Strain energy: SymPy expressions evaluated by lambdify and our own Gauss sum."""
    defn = ELEMENTS[name]()
    lib = kernel_library(name)
    p = parameters(name, rng, prestrain=0.02)
    e = deformed(name, p[0], rng)
    density = sp.lambdify([defn.local, defn.p], defn.energy_density, "numpy")
    local_map = sp.lambdify([defn.xi, defn.p], defn.local_map, "numpy")
    total = 0.0
    for x, w in zip(*gauss_legendre(defn.gauss_points)):
        g = np.asarray(local_map(x, p), dtype=float) @ e
        total += p[0] * w * float(density(g, p))
    if defn.section_density is not None:
        section = sp.lambdify([defn.local, defn.p], defn.section_density, "numpy")
        for x in (0.0, 1.0):
            total += p[0] / 2 * float(section(np.asarray(local_map(x, p), dtype=float) @ e, p))
    assert _call(lib[f"{name}_energy"], e, p).item() == pytest.approx(total, rel=1e-11)


@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_mass_matrix(name, rng):
    """Exact mass: SymPy evaluation, total mass, centre of mass, and an independent quadrature."""
    defn = ELEMENTS[name]()
    etype = ELEMENT_TYPES[name]
    lib = kernel_library(name)
    p = parameters(name, rng, prestrain=0.05)
    m = _call(lib[f"{name}_mass"], p)
    m_sympy = np.asarray(sp.lambdify([defn.p], defn.mass_matrix, "numpy")(p), dtype=float)
    np.testing.assert_allclose(m, m_sympy, rtol=1e-13)
    names = etype.param_names
    get = dict(zip(names, p))
    total = get["rho"] * get["A"] * get["length"] / (1 + get["prestrain"])
    dim = etype.dim
    for axis in range(dim):
        v = np.zeros(etype.n_coordinates)  # rigid translation velocity along `axis`
        v[[axis, etype.dofs_per_node + axis]] = 1.0
        assert v @ m @ v == pytest.approx(total, rel=1e-13)
    # First moment: gravity shape times the straight coordinates = total mass * centre.
    g = np.zeros(dim)
    g[0] = 1.0
    q_g = _call(lib[f"{name}_gravity"], p, g).ravel()
    e0 = straight(name, get["length"])
    assert q_g @ e0 == pytest.approx(total * get["length"] / 2, rel=1e-12)
    # Independent check: kinetic energy by Gauss quadrature of the interpolated centre-line
    # velocity (cables: exact for cubic Hermite with 4 points).
    if name != "beam3d":
        pos = lib[f"{name}_position"]
        v = rng.standard_normal(etype.n_coordinates)
        ke = 0.0
        for x, w in zip(*gauss_legendre(4)):
            r_dot = _call(pos, v, float(x), p)[0].ravel()  # position is linear in e
            ke += total * w * r_dot @ r_dot
        assert v @ m @ v == pytest.approx(ke, rel=1e-12)


@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_rigid_motion_is_free_of_elastic_and_damping_forces(name, rng):
    lib = kernel_library(name)
    p = parameters(name, rng, damping=(0.01, 0.01))
    dim = ELEMENT_TYPES[name].dim
    e0 = straight(name, p[0])
    k_scale = np.abs(_call(lib[f"{name}_stiffness"], e0, p)).max()
    for _ in range(3):  # large rotations included
        rot = random_rotation(dim, rng)
        e = rigid_motion(name, e0, rot, rng.standard_normal(dim) * 5)
        f = _call(lib[f"{name}_force"], e, p).ravel()
        assert np.abs(f).max() <= 1e-9 * k_scale * p[0]
        # Rigid velocity: translation plus rotation about a random axis.
        omega = rng.standard_normal(3) if dim == 3 else np.array([0, 0, rng.standard_normal()])
        skew = np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]])[:dim, :dim]
        e_dot = rigid_motion(name, e, skew, rng.standard_normal(dim)) - rigid_motion(name, e, np.zeros((dim, dim)), np.zeros(dim))
        f_d = _call(lib[f"{name}_damping"], e, e_dot, p).ravel()
        assert np.abs(f_d).max() <= 1e-9 * k_scale * p[0] * 0.01 * np.abs(omega).max()


def test_slope_moment_is_the_gradient_of_the_rotation_angle(rng):
    lib = kernel_library("slope_moment")
    axis = rng.standard_normal(3)
    axis /= np.linalg.norm(axis)
    a = rng.standard_normal(3)
    moment = 3.7
    f = _call(lib["slope_moment"], a, np.r_[moment, axis]).ravel()
    e1 = np.cross(axis, [1.0, 0, 0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    angle = lambda x: np.arctan2(x @ e2, x @ e1)
    grad = np.array([(angle(a + h) - angle(a - h)) / 2e-7 for h in np.eye(3) * 1e-7])
    np.testing.assert_allclose(f, moment * grad, rtol=1e-6)


@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_position_and_strain_kernels_against_sympy(name, rng):
    defn = ELEMENTS[name]()
    lib = kernel_library(name)
    p = parameters(name, rng, prestrain=0.01)
    e = deformed(name, p[0], rng)
    xi = 0.37
    r = sp.lambdify([defn.e, defn.xi, defn.p], defn.position, "numpy")(e, xi, p)
    r_x = sp.lambdify([defn.e, defn.xi, defn.p], defn.slope, "numpy")(e, xi, p)
    got_r, got_rx = _call(lib[f"{name}_position"], e, xi, p)
    np.testing.assert_allclose(got_r.ravel(), np.ravel(r), rtol=1e-13)
    np.testing.assert_allclose(got_rx.ravel(), np.ravel(r_x), rtol=1e-13)
    g = np.asarray(sp.lambdify([defn.xi, defn.p], defn.local_map, "numpy")(xi, p), dtype=float) @ e
    eps = float(sp.lambdify([defn.local, defn.p], defn.axial_strain, "numpy")(g, p))
    kappa = np.ravel(sp.lambdify([defn.local, defn.p], defn.bending_strain, "numpy")(g, p))
    got = _call(lib[f"{name}_strain"], e, xi, p)
    assert got[0].item() == pytest.approx(eps, rel=1e-12)
    np.testing.assert_allclose(got[1].ravel(), kappa, rtol=1e-11, atol=1e-14)


def test_casadi_differentiates_through_the_compiled_externals():
    """AD of an assembled MX graph uses the jac_<name> companions: it equals the stiffness."""
    from symcat.assembly import assemble
    from symcat.scene import AncfBody, Material, Scene, Section

    wire = AncfBody.straight("w", "cable3d", [0, 0, 0], [3, 0, 0], 5, Material(1e10, 2000), Section.circle(0.01), prestrain=1e-3)
    scene = Scene()
    scene.add(wire)
    system = assemble(scene)
    q = ca.MX.sym("q", system.n)
    fn = ca.Function("f", [q], [ca.jacobian(system.internal_force(q), q), system.tangent_stiffness(q)])
    q0 = system.dofs.q0 + 0.01 * np.random.default_rng(3).standard_normal(system.n)
    jac, k = (np.asarray(ca.densify(m)) for m in fn(q0))
    np.testing.assert_allclose(jac, -k, rtol=1e-12, atol=1e-12 * np.abs(k).max())
