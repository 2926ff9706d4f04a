"""Centre lines of the ANCF bodies of a system: sampling, VTU files and PNG plots."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..assembly.system import System


def centerlines(system: System, q: np.ndarray, points_per_element: int = 8) -> dict[str, np.ndarray]:
    """Positions (m) along every body's centre line, padded to 3D: ``{body: (n, 3)}``."""
    out = {}
    for body in system.scene.bodies:
        r, _ = system.body_set(body.name).sample(q, points_per_element)
        out[body.name] = np.pad(r, ((0, 0), (0, 3 - r.shape[1])))
    return out


def write_centerlines_vtu(system: System, q: np.ndarray, path: Path, points_per_element: int = 8) -> Path:
    """Write the centre lines as VTU polylines (ParaView opens it); point data ``displacement_m``."""
    import meshio

    lines = centerlines(system, q, points_per_element)
    ref = centerlines(system, system.dofs.q0, points_per_element)
    points, cells, disp = [], [], []
    start = 0
    for name, r in lines.items():
        points.append(r)
        disp.append(r - ref[name])
        idx = np.arange(start, start + len(r))
        cells.append(np.column_stack([idx[:-1], idx[1:]]))
        start += len(r)
    mesh = meshio.Mesh(np.vstack(points), [("line", np.vstack(cells))], point_data={"displacement_m": np.vstack(disp)})
    path = Path(path)
    mesh.write(path)
    return path


def write_modes_vtu(system: System, q: np.ndarray, shapes: np.ndarray, frequencies_hz, folder: Path,
                    points_per_element: int = 8) -> list[Path]:
    """One VTU per mode, with point data ``mode_shape`` (normalized to unit max amplitude)."""
    import meshio

    base = centerlines(system, q, points_per_element)
    files = []
    for k, f in enumerate(frequencies_hz):
        shifted = centerlines(system, q + 1e-3 * shapes[:, k] / max(np.abs(shapes[:, k]).max(), 1e-300), points_per_element)
        pts = np.vstack(list(base.values()))
        shape = np.vstack([shifted[n] - base[n] for n in base]) / 1e-3
        cells, start = [], 0
        for r in base.values():
            idx = np.arange(start, start + len(r))
            cells.append(np.column_stack([idx[:-1], idx[1:]]))
            start += len(r)
        path = Path(folder) / f"mode_{k + 1:02d}_{f:.4g}Hz.vtu"
        meshio.Mesh(pts, [("line", np.vstack(cells))], point_data={"mode_shape": shape}).write(path)
        files.append(path)
    return files


def plot_centerlines(curves: dict[str, np.ndarray], path: Path, title: str = "", plane: str = "xy",
                     reference: dict[str, np.ndarray] | None = None) -> Path:
    """Plot labelled curves (n, 3) in a coordinate plane and save a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    i, j = "xyz".index(plane[0]), "xyz".index(plane[1])
    fig, ax = plt.subplots(figsize=(7, 5))
    for label, r in curves.items():
        ax.plot(r[:, i], r[:, j], "-", lw=2, label=label)
    for label, r in (reference or {}).items():
        ax.plot(r[:, i], r[:, j], "k--", lw=1, label=label)
    ax.set_xlabel(f"{plane[0]} [m]")
    ax.set_ylabel(f"{plane[1]} [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend()
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
