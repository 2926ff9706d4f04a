"""ANCF bodies: a chain of elements of one type, its reference mesh and its supports."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..catalog import ElementType, element_type
from ..errors import ParameterError
from .sections import Material, Section, element_parameters


def _frame(direction: np.ndarray, up: np.ndarray | None) -> np.ndarray:
    """Orthonormal columns ``[d1, d2, d3]`` with ``d1`` along ``direction``."""
    d1 = direction / np.linalg.norm(direction)
    if up is None:
        up = np.array([0.0, 0.0, 1.0]) if abs(d1[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    d2 = np.cross(up, d1)
    d2 /= np.linalg.norm(d2)
    return np.column_stack([d1, d2, np.cross(d1, d2)])


@dataclass
class AncfBody:
    """A chain of ANCF elements of one type (a wire, a beam).

    Build one with :meth:`straight`. The coordinates of node ``i`` are
    ``q0[i]`` in the order ``element_type.node_coordinates``; element ``k`` joins nodes ``k``
    and ``k + 1``.

    Attributes
    ----------
    name : str
        Unique name in the scene.
    element : ElementType
        Element type (``cable2d``, ``cable3d`` or ``beam3d``).
    q0 : ndarray, shape (n_nodes, dofs_per_node)
        Initial (and reference-mesh) nodal coordinates (m, -).
    params : ndarray, shape (n_elements, n_params)
        Kernel parameters of each element (see :mod:`symcat.catalog`).
    fixed : dict
        ``(node, coordinate) -> value`` of prescribed coordinates.
    """

    name: str
    element: ElementType
    q0: np.ndarray
    params: np.ndarray
    fixed: dict[tuple[int, str], float] = field(default_factory=dict)

    @classmethod
    def straight(
        cls,
        name: str,
        element: str,
        start,
        end,
        n_elements: int,
        material: Material,
        section: Section,
        prestrain: float = 0.0,
        damping_axial: float = 0.0,
        damping_bending: float = 0.0,
        up=None,
    ) -> "AncfBody":
        """Straight mesh from ``start`` to ``end`` (m) with ``n_elements`` equal elements.

        Slopes are unit vectors along the axis; a beam's ``r_y, r_z`` form a right-handed
        frame with ``r_z`` towards ``up`` (default global z, or y for a vertical beam).
        ``prestrain`` makes the stress-free length ``|end - start| / (1 + prestrain)``.
        """
        etype = element_type(element)
        if int(n_elements) != n_elements or n_elements < 1:
            raise ParameterError(f"n_elements={n_elements}: must be an integer >= 1")
        n_elements = int(n_elements)
        start = np.asarray(start, dtype=float)
        end = np.asarray(end, dtype=float)
        if start.shape != (etype.dim,) or end.shape != (etype.dim,):
            raise ParameterError(f"start/end: need {etype.dim} coordinates for element {etype.name}")
        span = np.linalg.norm(end - start)
        if span <= 0:
            raise ParameterError("end: must differ from start")
        t = np.linspace(0.0, 1.0, n_elements + 1)[:, None]
        positions = start + t * (end - start)
        direction = (end - start) / span
        q0 = np.zeros((n_elements + 1, etype.dofs_per_node))
        q0[:, : etype.dim] = positions
        q0[:, etype.dim : 2 * etype.dim] = direction
        if etype.name == "beam3d":
            frame = _frame(direction, None if up is None else np.asarray(up, float))
            q0[:, 6:9] = frame[:, 1]
            q0[:, 9:12] = frame[:, 2]
        lengths = np.full(n_elements, span / n_elements)
        params = element_parameters(etype, lengths, material, section, prestrain, damping_axial, damping_bending)
        return cls(name=name, element=etype, q0=q0, params=params)

    @classmethod
    def from_nodes(cls, name: str, element: str, nodes, lengths, material: Material, section: Section,
                   prestrain: float = 0.0, damping_axial: float = 0.0, damping_bending: float = 0.0) -> "AncfBody":
        """Mesh through given nodal coordinates (e.g. a curved wire).

        ``nodes`` is (n_nodes, dofs_per_node) in the element's coordinate order; ``lengths``
        (m) are the reference (arc) lengths of the elements between consecutive nodes.
        """
        etype = element_type(element)
        nodes = np.array(nodes, dtype=float)
        if nodes.ndim != 2 or nodes.shape[1] != etype.dofs_per_node or len(nodes) < 2:
            raise ParameterError(f"nodes: need an (n >= 2, {etype.dofs_per_node}) array for {etype.name}")
        lengths = np.broadcast_to(np.asarray(lengths, dtype=float), (len(nodes) - 1,))
        params = element_parameters(etype, lengths, material, section, prestrain, damping_axial, damping_bending)
        return cls(name=name, element=etype, q0=nodes, params=params)

    @property
    def n_nodes(self) -> int:
        return self.q0.shape[0]

    @property
    def n_elements(self) -> int:
        return self.params.shape[0]

    def node_index(self, node: int) -> int:
        """Node number, with negative numbers counted from the end (-1 is the last node)."""
        n = self.n_nodes
        if not -n <= node < n:
            raise ParameterError(f"node={node}: body {self.name!r} has nodes 0..{n - 1}")
        return node % n

    def coordinate_index(self, name: str) -> int:
        try:
            return self.element.node_coordinates.index(name)
        except ValueError:
            raise ParameterError(
                f"coordinate={name!r}: {self.element.name} nodes have {', '.join(self.element.node_coordinates)}"
            ) from None

    def fix(self, node: int, coordinates=None, values=None) -> "AncfBody":
        """Prescribe coordinates of a node (default: all of them, at their current values)."""
        node = self.node_index(node)
        names = list(self.element.node_coordinates) if coordinates is None else list(coordinates)
        for k, name in enumerate(names):
            idx = self.coordinate_index(name)
            value = self.q0[node, idx] if values is None else float(np.atleast_1d(values)[k])
            self.q0[node, idx] = value
            self.fixed[(node, name)] = value
        return self

    def pin(self, node: int, position=None) -> "AncfBody":
        """Fix the position of a node (optionally moving it to ``position``, m)."""
        return self.fix(node, self.element.node_coordinates[: self.element.dim], position)

    def clamp(self, node: int) -> "AncfBody":
        """Fix every coordinate of a node (position and gradients)."""
        return self.fix(node)

    def mass(self) -> float:
        """Total mass (kg): sum of rho A L / (1 + prestrain)."""
        names = self.element.param_names
        p = {n: self.params[:, k] for k, n in enumerate(names)}
        return float(np.sum(p["rho"] * p["A"] * p["length"] / (1 + p["prestrain"])))
