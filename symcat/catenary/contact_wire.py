"""Where a pan-head touches the contact wire of a form-found catenary, and the wire's height
there as weights on the structure's coordinates ``q``: the static placement of pantographs
(:func:`~symcat.pantograph.lumped_scene.loaded_catenary`, the wire in running at a point) reads
the wire through these.

The pan-head is a horizontal strip across the track at ``x_c``; it touches the wire where the
wire crosses the plane x = x_c. On the cubic ANCF element containing that point the position is
``r(xi) = N1 r_k + N2 L r_x,k + N3 r_k+1 + N4 L r_x,k+1``, so the wire height is a weighted sum of
four coordinates (the weights depend on xi only).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def hermite(xi: float) -> tuple[np.ndarray, np.ndarray]:
    """Cubic Hermite shape functions ``[N1, N2, N3, N4]`` and their xi-derivatives."""
    x2, x3 = xi * xi, xi * xi * xi
    n = np.array([1 - 3 * x2 + 2 * x3, xi - 2 * x2 + x3, 3 * x2 - 2 * x3, -x2 + x3])
    dn = np.array([-6 * xi + 6 * x2, 1 - 4 * xi + 3 * x2, 6 * xi - 6 * x2, -2 * xi + 3 * x2])
    return n, dn


@dataclass
class WirePoint:
    """A point of the contact wire.

    Attributes
    ----------
    element : int
        Element index.
    xi : float
        Element coordinate in [0, 1].
    index : ndarray of int, shape (4,)
        Global indices of ``z_k, z_x,k, z_k+1, z_x,k+1``.
    weights : ndarray, shape (4,)
        Wire height = ``weights @ q[index]`` (m).
    """

    element: int
    xi: float
    index: np.ndarray
    weights: np.ndarray

    def height(self, q: np.ndarray) -> float:
        return float(self.weights @ q[self.index])


class WireLocator:
    """Finds the contact-wire point below a pan-head at ``x`` (m).

    Parameters
    ----------
    x_index, xx_index, z_index, zx_index : ndarray of int
        Global indices of the x, x_x, z and z_x coordinates of every contact-wire node.
    lengths : ndarray
        Reference element lengths (m).
    """

    def __init__(self, x_index, xx_index, z_index, zx_index, lengths):
        self.x_index = np.asarray(x_index)
        self.xx_index = np.asarray(xx_index)
        self.z_index = np.asarray(z_index)
        self.zx_index = np.asarray(zx_index)
        self.lengths = np.asarray(lengths, dtype=float)
        self._last = -1  # element of the previous call (pan-heads move little per call)

    def locate(self, q: np.ndarray, x: float) -> WirePoint:
        """The wire point at ``x``: element by the current nodal x, then two Newton steps on xi."""
        k = self._last
        ix = self.x_index
        if not (0 <= k < len(ix) - 1 and q[ix[k]] <= x < q[ix[k + 1]]):  # moved on: search again
            k = int(np.clip(np.searchsorted(q[ix], x, side="right") - 1, 0, len(ix) - 2))
            self._last = k
        x0, x1 = q[ix[k]], q[ix[k + 1]]
        length = self.lengths[k]
        cx = np.array([x0, length * q[self.xx_index[k]], x1, length * q[self.xx_index[k + 1]]])
        xi = (x - x0) / (x1 - x0)
        for _ in range(3):
            n, dn = hermite(xi)
            xi -= (n @ cx - x) / (dn @ cx)
        xi = float(np.clip(xi, 0.0, 1.0))
        n, _ = hermite(xi)
        index = np.array([self.z_index[k], self.zx_index[k], self.z_index[k + 1], self.zx_index[k + 1]])
        return WirePoint(k, xi, index, n * np.array([1.0, length, 1.0, length]))


def contact_wire_locators(structure) -> list[WireLocator]:
    """A :class:`WireLocator` for the contact wire of each tension section of ``structure``
    (a :class:`~symcat.catenary.CatenaryStructure`)."""
    return [WireLocator(structure.cw_xyz[r, 0], structure.cw_xx[r], structure.cw_xyz[r, 2], structure.cw_zx[r],
                        body.params[:, body.element.param_names.index("length")])
            for r, body in zip(structure.section_rows, structure.contacts)]


def running_wire(structure, locators: list[WireLocator], q: np.ndarray, x: float) -> int:
    """The tension section whose contact wire is lowest at ``x`` in the state ``q``: the one in
    running, that a pan-head there touches."""
    heights = {w: locators[w].locate(q, x).height(q) for w, sec in enumerate(structure.sections) if sec.covers(x)}
    return min(heights, key=heights.get)


def point_loads(n: int, locators: list[WireLocator], wires, xs, forces):
    """``q -> (f, None)``: upward point forces ``forces`` (N) on the contact wires ``wires`` at
    ``xs`` (m), as generalized forces on the ``n`` coordinates (the ``extra`` of
    :func:`~symcat.catenary.formfinding.coupled_equilibrium`)."""
    def loads(q):
        f = np.zeros(n)
        for x, force, w in zip(xs, forces, wires):
            point = locators[w].locate(q, x)
            np.add.at(f, point.index, force * point.weights)
        return f, None
    return loads
