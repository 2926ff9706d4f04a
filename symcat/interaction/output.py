"""Looking at a passage: PNG plots and a ParaView time series (VTU files + a .pvd index).

ParaView data of every snapshot:

cell data ``part_id``
    0 contact-wire segments, 1 messenger segments, 2 droppers, 3 pan-heads (vertices).
cell data ``force_N``
    Dropper tension and pan-head contact force (N); 0 on wire segments.
point data ``displacement_m`` (3 components, m)
    Displacement from the static catenary without pantographs (the form-found equilibrium,
    the reference of the EN 50318 support uplift): wire and dropper points move with the
    wires; a pan-head's is its height above that static contact wire at its position (0, 0,
    dz), so Warp By Vector keeps it on the warped wire. Its z component is the uplift.
point data ``wire_id`` (integer)
    ``k - 1`` on the contact wire of tension section ``k`` (k = 1 .. n), ``n + k - 1`` on its
    messenger (one section: 0 contact wire, 1 messenger), -1 at dropper ends, -2 at pan-heads.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .statistics import lowpass


def _marks(ax, result, lo, hi) -> None:
    """Supports (solid), droppers (dotted) and the analysis section (shaded) between ``lo`` and
    ``hi`` (m), each labelled once for the legend; the section is clipped to ``lo .. hi`` so a
    short run's axis is not stretched (and listed as outside the run when it is)."""
    st = result.form.structure
    label = "support"
    for x in st.x[st.support_nodes]:
        if lo <= x <= hi:
            ax.axvline(x, color="0.3", lw=0.8, label=label)
            label = None
    label = "dropper"
    for x in st.x[st.dropper_nodes]:
        if lo <= x <= hi:
            ax.axvline(x, color="0.6", lw=0.6, ls=":", label=label)
            label = None
    a, b = result.section_m
    band = f"analysis section {a:g} to {b:g} m"
    if max(a, lo) < min(b, hi):
        ax.axvspan(max(a, lo), min(b, hi), color="tab:green", alpha=0.08, label=band)
    else:  # a legend entry only
        ax.plot([], [], color="tab:green", alpha=0.2, lw=6, label=f"{band} (not reached)")


def case_title(result, stem: str) -> str:
    """The case of a passage in words: catenary, speed, pantograph(s), contact model."""
    line, design = result.line, result.form.structure.design
    kind = result.pantograph_text()
    sections = f", {design.n_sections} tension sections" if design.n_sections > 1 else ""
    presag = 1e3 * max(design.presag) if len(design.presag) else 0.0
    return (f"{stem}: {line.speed * 3.6:g} km/h, {kind}, {line.contact} contact\n"
            f"{design.line_spans} spans of {design.span_length:g} m{sections}, presag {presag:.0f} mm, "
            f"{result.form.structure.elements_per_span} elements/span")


def plot_passage(result, folder: Path, stem: str = "passage") -> list[Path]:
    """Write the contact-force, pan-head, uplift and dropper plots; returns their paths.

    Contact force raw and 20 Hz filtered against position with supports (solid) and droppers
    (dotted) marked and the analysis section shaded; pan-head height and acceleration; contact
    wire uplift at the supports; dropper tensions in the analysis section with slack marked.
    Every figure is titled with the case (:func:`case_title`) and every mark is in a legend.
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
    title = case_title(result, stem)

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
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, borderaxespad=0)
    axes[-1, 0].set_xlabel("position along the line [m]")
    axes[0, 0].set_title(title, fontsize=9)
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
    for ax in axes:
        _marks(ax, result, lo, hi)
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, borderaxespad=0)
    axes[0].set_title(title, fontsize=9)
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
            tag = " (analysis)" if result.section_m[0] <= sx[j] <= result.section_m[1] else ""
            axes[0].plot(rec.t_s, rise[:, j], lw=0.8, label=f"support x={sx[j]:g} m{tag}")
    axes[0].set_xlabel("time [s]")
    axes[0].set_ylabel("contact-wire uplift\nat supports [mm]")
    axes[0].legend(fontsize=7, ncol=3)
    axes[0].set_title(title, fontsize=9)
    tension = rec.dropper_tension_N
    dx = st.x[st.dropper_nodes]
    inside = np.flatnonzero((dx >= result.section_m[0]) & (dx <= result.section_m[1]))
    label = "slack (no tension)"
    for j in inside:
        axes[1].plot(rec.t_s, tension[:, j], lw=0.6)
        slack = tension[:, j] <= 0
        if slack.any():
            axes[1].plot(rec.t_s[slack], np.zeros(slack.sum()), "r.", ms=2, label=label)
            label = None
    if label is None:
        axes[1].legend(fontsize=7, loc="upper right")
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
    series. Point data ``displacement_m`` (from the static catenary) and ``wire_id``, cell data
    ``part_id`` and ``force_N`` (module docstring). Returns the ``.pvd`` path."""
    import meshio

    from ..results.paraview import write_pvd

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rec = result.record
    st = result.form.structure
    line = result.line
    n_sec = len(st.contacts)
    # (element set, part_id, wire_id): contact wires 0 .. n-1, messengers n .. 2n-1
    sets = ([(st.system.body_set(b.name), 0, k) for k, b in enumerate(st.contacts)]
            + [(st.system.body_set(b.name), 1, n_sec + k) for k, b in enumerate(st.messengers)])
    q0 = line.q_static
    static = [es.sample(q0, points_per_element)[0] for es, _, _ in sets]
    static_droppers = np.vstack([q0[st.cw_xyz[st.dropper_nodes]], q0[st.mw_xyz[st.dropper_nodes]]])

    def static_contact_height(x: float) -> float:
        """Height of the lowest static contact wire at ``x`` (the one in running)."""
        z = [np.interp(x, r[:, 0], r[:, 2]) for r in static[:n_sec] if r[0, 0] <= x <= r[-1, 0]]
        return min(z) if z else np.nan

    entries = []
    t_all = rec.t_s
    for k, (t, q) in enumerate(zip(rec.snapshot_t_s, rec.snapshot_q)):
        points, cells, kind, value, disp, wire = [], [], [], [], [], []
        start = 0
        for (es, part, wire_id), r0 in zip(sets, static):
            r, _ = es.sample(q, points_per_element)
            idx = np.arange(start, start + len(r))
            points.append(r)
            disp.append(r - r0)
            wire.append(np.full(len(r), wire_id))
            cells.append(np.column_stack([idx[:-1], idx[1:]]))
            kind.append(np.full(len(r) - 1, part))
            value.append(np.zeros(len(r) - 1))
            start += len(r)
        a = q[st.cw_xyz[st.dropper_nodes]]
        b = q[st.mw_xyz[st.dropper_nodes]]
        nd = len(a)
        points.append(np.vstack([a, b]))
        disp.append(points[-1] - static_droppers)
        wire.append(np.full(2 * nd, -1))
        cells.append(np.column_stack([start + np.arange(nd), start + nd + np.arange(nd)]))
        kind.append(np.full(nd, 2))
        value.append(st.dropper_state(q)[2])
        start += 2 * nd
        step = int(np.argmin(np.abs(t_all - t)))
        x_heads = line.x_contact(t)
        heads = np.column_stack([x_heads, np.zeros(len(x_heads)), rec.panhead_z_m[step]])
        points.append(heads)
        lift = heads[:, 2] - np.array([static_contact_height(x) for x in x_heads])
        disp.append(np.column_stack([np.zeros((len(heads), 2)), lift]))
        wire.append(np.full(len(heads), -2))
        vertex = start + np.arange(len(heads))
        mesh = meshio.Mesh(
            np.vstack(points),
            [("line", np.vstack(cells)), ("vertex", vertex[:, None])],
            point_data={"displacement_m": np.vstack(disp), "wire_id": np.concatenate(wire).astype(np.int32)},
            cell_data={"part_id": [np.concatenate(kind), np.full(len(heads), 3)],
                       "force_N": [np.concatenate(value), rec.contact_force_N[step]]},
        )
        name = f"{stem}_{k:05d}.vtu"
        mesh.write(folder / name)
        entries.append((float(t), name))
    return write_pvd(folder / f"{stem}.pvd", entries, "part_id: 0 contact wire, 1 messenger, 2 dropper, 3 pan-head; "
                     f"wire_id: 0..{n_sec - 1} contact wires, {n_sec}..{2 * n_sec - 1} messengers (by tension "
                     "section), -1 dropper ends, -2 pan-heads; displacement_m from the static catenary")
