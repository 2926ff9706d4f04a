"""Seeded random element states and parameters for kernel tests."""
from __future__ import annotations

import numpy as np

from symcat.catalog import ELEMENT_TYPES
from symcat.scene.sections import Material, Section, element_parameters


def parameters(name: str, rng, damping=(0.0, 0.0), prestrain=0.0) -> np.ndarray:
    etype = ELEMENT_TYPES[name]
    length = rng.uniform(0.5, 2.0)
    section = Section.rectangle(rng.uniform(0.02, 0.05), rng.uniform(0.02, 0.05))
    material = Material(E=rng.uniform(1e9, 2e9), rho=rng.uniform(1000, 8000), nu=0.3)
    return element_parameters(etype, [length], material, section, prestrain, *damping)[0]


def straight(name: str, length: float) -> np.ndarray:
    """Straight reference coordinates along x."""
    etype = ELEMENT_TYPES[name]
    dim = etype.dim
    node = np.zeros(etype.dofs_per_node)
    node[dim] = 1.0
    if name == "beam3d":
        node[6:9] = [0, 1, 0]
        node[9:12] = [0, 0, 1]
    second = node.copy()
    second[0] = length
    return np.concatenate([node, second])


def deformed(name: str, length: float, rng, scale=0.1) -> np.ndarray:
    """A random, moderately deformed state."""
    e = straight(name, length)
    return e + scale * rng.standard_normal(e.size) * np.where(np.arange(e.size) % ELEMENT_TYPES[name].dofs_per_node < ELEMENT_TYPES[name].dim, length, 1.0)


def rigid_motion(name: str, e: np.ndarray, rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """Apply a rigid motion to element coordinates (positions rotated and shifted, gradients rotated)."""
    etype = ELEMENT_TYPES[name]
    dim = etype.dim
    out = e.copy()
    for node in range(2):
        base = node * etype.dofs_per_node
        for k in range(etype.dofs_per_node // dim):
            block = slice(base + k * dim, base + (k + 1) * dim)
            out[block] = rotation @ e[block] + (translation if k == 0 else 0)
    return out


def random_rotation(dim: int, rng) -> np.ndarray:
    q, r = np.linalg.qr(rng.standard_normal((dim, dim)))
    q = q @ np.diag(np.sign(np.diag(r)))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return q
