"""What a pantograph passage records: contact histories every step, snapshots of the wires.

Arrays are named with their SI unit (``contact_force_N``, ``x_contact_m``, ...) and saved to
one ``.npz`` that :func:`load_passage` reads back.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


class PassageRecorder:
    """Collects the histories of a run of a :class:`~symcat.interaction.coupled.CoupledLine`.

    Attributes (after :meth:`finish`, all NumPy arrays)
    ----------------------------------------------------
    t_s : (n_steps,)
    x_contact_m, contact_force_N, penetration_m, panhead_z_m, panhead_acc_m_s2 : (n_steps, n_pantographs)
        (the force is the total on the pan-head; the penetration that of the lowest wire)
    contact_force_wire_N : (n_steps, n_pantographs, n_sections)  force on each section's wire
    support_z_m : (n_steps, n_supports)   contact-wire height at every support
    dropper_tension_N : (n_steps, n_droppers)
    iterations : (n_steps,)  Newton iterations per step
    snapshot_t_s : (n_snapshots,) and snapshot_q : (n_snapshots, n_catenary_coordinates)
    stats : dict  (wall time, steps, refactorisations, ...)
    """

    def __init__(self, line, record_every: float):
        self.line = line
        self.record_every = record_every
        self._rows: dict[str, list] = {k: [] for k in (
            "t_s", "x_contact_m", "contact_force_N", "contact_force_wire_N", "penetration_m", "panhead_z_m", "panhead_acc_m_s2",
            "support_z_m", "dropper_tension_N", "iterations", "work_power_W", "dissipation_power_W")}
        self._snap_t, self._snap_q, self._snap_u, self._snap_e = [], [], [], []
        self._next_snapshot = 0.0
        self.stats: dict = {}

    def record(self, t, y, v, acc, states, contact_forces, iterations) -> None:
        line = self.line
        st = line.structure
        q = line.catenary_q(y)
        rows = self._rows
        rows["t_s"].append(t)
        rows["x_contact_m"].append(line.x_contact(t))
        rows["contact_force_N"].append(line.per_pantograph(states, contact_forces))
        rows["contact_force_wire_N"].append(line.per_wire(states, contact_forces))
        deepest = np.full(len(line.runs), -np.inf)
        for s in states:
            deepest[s.pantograph] = max(deepest[s.pantograph], s.delta)
        rows["penetration_m"].append(deepest)
        rows["panhead_z_m"].append(line.z_ref + y[line.head_index])
        rows["panhead_acc_m_s2"].append(acc[line.head_index])
        rows["support_z_m"].append(q[st.cw_xyz[st.support_nodes, 2]])
        rows["dropper_tension_N"].append(st.dropper_state(q)[2])
        rows["iterations"].append(iterations)
        # work done by the moving contact points (explicit time dependence of the contact)
        rows["work_power_W"].append(sum(-f * s.slope * line.speed for f, s in zip(contact_forces, states)))
        rows["dissipation_power_W"].append(line.dissipation_power(v))
        if t >= self._next_snapshot - 1e-12:
            self._snap_t.append(t)
            self._snap_q.append(q)
            self._snap_u.append(y[line.n_cat:].copy())
            self._snap_e.append(line.energy(y, v, t)["total_J"])
            self._next_snapshot += self.record_every

    def finish(self, **stats) -> None:
        self.stats.update(stats)
        self.stats["steps"] = len(self._rows["t_s"]) - 1
        self.stats["newton_iterations"] = int(np.sum(self._rows["iterations"]))

    def __getattr__(self, name):
        rows = self.__dict__.get("_rows", {})
        if name in rows:
            return np.asarray(rows[name])
        if name == "snapshot_t_s":
            return np.asarray(self._snap_t)
        if name == "snapshot_q":
            return np.asarray(self._snap_q)
        if name == "snapshot_pantograph_m":
            return np.asarray(self._snap_u)
        raise AttributeError(name)

    def energy_balance(self) -> dict[str, np.ndarray]:
        """Energy (J) at the snapshots against the work done by the moving contacts minus the
        damper dissipation since the start (:func:`symcat.assembly.energy.balance`, as the
        multibody path's). ``error_J`` is what the time integration lost or gained
        (generalized-alpha with rho_inf < 1 damps)."""
        from ..assembly.energy import balance

        return balance(self._rows["t_s"], self._rows["work_power_W"], -np.asarray(self._rows["dissipation_power_W"]),
                       self.snapshot_t_s, np.asarray(self._snap_e))

    @property
    def static_support_z_m(self) -> np.ndarray:
        """Contact-wire heights at the supports in the static equilibrium without pantographs."""
        st = self.line.structure
        return self.line.q_static[st.cw_xyz[st.support_nodes, 2]]

    def arrays(self) -> dict[str, np.ndarray]:
        """Every recorded array by name (SI units in the names)."""
        st = self.line.structure
        out = {k: np.asarray(v) for k, v in self._rows.items()}
        out.update(snapshot_t_s=self.snapshot_t_s, snapshot_q=self.snapshot_q,
                   snapshot_pantograph_m=self.snapshot_pantograph_m, station_x_m=st.x,
                   support_x_m=st.x[st.support_nodes], dropper_x_m=st.x[st.dropper_nodes],
                   dropper_length_m=st.dropper_length, static_support_z_m=self.static_support_z_m,
                   speed_m_s=np.array(self.line.speed))
        return out

    def save(self, path) -> Path:
        """Write every array to ``path`` (.npz)."""
        path = Path(path)
        np.savez_compressed(path, **self.arrays())
        return path


def load_passage(path) -> dict[str, np.ndarray]:
    """Read a saved passage back as a dict of named arrays (units in the names)."""
    with np.load(path) as data:
        return {k: data[k] for k in data.files}
