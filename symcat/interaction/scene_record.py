"""The records of a multibody line passage (:mod:`.scene_passage`): the per-step monitor of its
penalty contacts, the histories read from a run's outputs, :class:`SceneRecord`, which holds them
under names with their SI units for the statistics, plots and files, and :func:`load_passage`,
which reads a saved record back."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..catenary.formfinding import FormFindingResult
from .scene_pantographs import SECTION_MARK


#: Why a :class:`SceneRecord` has no value for these summary entries.
NOT_COMPUTED = {
    "energy_balance_error_J": "not recorded for this scene (its wheel/rail contacts' creep forces are not in the "
                              "balance)",
    "contact_work_J": "not recorded for this scene (see energy_balance_error_J)",
    "newton_iterations_per_step": "not recorded per step on the multibody path (stats holds the total)",
}


class SceneRecord:
    """Histories of a :func:`~.scene_passage.run_scene_passage`, named with their SI units
    (``p`` pantographs, leading first; ``w`` contact wires of the tension sections). The
    attributes are NumPy arrays, SI units in the names.

    Attributes
    ----------
    t_s : (n,)
    x_contact_m, contact_force_N, penetration_m, panhead_z_m, panhead_acc_m_s2 : (n, p)
        Pan-head position along the line, contact force, penetration (minus the normal gap;
        bilateral: the largest constraint violation of the step), height and vertical
        acceleration of the pan-head's body.
    contact_force_wire_N : (n, p, w)
    work_power_W, dissipation_power_W : (n,)
        Power of the driving (the prescribed speed) and dissipated by the dampers.
    energy_J : (n,)
        Energy of the whole scene at the snapshots (NaN between them).
    support_z_m : (n, n_supports)
    dropper_tension_N : (n, n_droppers)
    snapshot_t_s, snapshot_q : (n_snapshots,), (n_snapshots, n_catenary_coordinates)
    static_support_z_m : (n_supports,)
        Contact-wire heights at the supports of the static catenary without pantographs.
    uplift_N, static_contact_force_N : float
    stats : dict
        The integrator's statistics (``wall_s``, ``steps``, ...).
    not_computed : dict
        Summary entries this path does not have, and why.
    """

    def __init__(self, arrays: dict, form: FormFindingResult, speed: float, stats: dict):
        self._arrays = arrays
        self._form = form
        self._speed = speed
        self.stats = stats
        self.not_computed = {k: why for k, why in NOT_COMPUTED.items() if k not in (
            ("energy_balance_error_J", "contact_work_J") if "energy_J" in arrays else ())}

    def __getattr__(self, name):
        arrays = self.__dict__.get("_arrays", {})
        if name in arrays:
            return arrays[name]
        raise AttributeError(name)

    @property
    def static_support_z_m(self) -> np.ndarray:
        st = self._form.structure
        return np.asarray(self._form.q)[st.cw_xyz[st.support_nodes, 2]]

    def energy_balance(self) -> dict[str, np.ndarray] | None:
        """Energy (J) of the whole system at the snapshots against its start plus the work of
        the driving (the train's prescribed speed) minus what the dampers dissipated
        (:func:`symcat.assembly.energy.balance`); ``error_J`` is what the time integration
        gained or lost (generalized-alpha with rho_inf < 1 damps). None when not recorded
        (``not_computed``)."""
        from ..assembly.energy import balance

        if "energy_J" not in self._arrays:
            return None
        e = np.asarray(self._arrays["energy_J"])
        at = np.isfinite(e)
        return balance(self.t_s, self.work_power_W, -np.asarray(self.dissipation_power_W), self.t_s[at], e[at])

    def arrays(self) -> dict[str, np.ndarray]:
        """Every recorded array by name (SI units in the names), with the catenary's stations,
        supports, droppers, static support heights and the speed."""
        st = self._form.structure
        out = dict(self._arrays)
        out.update(station_x_m=st.x, support_x_m=st.x[st.support_nodes], dropper_x_m=st.x[st.dropper_nodes],
                   dropper_length_m=st.dropper_length, static_support_z_m=self.static_support_z_m,
                   speed_m_s=np.array(self._speed))
        return out

    def save(self, path) -> Path:
        """Write every array to ``path`` (.npz; :func:`load_passage` reads it)."""
        path = Path(path)
        np.savez_compressed(path, **self.arrays())
        return path



def load_passage(path) -> dict[str, np.ndarray]:
    """Read a passage saved by :meth:`SceneRecord.save` back as a dict of named arrays (units in
    the names)."""
    with np.load(path) as data:
        return {k: data[k] for k in data.files}

def _monitor(form, model, elements, energy, snapshot_every: float):
    """Per-step records of the penalty contacts' passage (generalized-alpha's ``monitor``, of
    the states after several steps at once): what the statistics need at every step, without
    a full output per step (one column per pantograph; the force on each tension section's
    contact wire in ``contact_force_wire_N``, a pan-head's force their sum and its
    penetration the largest), the work rates of the
    energy balance (``energy``: the model's :class:`~symcat.assembly.energy.EnergyTerms`) and
    the energy at the snapshots (``energy_J``, NaN between them)."""
    st = form.structure
    heads = np.array([model.rigid_offset[e.body] for e in elements])
    names = [ct.joint.name for ct in model.contacts]
    wires = [b.name for b in st.contacts]
    # (pantograph, wire) -> contact index: the pan-head's contact on its running wire or a copy
    index = np.full((len(elements), len(wires)), -1)
    for p, e in enumerate(elements):
        for k, name in enumerate(names):
            if name == e.name or name.startswith(e.name + SECTION_MARK):
                index[p, wires.index(model.contacts[k].joint.wire)] = k
    has = index >= 0
    at = np.where(has, index, 0)
    supports = st.cw_xyz[st.support_nodes, 2]
    next_snapshot = [0.0]

    def monitor(s):  # the states after several steps (StepStates): one row per step
        force = np.where(has, s.force_N[:, at], 0.0)
        driving, other = energy.powers(s.q, s.v, s.sc_m, s.multipliers, s.t_s)
        e = np.full(len(s), np.nan)
        for i, t in enumerate(s.t_s):
            if t >= next_snapshot[0] - 1e-9:  # as the snapshots (_snapshots)
                e[i] = sum(energy.energy(s.q[i], s.v[i], s.sc_m[i]))
                next_snapshot[0] = t + snapshot_every
        return {"x_contact_m": s.q[:, heads], "contact_force_N": force.sum(axis=2), "contact_force_wire_N": force,
                "penetration_m": np.where(has, -s.gap_m[:, at], -np.inf).max(axis=2), "panhead_z_m": s.q[:, heads + 2],
                "panhead_acc_m_s2": s.a[:, heads + 2], "support_z_m": s.q[:, supports],
                "dropper_tension_N": st.dropper_state(s.q[:, : st.n])[2], "work_power_W": driving,
                "dissipation_power_W": -other, "energy_J": e}

    return monitor


def record_histories(res, form, model, elements, snapshot_every: float, energy=None) -> dict:
    """The SceneRecord arrays of a SimulationResult (per-step values from its ``monitored``
    records when there are, snapshots from its outputs), one column per pan-head contact of
    ``elements`` (a list, leading pantograph first, or one element); with ``energy`` (the
    model's :class:`~symcat.assembly.energy.EnergyTerms`), the work rates at the outputs and the
    energy at the snapshots, for the energy balance."""
    from ..scene import PenaltyContact

    st = form.structure
    q = np.asarray(res.q)
    if res.monitored:
        m = res.monitored
        snap = _snapshots(np.asarray(res.t_s), snapshot_every)
        return {"t_s": m["t_s"], **{key: m[key] for key in ("x_contact_m", "contact_force_N", "penetration_m",
                                                             "panhead_z_m", "panhead_acc_m_s2", "work_power_W",
                                                             "dissipation_power_W", "energy_J")},
                "contact_force_wire_N": m["contact_force_wire_N"], "support_z_m": m["support_z_m"],
                "dropper_tension_N": m["dropper_tension_N"], "snapshot_t_s": np.asarray(res.t_s)[snap],
                "snapshot_q": q[snap, : st.n]}
    elements = list(elements) if isinstance(elements, (list, tuple)) else [elements]
    heads = np.array([model.rigid_offset[e.body] for e in elements])
    force, penetration = [], []
    for e in elements:
        if isinstance(e, PenaltyContact):
            c = res.contacts[e.name]
            force.append(np.asarray(c["force_N"]))
            penetration.append(-np.asarray(c["gap_m"]))
        else:  # a sliding joint: its reaction on the pan-head, the largest constraint violation
            force.append(-np.asarray(res.reactions_N[e.name])[:, 2])
            penetration.append(np.asarray(res.position_drift))
    force, penetration = np.array(force).T, np.array(penetration).T
    t = np.asarray(res.t_s)
    snap = _snapshots(t, snapshot_every)
    q_cat = q[:, : st.n]
    extra = {}
    if energy is not None:
        v, lam = np.asarray(res.v), np.asarray(res.multipliers)
        sc = np.array([res.contacts[c.joint.name]["s_m"] for c in model.contacts]).T.reshape(len(t), -1)
        powers = np.array([energy.power(q[i], v[i], sc[i], lam[i], t[i]) for i in range(len(t))])
        e = np.full(len(t), np.nan)
        e[snap] = [sum(energy.energy(q[i], v[i], sc[i])) for i in snap]
        extra = {"work_power_W": powers[:, 0], "dissipation_power_W": -powers[:, 1], "energy_J": e}
    return {
        **extra,
        "t_s": t,
        "x_contact_m": q[:, heads],
        "contact_force_N": force,
        "contact_force_wire_N": force[:, :, None],
        "penetration_m": penetration,
        "panhead_z_m": q[:, heads + 2],
        "panhead_acc_m_s2": np.asarray(res.a)[:, heads + 2],
        "support_z_m": q_cat[:, st.cw_xyz[st.support_nodes, 2]],
        "dropper_tension_N": np.array([st.dropper_state(qk)[2] for qk in q_cat]),
        "snapshot_t_s": t[snap],
        "snapshot_q": q_cat[snap],
    }


def _snapshots(t: np.ndarray, every: float) -> list[int]:
    """Indices of the outputs at least ``every`` seconds apart, from the first."""
    snap = [0]
    for k in range(1, len(t)):
        if t[k] >= t[snap[-1]] + every - 1e-12:
            snap.append(k)
    return snap
