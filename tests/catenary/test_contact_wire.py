"""The contact-wire locator (symcat.catenary.contact_wire) against the element's compiled
position kernel: two independent evaluations of the same point of the wire."""
import pytest

from symcat.catenary import benchmark2015, find_form
from symcat.catenary.contact_wire import WireLocator


@pytest.fixture(scope="module")
def short_line():
    return find_form(benchmark2015(n_spans=5), 10, progress=False)


def test_wire_locator_matches_compiled_position_kernel(short_line):
    from symcat.codegen.library import kernel_library

    st = short_line.structure
    dofs = st.system.dofs
    body = st.contacts[0]
    lengths = body.params[:, 0]
    loc = WireLocator(st.cw_xyz[:, 0], [dofs.index(body, k, "x_x") for k in range(body.n_nodes)], st.cw_xyz[:, 2],
                      st.cw_zx, lengths)
    q = short_line.q
    position = kernel_library("cable3d")["cable3d_position"]
    for x in (3.1, 27.4, 131.0, 250.2):
        point = loc.locate(q, x)
        e = q[dofs.element_indices(body)[point.element]]
        r, _ = position(e, point.xi, body.params[point.element])
        assert float(r[0]) == pytest.approx(x, abs=1e-10)
        assert point.height(q) == pytest.approx(float(r[2]), abs=1e-12)

