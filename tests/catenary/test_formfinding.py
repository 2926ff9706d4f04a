"""Form finding of the benchmark catenary: design heights, taut-string statics, bad designs."""
import numpy as np
import pytest

from symcat.catenary import CatenaryDesign, Wire, benchmark2015, find_form
from symcat.errors import ParameterError


@pytest.fixture(scope="module")
def form():
    return find_form(benchmark2015(n_spans=4), 20)


def test_contact_wire_hangs_at_design_height(form):
    # the coupled catenary (droppers as springs, support preloads) reproduces the target
    assert form.height_error_m < 1e-8
    st = form.structure
    assert np.all(st.dropper_state(form.q)[2] > 0)  # all droppers taut


def _finite_difference_reactions(d, h=0.01):
    """Pin reactions of the contact wire as a tensioned Euler beam, EI w'''' - H w'' = p,
    pinned (w given, no moment at the ends) at supports and droppers: a fine finite-difference
    grid, independent of the ANCF model."""
    import scipy.sparse as sps
    import scipy.sparse.linalg as spla

    n = int(round(d.length / h))
    x = np.arange(n + 1) * h
    EI, H = d.contact_wire.EI, d.contact_wire.tension
    q = d.contact_wire.mass_per_length * d.gravity
    d4 = np.array([1.0, -4.0, 6.0, -4.0, 1.0]) * EI / h**4 + np.array([0.0, -1.0, 2.0, -1.0, 0.0]) * H / h**2
    rows, cols, vals = [], [], []
    for j in range(1, n):
        for o, c in zip(range(-2, 3), d4):
            k = j + o
            if k < 0:  # ghost w_-1 = 2 w_0 - w_1 (no moment at the end pin)
                rows += [j, j]
                cols += [0, 1]
                vals += [2 * c, -c]
            elif k > n:
                rows += [j, j]
                cols += [n, n - 1]
                vals += [2 * c, -c]
            else:
                rows.append(j)
                cols.append(k)
                vals.append(c)
    op = sps.csr_matrix((vals, (rows, cols)), shape=(n + 1, n + 1))
    pins = np.unique(np.round(np.concatenate([d.support_x(), d.dropper_x()]) / h).astype(int))
    free = np.setdiff1d(np.arange(1, n), pins)
    w = np.zeros(n + 1)
    w[pins] = d.target_height(x[pins])
    rhs = -q - op[free][:, pins] @ w[pins]
    w[free] = spla.spsolve(op[free][:, free].tocsc(), rhs)
    reaction = h * (op @ w + q)
    drop = np.round(d.dropper_x() / h).astype(int)
    return reaction[drop]


def test_dropper_tensions_match_a_finite_difference_beam():
    d = benchmark2015(n_spans=2)
    form = find_form(d, 160)
    st = form.structure
    point = (d.clamp_mass_contact + 0.5 * d.dropper_mass_per_length * st.dropper_length) * d.gravity
    expected = _finite_difference_reactions(d) + point
    np.testing.assert_allclose(form.dropper_tension_N, expected, rtol=3e-3)


def test_dropper_tensions_converge_with_the_mesh(form):
    finer = find_form(form.structure.design, 40)
    # C1 elements smear the kinks at the clamps over an element: first-order convergence
    assert np.max(np.abs(finer.dropper_tension_N / form.dropper_tension_N - 1)) < 0.05


def test_support_reactions_carry_the_weight(form):
    """Messenger support preloads plus end reactions equal the total weight (global balance)."""
    st = form.structure
    q = form.q
    f = st.forces(q)
    fixed = np.setdiff1d(np.arange(st.n), st.free)
    z_fixed = np.intersect1d(fixed, np.concatenate([st.cw_xyz[:, 2], st.mw_xyz[:, 2]]))
    end_reactions = -f[z_fixed].sum()
    supports = st.cw_supports.preload.sum() + st.mw_supports.preload.sum()
    weight = -st._f_ext[np.concatenate([st.cw_xyz[:, 2], st.mw_xyz[:, 2]])].sum()
    spring = sum((-(sup.stiffness * (q[xyz[sup.nodes, 2]] - sup.height))).sum()
                 for sup, xyz in ((st.cw_supports, st.cw_xyz), (st.mw_supports, st.mw_xyz)))
    assert end_reactions + supports + spring == pytest.approx(weight, rel=1e-8)


def test_dropper_lengths_symmetric_and_plausible(form):
    per = 9
    span = form.dropper_length_m[per:2 * per]
    np.testing.assert_allclose(span, span[::-1], atol=2e-3)  # only the wire stretch breaks symmetry
    assert 0.6 < span.min() < span.max() < 1.2  # encumbrance 1.2 m, presag 55 mm


def test_long_section_keeps_droppers_vertical():
    """Over a 1.1 km tension section the wires keep their stations (no drift of the messenger
    against the contact wire), so every span gets the same droppers."""
    form = find_form(benchmark2015(n_spans=20), 10)
    e, _, _ = form.structure.dropper_state(form.q)
    assert np.abs(e[:, 0]).max() < 1e-6
    lengths = form.dropper_length_m.reshape(20, 9)
    np.testing.assert_allclose(lengths[2:-2], np.broadcast_to(lengths[10], (16, 9)), atol=1e-4)


def test_beam_elements_give_the_same_form():
    cable = find_form(benchmark2015(n_spans=3), 10)
    beam = find_form(benchmark2015(n_spans=3), 10, element="beam3d")
    np.testing.assert_allclose(beam.dropper_length_m, cable.dropper_length_m, rtol=2e-4)


def test_unreachable_presag_names_the_parameter():
    d = benchmark2015(n_spans=3)
    bad = d.with_(presag=(0, 0, 0, 0, -0.3, 0, 0, 0, 0))  # middle dropper pushed 0.3 m up: needs compression
    with pytest.raises(ParameterError, match="presag"):
        find_form(bad, 10)


@pytest.mark.parametrize("change, name", [
    (dict(dropper_positions=(4.5, 10.25, 16.0, 21.75, 27.5, 33.25, 39.0, 44.75, 60.0)), "dropper_positions"),
    (dict(contact_wire=Wire(-22000.0, 1.35, 1.5e7, 195.0)), "contact_wire.tension"),
    (dict(messenger_wire=Wire(16000.0, 1.08, 1.164e7, -1.0)), "messenger_wire.EI"),
    (dict(presag=(0.0, 0.1)), "presag"),
    (dict(n_spans=0), "n_spans"),
])
def test_bad_designs_are_rejected(change, name):
    with pytest.raises(ParameterError, match=name):
        benchmark2015().with_(**change)


def test_design_geometry_helpers():
    d = benchmark2015(n_spans=2)
    assert d.target_height(27.5) == pytest.approx(5.3 - 0.055)
    assert d.target_height(55.0) == pytest.approx(5.3)
    assert d.stagger_y(0.0) == pytest.approx(0.2) and d.stagger_y(55.0) == pytest.approx(-0.2)
    assert d.wave_speed * 3.6 == pytest.approx(459.6, abs=0.1)
    assert isinstance(d, CatenaryDesign)
