"""Looking at a passage: PNG plots and a ParaView time series (VTU files + a .pvd index).

The ParaView ``part_id`` is 0 for contact wires, 1 for messengers, 2 for droppers and 3 for
pan-heads."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .statistics import lowpass


def _marks(ax, result, lo, hi) -> None:
    st = result.form.structure
    for x in st.x[st.support_nodes]:
        if lo <= x <= hi:
            ax.axvline(x, color="0.3", lw=0.8)
    for x in st.x[st.dropper_nodes]:
        if lo <= x <= hi:
            ax.axvline(x, color="0.75", lw=0.5, ls=":")
    ax.axvspan(*result.section_m, color="tab:green", alpha=0.06)


def plot_passage(result, folder: Path, stem: str = "passage") -> list[Path]:
    """Write the contact-force, pan-head, uplift and dropper plots; returns their paths.

    Contact force raw and 20 Hz filtered against position with supports (solid) and droppers
    (dotted) marked and the analysis section shaded; pan-head height and acceleration; contact
    wire uplift at the supports; dropper tensions in the analysis section with slack marked.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = Path(folder)
    rec = result.record
    paths = []
    n_p = rec.contact_force_N.shape[1]
    x = rec.x_contact_m
    lo, hi = float(x.min()), float(x.max())

    fig, axes = plt.subplots(n_p, 1, figsize=(11, 3.2 * n_p), squeeze=False)
    for p in range(n_p):
        ax = axes[p, 0]
        f = rec.contact_force_N[:, p]
        ax.plot(x[:, p], f, color="0.6", lw=0.6, label="raw")
        ax.plot(x[:, p], lowpass(rec.t_s, f), color="tab:blue", lw=1.2, label="filtered 20 Hz")
        per_wire = rec.contact_force_wire_N[:, p, :]
        if per_wire.shape[1] > 1:  # overlaps: how the force is shared between the wires
            for w in range(per_wire.shape[1]):
                if np.any(per_wire[:, w] > 0) and np.any(per_wire[:, w] < f):
                    ax.plot(x[:, p], per_wire[:, w], lw=0.7, ls="--", label=f"on wire of section {w + 1}")
        _marks(ax, result, x[:, p].min(), x[:, p].max())
        ax.set_ylabel(f"pantograph {p + 1}\ncontact force [N]")
        ax.legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("position along the line [m]")
    fig.tight_layout()
    paths.append(folder / f"{stem}_contact_force.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(2, 1, figsize=(11, 6), sharex=True)
    for p in range(n_p):
        axes[0].plot(x[:, p], 1e3 * (rec.panhead_z_m[:, p] - rec.panhead_z_m[0, p]), lw=0.8, label=f"pantograph {p + 1}")
        axes[1].plot(x[:, p], rec.panhead_acc_m_s2[:, p], lw=0.6)
    axes[0].set_ylabel("pan-head height change [mm]")
    axes[1].set_ylabel("pan-head acceleration [m/s^2]")
    axes[1].set_xlabel("position of the pan-head [m]")
    axes[0].legend(fontsize=8)
    for ax in axes:
        _marks(ax, result, lo, hi)
    fig.tight_layout()
    paths.append(folder / f"{stem}_panhead.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)

    st = result.form.structure
    fig, axes = plt.subplots(2, 1, figsize=(11, 6))
    sx = st.x[st.support_nodes]
    rise = 1e3 * (rec.support_z_m - rec.static_support_z_m[None, :])
    for j in range(len(sx)):
        if result.section_m[0] - st.design.span_length <= sx[j] <= result.section_m[1] + st.design.span_length:
            axes[0].plot(rec.t_s, rise[:, j], lw=0.8, label=f"support x={sx[j]:g} m")
    axes[0].set_xlabel("time [s]")
    axes[0].set_ylabel("contact-wire uplift\nat supports [mm]")
    axes[0].legend(fontsize=7, ncol=3)
    tension = rec.dropper_tension_N
    dx = st.x[st.dropper_nodes]
    inside = np.flatnonzero((dx >= result.section_m[0]) & (dx <= result.section_m[1]))
    for j in inside:
        axes[1].plot(rec.t_s, tension[:, j], lw=0.6)
        slack = tension[:, j] <= 0
        if slack.any():
            axes[1].plot(rec.t_s[slack], np.zeros(slack.sum()), "r.", ms=2)
    axes[1].set_xlabel("time [s]")
    axes[1].set_ylabel("dropper tension [N]\n(analysis section; red: slack)")
    fig.tight_layout()
    paths.append(folder / f"{stem}_uplift_droppers.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)
    return paths


def write_paraview_series(result, folder: Path, stem: str = "passage", points_per_element: int = 4) -> Path:
    """One VTU per snapshot (wires as polylines, droppers as lines with their tension, pan-heads
    as vertices with their contact force) and a ``.pvd`` index that ParaView opens as a time
    series. Returns the ``.pvd`` path."""
    import meshio

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rec = result.record
    st = result.form.structure
    line = result.line
    sets = [(st.system.body_set(b.name), 0) for b in st.contacts] + [(st.system.body_set(b.name), 1) for b in st.messengers]
    entries = []
    t_all = rec.t_s
    for k, (t, q) in enumerate(zip(rec.snapshot_t_s, rec.snapshot_q)):
        points, cells, kind, value = [], [], [], []
        start = 0
        for es, wire_id in sets:
            r, _ = es.sample(q, points_per_element)
            idx = np.arange(start, start + len(r))
            points.append(r)
            cells.append(np.column_stack([idx[:-1], idx[1:]]))
            kind.append(np.full(len(r) - 1, wire_id))
            value.append(np.zeros(len(r) - 1))
            start += len(r)
        a = q[st.cw_xyz[st.dropper_nodes]]
        b = q[st.mw_xyz[st.dropper_nodes]]
        nd = len(a)
        points.append(np.vstack([a, b]))
        cells.append(np.column_stack([start + np.arange(nd), start + nd + np.arange(nd)]))
        kind.append(np.full(nd, 2))
        value.append(st.dropper_state(q)[2])
        start += 2 * nd
        step = int(np.argmin(np.abs(t_all - t)))
        heads = np.column_stack([line.x_contact(t), np.zeros(len(line.runs)), rec.panhead_z_m[step]])
        points.append(heads)
        vertex = start + np.arange(len(heads))
        mesh = meshio.Mesh(
            np.vstack(points),
            [("line", np.vstack(cells)), ("vertex", vertex[:, None])],
            cell_data={"part_id": [np.concatenate(kind), np.full(len(heads), 3)],
                       "force_N": [np.concatenate(value), rec.contact_force_N[step]]},
        )
        name = f"{stem}_{k:05d}.vtu"
        mesh.write(folder / name)
        entries.append(f'    <DataSet timestep="{t:.6f}" part="0" file="{name}"/>')
    pvd = folder / f"{stem}.pvd"
    pvd.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
                   + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
    return pvd
