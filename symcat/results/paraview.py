"""ParaView time series of a multibody run: one VTU per output time and a ``.pvd`` index.

What :func:`write_multibody_series` draws at each frame:

ANCF bodies
    Polylines through points sampled along their centre lines (``line`` cells).
Rigid bodies
    Their equivalent-inertia box (``hexahedron`` cells): the uniform box of the body's mass and
    principal inertia, placed at its centre of mass along its principal axes, so it moves and
    turns with the body; a slender rod appears as a thin box of its length. Edges are at least
    2 % of the body's longest edge, so flat and point-like bodies stay visible.

Point data ``displacement_m`` (3 components, m; from the first frame, the run's initial state:
Warp By Vector and colouring work on it) and ``body_id``; cell data ``body_id``. The ids are
the positions of the bodies in ``[ANCF bodies..., rigid bodies...]`` of the scene, listed by
name in a comment of the ``.pvd`` file.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

#: Largest number of frames written by default (the output times are subsampled evenly).
MAX_FRAMES = 200

#: Corners of the unit cube in VTK's hexahedron order.
_CUBE = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                  [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float) / 2


def write_pvd(path: Path, entries: list[tuple[float, str]], comment: str = "") -> Path:
    """A ParaView collection (``.pvd``) of ``(time s, file name relative to path)`` entries."""
    path = Path(path)
    note = f"<!-- {comment.replace('--', '-')} -->\n" if comment else ""
    rows = "\n".join(f'    <DataSet timestep="{t:.9g}" part="0" file="{name}"/>' for t, name in entries)
    path.write_text(f'<?xml version="1.0"?>\n{note}<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
                    f"{rows}\n  </Collection>\n</VTKFile>\n")
    return path


def frame_indices(n: int, max_frames: int = MAX_FRAMES) -> np.ndarray:
    """Indices of at most ``max_frames`` evenly spread output times out of ``n``, first and last
    included."""
    if n <= max_frames:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, max(max_frames, 2))).astype(int))


def inertia_box(mass: float, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Edge lengths (m) and principal axes (columns, body frame) of the uniform box with the
    body's mass and inertia (kg m^2, about the centre of mass: 3 principal values or 3x3)."""
    inertia = np.asarray(inertia, dtype=float)
    values, axes = np.linalg.eigh(np.diag(inertia) if inertia.shape == (3,) else inertia)
    j1, j2, j3 = values
    squares = 6.0 / mass * np.array([j2 + j3 - j1, j1 + j3 - j2, j1 + j2 - j3])
    edges = np.sqrt(np.clip(squares, 0.0, None))
    edges = np.maximum(edges, 0.02 * edges.max()) if edges.max() > 0 else np.full(3, 0.05)
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1
    return edges, axes


def multibody_geometry(model, q: np.ndarray, points_per_element: int = 8):
    """Points (n, 3), cell blocks ``[(type, connectivity)]``, point ``body_id`` and per-block cell
    ``body_id`` of a :class:`~symcat.assembly.multibody.MultibodyModel` at coordinates ``q``."""
    from ..scene.rigid import rotation_matrix

    scene = model.scene
    points, lines, line_ids, hexes, hex_ids, point_ids = [], [], [], [], [], []
    start = 0
    n_a = model.ancf.n
    for k, body in enumerate(scene.bodies):
        r, _ = model.ancf.body_set(body.name).sample(q[:n_a], points_per_element)
        r = np.pad(r, ((0, 0), (0, 3 - r.shape[1])))
        idx = np.arange(start, start + len(r))
        points.append(r)
        lines.append(np.column_stack([idx[:-1], idx[1:]]))
        line_ids.append(np.full(len(r) - 1, k))
        point_ids.append(np.full(len(r), k))
        start += len(r)
    n_ancf = len(scene.bodies)
    for k, body in enumerate(scene.rigid_bodies):
        off = model.rigid_offset[body.name]
        edges, axes = inertia_box(body.mass, body.J)
        corners = q[off:off + 3] + (_CUBE * edges) @ (rotation_matrix(q[off + 3:off + 7]) @ axes).T
        points.append(corners)
        hexes.append(np.arange(start, start + 8)[None, :])
        hex_ids.append([n_ancf + k])
        point_ids.append(np.full(8, n_ancf + k))
        start += 8
    cells, cell_ids = [], []
    if lines:
        cells.append(("line", np.vstack(lines)))
        cell_ids.append(np.concatenate(line_ids))
    if hexes:
        cells.append(("hexahedron", np.vstack(hexes)))
        cell_ids.append(np.concatenate(hex_ids))
    return np.vstack(points), cells, np.concatenate(point_ids), cell_ids


def write_multibody_series(model, t_s: np.ndarray, q: np.ndarray, folder: Path, stem: str,
                           max_frames: int = MAX_FRAMES, points_per_element: int = 8) -> Path:
    """Write ``folder/stem_NNNNN.vtu`` at (at most ``max_frames`` of) the output times ``t_s``
    (s) with coordinates ``q`` (n_t, n_q) of ``model`` and the index ``folder/stem.pvd``
    (module docstring); returns the ``.pvd`` path."""
    import meshio

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    t_s, q = np.asarray(t_s, dtype=float), np.asarray(q, dtype=float)
    reference = None
    entries = []
    for k, i in enumerate(frame_indices(len(t_s), max_frames)):
        points, cells, point_ids, cell_ids = multibody_geometry(model, q[i], points_per_element)
        if reference is None:
            reference = multibody_geometry(model, q[0], points_per_element)[0]
        mesh = meshio.Mesh(points, cells, point_data={"displacement_m": points - reference,
                                                      "body_id": point_ids.astype(np.int32)},
                           cell_data={"body_id": [c.astype(np.int32) for c in cell_ids]})
        name = f"{stem}_{k:05d}.vtu"
        mesh.write(folder / name)
        entries.append((float(t_s[i]), name))
    names = [b.name for b in model.scene.bodies] + [b.name for b in model.scene.rigid_bodies]
    comment = "body_id: " + ", ".join(f"{k} {n}" for k, n in enumerate(names))
    return write_pvd(folder / f"{stem}.pvd", entries, comment)
