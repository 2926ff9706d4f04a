"""Global numbering of the coordinates of a scene."""
from __future__ import annotations

import numpy as np

from ..scene.ancf import AncfBody


class DofMap:
    """Coordinates of all bodies, concatenated body after body, node after node.

    Attributes
    ----------
    n : int
        Number of coordinates.
    q0 : ndarray
        Initial coordinates.
    fixed : ndarray of bool
        True for prescribed coordinates.
    """

    def __init__(self, bodies: list[AncfBody]):
        self.bodies = list(bodies)
        self.offset: dict[str, int] = {}
        n = 0
        for body in self.bodies:
            self.offset[body.name] = n
            n += body.q0.size
        self.n = n
        self.q0 = np.concatenate([b.q0.ravel() for b in self.bodies]) if self.bodies else np.zeros(0)
        self.fixed = np.zeros(n, dtype=bool)
        for body in self.bodies:
            for (node, coord) in body.fixed:
                self.fixed[self.index(body, node, coord)] = True
        self.free = np.flatnonzero(~self.fixed)

    def index(self, body: AncfBody, node: int, coordinate: str) -> int:
        """Global index of one nodal coordinate."""
        return self.offset[body.name] + body.node_index(node) * body.element.dofs_per_node + body.coordinate_index(coordinate)

    def node_indices(self, body: AncfBody, node: int) -> np.ndarray:
        """Global indices of all coordinates of one node."""
        dpn = body.element.dofs_per_node
        start = self.offset[body.name] + body.node_index(node) * dpn
        return np.arange(start, start + dpn)

    def element_indices(self, body: AncfBody) -> np.ndarray:
        """(n_elements, 2 * dofs_per_node) global indices of each element's coordinates."""
        dpn = body.element.dofs_per_node
        first = self.offset[body.name] + dpn * np.arange(body.n_elements)
        return first[:, None] + np.arange(2 * dpn)[None, :]

    def names(self) -> list[str]:
        """Readable name of every coordinate, e.g. ``wire[3].y_x``."""
        out = []
        for body in self.bodies:
            for node in range(body.n_nodes):
                out.extend(f"{body.name}[{node}].{c}" for c in body.element.node_coordinates)
        return out
