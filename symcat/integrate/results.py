"""The result of a simulation (:class:`SimulationResult`) and its assembly from the
integrator's states: multipliers from the KKT system at each output (exact for the state,
whatever IDAS's tolerance on algebraic variables), drifts, energies, joint reactions, contact
and wheel/rail histories."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
import scipy.sparse.linalg as spla

from ..assembly.sparse import to_scipy
from ..assembly.wheelrail import GAP_ROW
from ..dae.formulation import Formulation
from ..dae.initial import CreepCoupling, kkt_solver_closed
from .failure import split_state

@dataclass
class SimulationResult:
    """Time histories of a simulation (SI units; names carry the unit).

    Attributes
    ----------
    t_s : ndarray (n_t,)
    q, v : ndarray (n_t, n_q)
        All generalized coordinates and velocities (fixed ones included).
    s_m, s_dot_m_s : ndarray (n_t, n_s)
        Arc-length parameters of the sliding joints and their rates.
    multipliers : ndarray (n_t, n_c)
        Lagrange multipliers of every constraint row (``row_names``), recomputed at each output
        from the KKT system of eq. (25) for the integrated state, so they are exact for that
        state and identical in meaning for every formulation.
    reactions_N : dict
        Joint name -> (n_t, 3) constraint force (global, N) on the joint's ``body`` (sliding
        and driving joints) or ``body_j`` (two-body joints; on the ground: minus the force on
        ``body_i``).
    energy_J : dict
        ``kinetic``, ``potential`` and ``total`` (n_t,).
    position_drift, velocity_drift : ndarray (n_t,)
        Max-norm of ``C`` and of ``C_q v + C_s s_dot + C_t``.
    stats : dict
        IDAS statistics summed over chunks, restarts, wall time.
    a : ndarray (n_t, n_q)
        Accelerations (m/s^2, 1/s^2), from the same KKT solve as the multipliers.
    contacts : dict
        Penalty contact name -> ``{"s_m", "gap_m", "force_N"}`` histories (n_t,): arc length,
        normal gap (> 0 separated) and normal force.
    wheelrail : dict
        Wheel/rail contact name -> histories: ``normal_force_N`` (n_t,), the surface parameters
        ``s`` (n_t, 4: s1w m, s2w rad, s1r m, s2r m), ``xi_x``, ``xi_y`` (-), ``phi_per_m``
        (spin, 1/m), the creep forces ``fx_N``, ``fy_N``, ``mz_Nm`` (zero without creep), the
        normal gap ``gap_m`` (> 0 separated; the constraint drift while in contact), ``open``
        (bool: lifted off, see :mod:`.contact_switching`) and the times (s) of its lift-offs and
        touchdowns, ``lift_off_s`` and ``touchdown_s``.
    """

    t_s: np.ndarray
    q: np.ndarray
    v: np.ndarray
    s_m: np.ndarray
    s_dot_m_s: np.ndarray
    multipliers: np.ndarray
    row_names: list
    coordinate_names: list
    reactions_N: dict = field(default_factory=dict)
    energy_J: dict = field(default_factory=dict)
    position_drift: np.ndarray | None = None
    velocity_drift: np.ndarray | None = None
    stats: dict = field(default_factory=dict)
    a: np.ndarray | None = None
    contacts: dict = field(default_factory=dict)
    wheelrail: dict = field(default_factory=dict)

    def coordinate(self, name: str) -> np.ndarray:
        """History of one coordinate, e.g. ``"wire[3].z"`` or ``"body.x"``."""
        return self.q[:, self.coordinate_names.index(name)]

    def save(self, path) -> None:
        """Named arrays with units in an ``.npz`` file."""
        arrays = {"t_s": self.t_s, "q": self.q, "v": self.v, "s_m": self.s_m, "s_dot_m_s": self.s_dot_m_s,
                  "multipliers": self.multipliers, "position_drift": self.position_drift,
                  "velocity_drift": self.velocity_drift,
                  **{f"energy_{k}_J": v for k, v in self.energy_J.items()},
                  **{f"reaction_{k}_N": v for k, v in self.reactions_N.items()},
                  **{f"contact_{k}_{n}": v for k, c in self.contacts.items() for n, v in c.items()},
                  **{f"wheelrail_{k}_{n}": v for k, c in self.wheelrail.items() for n, v in c.items()},
                  **({"a": self.a} if self.a is not None else {}),
                  "coordinate_names": np.array(self.coordinate_names), "row_names": np.array(self.row_names)}
        np.savez_compressed(path, **arrays)


def collect_result(form: Formulation, t, xs, zs, stats, wall0, opens, events) -> SimulationResult:
    model = form.model
    # Post-processing sees the whole wire: the integration windows have moved on.
    saved = [sl.window for sl in model.windowed()]
    for sl in model.windowed():
        sl.window = (0, len(sl.element_start) - 1)
    try:
        return _collect(form, t, xs, zs, stats, wall0, opens, events)
    finally:
        for sl, w in zip(model.windowed(), saved):
            sl.window = w


def _collect(form: Formulation, t, xs, zs, stats, wall0, opens, events) -> SimulationResult:
    model = form.model
    n_f, n_s = form.n_f, form.n_s
    parts = [split_state(form, x, z) for x, z in zip(xs, zs)]
    q = np.tile(model.q0, (len(parts), 1))
    v = np.zeros_like(q)
    for k, p in enumerate(parts):
        q[k, model.free] = form.to_physical(p["q"])
        v[k, model.free] = form.to_physical(p["v"])
    s = np.array([p["s"] for p in parts]).reshape(len(parts), n_s)
    qs, vs = ca.MX.sym("q", n_f), ca.MX.sym("v", n_f)
    ss, ws, ts = ca.MX.sym("s", n_s), ca.MX.sym("w", n_s), ca.MX.sym("t")
    scs = ca.MX.sym("sc", form.n_sc)
    if form.formulation == "embedded" and n_s:
        k = form.embedded_terms(qs, vs, ss, ts, scs)
        s_dot_expr = k["s_dot"]
    else:
        s_dot_expr = ws
    kk = form.terms(qs, vs, ss, s_dot_expr, ts, scs)
    qf = form.q_fixed + ca.mtimes(form.P, qs)
    vf = ca.mtimes(form.P, vs)
    energy = ca.Function("e", [qs, vs], [model.kinetic_energy(qf, vf), model.potential_energy(qf)])
    drift = ca.Function("d", [qs, vs, ss, ws, ts, scs], [kk["C"], ca.mtimes(kk["Cq"], vs) + ca.mtimes(kk["Cs"], s_dot_expr) + kk["Ct"],
                                                        s_dot_expr, kk["Cq"], kk["Cs"], kk["M"], kk["Q"], kk["Qd"],
                                                        kk["gap"], kk["fc"]])
    n_sc = form.n_sc
    sc = np.array([p.get("sc", np.zeros(0)) for p in parts]).reshape(len(parts), n_sc)
    gaps, contact_forces = np.zeros((len(parts), n_sc)), np.zeros((len(parts), n_sc))
    acc = np.zeros_like(q)
    lam = np.zeros((len(parts), model.n_c))
    s_dot = np.zeros((len(parts), n_s))
    normal_rows = [e.row_start + GAP_ROW for e in model.wheelrail]  # the gap rows (lam: augmented layout)
    creep_record = np.zeros((len(parts), 6 * len(model.wheelrail)))
    wheel_gap = np.zeros((len(parts), len(model.wheelrail)))
    creep_fn = form.creep_function() if model.wheelrail else None
    pos, vel, kin, pot = (np.zeros(len(parts)) for _ in range(4))
    reactions = {name.split("[")[0]: np.zeros((len(parts), 3)) for name in model.row_names}
    for i, (p, ti) in enumerate(zip(parts, t)):
        w = p.get("w", np.zeros(n_s))
        c, cdot, sd, cq, cs, mass, force, qd, gap, fc = drift(p["q"], p["v"], p["s"], w, ti, sc[i])
        gaps[i], contact_forces[i] = np.asarray(gap).ravel(), np.asarray(fc).ravel()
        s_dot[i] = np.asarray(sd).ravel()
        closed = np.setdiff1d(np.arange(model.n_c), form.open_rows(opens[i]) if model.wheelrail else [])
        c = np.asarray(c).ravel()
        wheel_gap[i] = [c[e.row_start + GAP_ROW] if e.joint.form == "railframe"
                        else e.contact.gap(q[i, e.rows], p["s"][e.s_index : e.s_index + 4]) for e in model.wheelrail]
        pos[i] = np.abs(c[closed]).max(initial=0.0)
        vel[i] = np.abs(np.asarray(cdot).ravel()[closed]).max(initial=0.0)
        # Multipliers from the KKT system at each output (exact for the state, whatever IDAS's
        # tolerance on algebraic variables): the same for every formulation.
        if model.n_c:
            creep = CreepCoupling(form, p["q"], p["v"], p["s"], s_dot[i], normal_rows)
            mass_i, cq_i = to_scipy(mass), to_scipy(cq).tocsr()[closed].tocsc()
            cs_i, qd_i = np.asarray(ca.densify(cs))[closed], np.asarray(qd).ravel()[closed]
            solve = kkt_solver_closed(mass_i, cq_i, cs_i, closed, model.n_c)
            a_i, _, lam[i] = creep.solve(lambda f: solve(f, qd_i), np.asarray(force).ravel())
            if creep.active:
                creep_record[i] = np.asarray(creep_fn(p["q"], p["v"], p["s"], s_dot[i], -lam[i][normal_rows])[1]).ravel()
        else:
            a_i = spla.spsolve(to_scipy(mass).tocsc(), np.asarray(force).ravel()) if n_f else np.zeros(0)
        acc[i, model.free] = form.to_physical(np.atleast_1d(a_i))
        e_k, e_p = energy(p["q"], p["v"])
        kin[i], pot[i] = float(e_k), float(e_p)
        _reactions(model, form, np.asarray(ca.densify(cq)), lam[i], reactions, i)
    wall = time.perf_counter() - wall0
    stats = {**stats, "wall_s": wall, "steps": stats.get("nsteps", 0)}
    return SimulationResult(
        t_s=np.asarray(t), q=q, v=v, s_m=s, s_dot_m_s=s_dot, multipliers=lam, row_names=model.row_names,
        coordinate_names=model.coordinate_names(), reactions_N=reactions,
        energy_J={"kinetic": kin, "potential": pot, "total": kin + pot}, position_drift=pos, velocity_drift=vel,
        stats=stats, a=acc,
        contacts={ct.joint.name: {"s_m": sc[:, k], "gap_m": gaps[:, k], "force_N": contact_forces[:, k]}
                  for k, ct in enumerate(model.contacts)},
        wheelrail={e.joint.name: {"normal_force_N": _normal_force(e, lam), "s": s[:, e.s_index : e.s_index + 4],
                                  "gap_m": wheel_gap[:, k], "open": np.array([o[k] for o in opens], bool),
                                  **{f"{kind.replace('-', '_')}_s": np.array([ev.t_s for ev in events if ev.name == e.joint.name
                                                                              and ev.kind == kind]) for kind in ("lift-off", "touchdown")},
                                  **{name: creep_record[:, 6 * k + j] for j, name in
                                     enumerate(("xi_x", "xi_y", "phi_per_m", "fx_N", "fy_N", "mz_Nm"))}}
                   for k, e in enumerate(model.wheelrail)},
    )


def _normal_force(entry, lam) -> np.ndarray:
    """Normal force (N) of a wheel/rail contact from the multipliers: minus that of the gap row
    (eq. 22), or, for eq. 21 (frictionless), the magnitude of the three distance rows' force."""
    rows = lam[:, entry.row_start : entry.row_start + 3]
    if entry.joint.form == "railframe":
        return -rows[:, 2]
    return -np.sign(rows[:, 2]) * np.linalg.norm(rows, axis=1)


def _reactions(model, form, cq_free, lam, reactions, i):
    """Constraint force on body j of each joint: -(C_q rows of body j's first 3 coordinates)^T lambda
    (for joints to the ground, minus the force on body i)."""
    full = np.zeros((cq_free.shape[0], model.n_q))
    full[:, model.free] = cq_free
    names = [n.split("[")[0] for n in model.row_names]
    for name in reactions:
        rows = [r for r, n in enumerate(names) if n == name]
        gen = -full[rows].T @ lam[rows]
        reactions[name][i] = _force_on_j(model, name, gen)


def _force_on_j(model, name, gen):
    """Force on the joint's reporting body: ``body`` of sliding and driving joints, ``body_j``
    of two-body joints, or the ground (minus the force on ``body_i``)."""
    joint = next((j for j in model.scene.joints if j.name == name), None)
    if joint is None:  # Euler-parameter normalization rows carry no force
        return np.zeros(3)
    ref = getattr(joint, "body", None) or joint.body_j
    if ref == "ground":
        return -gen[_first3(model, joint.body_i)]
    return gen[_first3(model, ref)]


def _first3(model, ref):
    if isinstance(ref, tuple):
        body = model.scene.find(ref[0])
        return model.ancf.dofs.node_indices(body, ref[1])[:3]
    start = model.rigid_offset[ref]
    return np.arange(start, start + 3)
