"""The result of a simulation (:class:`SimulationResult`) and its assembly from the
integrator's states: multipliers from the KKT system at each output (exact for the state,
whatever IDAS's tolerance on algebraic variables), drifts, energies, joint reactions, contact
and wheel/rail histories."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..assembly.wheelrail import GAP_ROW
from ..dae.formulation import Formulation, normal_forces_numeric
from ..dae.initial import KKTPattern, settle_creep
from .post_terms import Mapped, mapped_terms

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
    output_wall_s : ndarray (n_t,)
        Wall time (s) from the run's start at which each output's state was known (the speed of
        a part of the run: ``diff(output_wall_s) / diff(t_s)``).
    contacts : dict
        Penalty contact name -> ``{"s_m", "gap_m", "force_N"}`` histories (n_t,): arc length,
        normal gap (> 0 separated) and normal force.
    wheelrail : dict
        Wheel/rail contact name -> histories: ``normal_force_N`` (n_t,; minus the gap row's
        multiplier in the rail-frame form, minus the coincidence rows' multipliers projected on
        the rail's outward normal in the global form: the force the creep laws use), the surface parameters
        ``s`` (n_t, 4: s1w m, s2w rad, s1r m, s2r m), ``xi_x``, ``xi_y`` (-), ``phi_per_m``
        (spin, 1/m), the creep forces ``fx_N``, ``fy_N``, ``mz_Nm`` (zero without creep), the
        normal gap ``gap_m`` (> 0 separated; the constraint drift while in contact), ``open``
        (bool: lifted off, see :mod:`symcat.wheelrail_events.contact_switching`) and the times
        (s) of its lift-offs and touchdowns, ``lift_off_s`` and ``touchdown_s``.
    monitored : dict
        Generalized-alpha's per-step records (its ``monitor``): ``t_s`` (n_steps + 1,) and the
        monitor's keys stacked over the steps; empty otherwise.
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
    output_wall_s: np.ndarray | None = None
    contacts: dict = field(default_factory=dict)
    wheelrail: dict = field(default_factory=dict)
    monitored: dict = field(default_factory=dict)

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
                  **({"output_wall_s": self.output_wall_s} if self.output_wall_s is not None else {}),
                  "coordinate_names": np.array(self.coordinate_names), "row_names": np.array(self.row_names)}
        np.savez_compressed(path, **arrays)


def collect_result(form: Formulation, t, xs, zs, stats, wall0, opens, events, walls=None,
                   given=None, compiled: bool = False) -> SimulationResult:
    """The :class:`SimulationResult` of the outputs ``xs``, ``zs`` at times ``t``.

    ``given = (accelerations, multipliers[, contacts])`` (free internal coordinates, (n, n_f) and
    (n, n_c)): the integrator's own, used instead of solving the KKT system at each output
    (which costs a sparse factorization of the mass matrix per output: most of the
    post-processing of a long run on a line); ``contacts``, if given and not None, the penalty
    contacts' gaps and normal forces ((n, n_sc) each), used instead of evaluating the contacts
    with windows over whole wires."""
    model = form.model
    # Post-processing sees the whole wire: the integration windows have moved on.
    saved = [sl.window for sl in model.windowed()]
    for sl in model.windowed():
        sl.window = (0, len(sl.element_start) - 1)
    try:
        res = _collect(form, t, xs, zs, stats, wall0, opens, events, given, compiled)
        if walls is not None:
            res.output_wall_s = np.asarray(walls[: len(res.t_s)], float)
        return res
    finally:
        for sl, w in zip(model.windowed(), saved):
            sl.window = w


#: Outputs per mapped evaluation of the post-processing terms (bounds the memory of long runs).
CHUNK = 256


def _collect(form: Formulation, t, xs, zs, stats, wall0, opens, events, given=None,
             compiled: bool = False) -> SimulationResult:
    model = form.model
    state = _stacked_state(form, xs, zs)
    n_t = state["q"].shape[0]
    q, v = _physical(form, state["q"], model.q0), _physical(form, state["v"], np.zeros(model.n_q))
    given_contacts = given[2] if given is not None and len(given) > 2 else None
    post = _PostTerms(form, light=given is not None, contacts=given_contacts is None, compiled=compiled)
    n_w = len(model.wheelrail)
    gaps, contact_forces = np.zeros((n_t, form.n_sc)), np.zeros((n_t, form.n_sc))
    acc = np.zeros_like(q)
    lam = np.zeros((n_t, model.n_c))
    s_dot = np.zeros((n_t, form.n_s))
    creep_record = np.zeros((n_t, 6 * n_w))
    normal = np.zeros((n_t, n_w))
    wheel_gap = np.zeros((n_t, n_w))
    pos, vel, kin, pot = (np.zeros(n_t) for _ in range(4))
    reactions = {name: np.zeros((n_t, 3)) for name in post.reactions.names}
    open_rows = [tuple(form.open_rows(opens[i])) if n_w else () for i in range(n_t)]  # lifted-off contacts
    t_in = np.asarray(t, float)[:n_t].reshape(n_t, 1)
    for lo in range(0, n_t, CHUNK):
        rows = slice(lo, min(lo + CHUNK, n_t))
        chunk = {name: x[rows] for name, x in state.items()}
        terms = post.evaluate(chunk, t_in[rows])
        if given_contacts is None:
            gaps[rows], contact_forces[rows] = terms["gap"], terms["fc"]
        else:
            gaps[rows], contact_forces[rows] = given_contacts[0][rows], given_contacts[1][rows]
        s_dot[rows] = terms["s_dot"]
        kin[rows], pot[rows] = terms["kinetic"][:, 0], terms["potential"][:, 0]
        closed = _closed_mask(model.n_c, open_rows[rows])
        pos[rows], vel[rows] = _max_abs(terms["C"], closed), _max_abs(terms["C_dot"], closed)
        wheel_gap[rows] = _wheel_gaps(model, q[rows], chunk["s"], terms["C"])
        if given is not None:
            a, lam[rows] = given[0][rows], given[1][rows]
        elif model.n_c:
            # Multipliers from the KKT system at each output (exact for the state, whatever
            # IDAS's tolerance on algebraic variables): the same for every formulation.
            a, lam[rows], creep_record[rows] = post.multipliers(chunk, terms, open_rows[rows])
            if n_w:
                normal[rows] = post.normal_forces(chunk, lam[rows])
        else:
            a = post.accelerations(terms)
        for i, a_i in zip(range(rows.start, rows.stop), a):
            acc[i, model.free] = form.to_physical(np.atleast_1d(a_i))
        for name, force in post.reactions(terms["Cq"], lam[rows]).items():
            reactions[name][rows] = force
    wall = time.perf_counter() - wall0
    stats = {**stats, "wall_s": wall, "steps": stats.get("nsteps", 0)}
    s, sc = state["s"], state["sc"]
    return SimulationResult(
        t_s=np.asarray(t), q=q, v=v, s_m=s, s_dot_m_s=s_dot, multipliers=lam, row_names=model.row_names,
        coordinate_names=model.coordinate_names(), reactions_N=reactions,
        energy_J={"kinetic": kin, "potential": pot, "total": kin + pot}, position_drift=pos, velocity_drift=vel,
        stats=stats, a=acc,
        contacts={ct.joint.name: {"s_m": sc[:, k], "gap_m": gaps[:, k], "force_N": contact_forces[:, k]}
                  for k, ct in enumerate(model.contacts)},
        wheelrail={e.joint.name: {"normal_force_N": normal[:, k], "s": s[:, e.s_index : e.s_index + 4],
                                  "gap_m": wheel_gap[:, k], "open": np.array([o[k] for o in opens], bool),
                                  **{f"{kind.replace('-', '_')}_s": np.array([ev.t_s for ev in events if ev.name == e.joint.name
                                                                              and ev.kind == kind]) for kind in ("lift-off", "touchdown")},
                                  **{name: creep_record[:, 6 * k + j] for j, name in
                                     enumerate(("xi_x", "xi_y", "phi_per_m", "fx_N", "fy_N", "mz_Nm"))}}
                   for k, e in enumerate(model.wheelrail)},
    )


def _stacked_state(form: Formulation, xs, zs) -> dict:
    """The integrator's outputs split as :func:`split_state` does, one row per output:
    ``q``, ``v``, ``s``, ``w`` (zero where the state has none) and ``sc``."""
    xb, zb = form.blocks()
    n_t = len(xs)
    x = np.asarray(xs, float).reshape(n_t, sum(b.size for b in xb.values()))
    z = np.asarray(zs, float).reshape(n_t, sum(b.size for b in zb.values()))
    out = {k: x[:, b.slice] for k, b in xb.items()}
    out.update({k: z[:, b.slice] for k, b in zb.items() if k not in out})
    sizes = {"q": form.n_f, "v": form.n_f, "s": form.n_s, "w": form.n_s, "sc": form.n_sc}
    return {k: out.get(k, np.zeros((n_t, n))) for k, n in sizes.items()}


def _physical(form: Formulation, y: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """All coordinates (fixed ones from ``fixed``) from the DAE's free ones, one row per output."""
    model = form.model
    out = np.tile(fixed, (y.shape[0], 1))
    for k, y_k in enumerate(y):
        out[k, model.free] = form.to_physical(y_k)
    return out


def _closed_mask(n_c: int, open_rows) -> np.ndarray:
    """(n, n_c) True on the closed constraint rows of each output."""
    mask = np.ones((len(open_rows), n_c), bool)
    for i, rows in enumerate(open_rows):
        mask[i, list(rows)] = False
    return mask


def _max_abs(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Max-norm of each row over its ``mask`` entries (zero if none)."""
    return np.where(mask, np.abs(values), 0.0).max(axis=1, initial=0.0)


def _wheel_gaps(model, q: np.ndarray, s: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Normal gap of every wheel/rail contact: the gap row of eq. 22 (railframe), else from the
    contact's geometry."""
    gaps = np.zeros((q.shape[0], len(model.wheelrail)))
    for k, e in enumerate(model.wheelrail):
        if e.joint.form == "railframe":
            gaps[:, k] = c[:, e.row_start + GAP_ROW]
        else:
            gaps[:, k] = [e.contact.gap(q_i[e.rows], s_i[e.s_index : e.s_index + 4]) for q_i, s_i in zip(q, s)]
    return gaps


class _PostTerms:
    """The per-output terms of a formulation (constraints, drifts, mass matrix, forces, energies;
    sparse matrices as their nonzeros) and what follows from them: multipliers, accelerations,
    creep records and joint reactions. The sparsity patterns are the same at every output, so
    the KKT matrices and reactions are assembled by index maps built once."""

    def __init__(self, form: Formulation, light: bool = False, contacts: bool = True, compiled: bool = False):
        from ..assembly.wheelrail import has_creep

        self.form = form
        model = form.model
        fn, self.patterns, self._terms = mapped_terms(form, light, contacts, compiled)
        self._names = fn.name_out()
        self.creep = Mapped(form.creep_function()) if has_creep(model) else None
        self._normal = Mapped(form.normal_direction_function()) if model.wheelrail else None
        self.normal_rows = form.normal_force_rows(full=True)  # the KKT multipliers have every row
        self._kkt = {}  # open rows -> KKTPattern
        self.reactions = _ReactionMap(model, self.patterns["Cq"])

    def evaluate(self, state: dict, t: np.ndarray) -> dict:
        """The terms (n, size) of the outputs of ``state`` (internal coordinates) at times ``t``."""
        out = self._terms(state["q"], state["v"], state["s"], state["w"], t, state["sc"])
        return dict(zip(self._names, out))

    def normal_directions(self, state: dict) -> np.ndarray:
        """(n, 3 n_w) weights of the normal forces in the multipliers (see
        :meth:`Formulation.normal_direction_function`)."""
        return self._normal(state["q"], state["s"])[0]

    def normal_forces(self, state: dict, lam: np.ndarray) -> np.ndarray:
        """(n, n_w) normal forces (N) for the multipliers ``lam`` (n, n_c) of ``state``."""
        return normal_forces_numeric(self.normal_directions(state), lam, self.normal_rows)

    def multipliers(self, state: dict, terms: dict, open_rows) -> tuple:
        """Accelerations (free, internal), multipliers (n, n_c) and creep records (n, 6 n_w) from
        the KKT system of every output (creep forces settled with the normal forces)."""
        solves = [self._solver(terms, i, rows) for i, rows in enumerate(open_rows)]
        n = len(solves)
        if self.creep is None:
            outs = [solve(f) for solve, f in zip(solves, terms["Q"])]
            lam = np.array([out[2] for out in outs]).reshape(n, self.form.n_c)
            return [out[0] for out in outs], lam, np.zeros((n, 6 * len(self.normal_rows)))
        args = (state["q"], state["v"], state["s"], terms["s_dot"])
        weights = self.normal_directions(state)
        outs = settle_creep(solves, terms["Q"], lambda normal: self.creep(*args, normal)[0],
                            lambda i, lam_i: normal_forces_numeric(weights[i], lam_i, self.normal_rows))
        lam = np.array([out[2] for out in outs]).reshape(n, self.form.n_c)
        return [out[0] for out in outs], lam, self.creep(*args, normal_forces_numeric(weights, lam, self.normal_rows))[1]

    def _solver(self, terms: dict, i: int, open_rows):
        """``solve(force)`` of output ``i``'s KKT system, its rows ``open_rows`` released."""
        if open_rows not in self._kkt:
            closed = np.setdiff1d(np.arange(self.form.model.n_c), open_rows)
            self._kkt[open_rows] = KKTPattern(self.patterns["M"], self.patterns["Cq"], self.patterns["Cs"], closed)
        pattern = self._kkt[open_rows]
        solve = pattern.solver(terms["M"][i], terms["Cq"][i], terms["Cs"][i])
        qd = terms["Qd"][i][pattern.closed]
        return lambda force: solve(force, qd)

    def accelerations(self, terms: dict) -> list:
        """Accelerations (free, internal) of unconstrained outputs: ``M a = Q``."""
        n_f = self.form.n_f
        if not n_f:
            return [np.zeros(0) for _ in terms["Q"]]
        colind, row = (np.asarray(x) for x in self.patterns["M"].get_ccs())
        return [spla.spsolve(sps.csc_matrix((m_nz, row, colind), shape=(n_f, n_f)), f)
                for m_nz, f in zip(terms["M"], terms["Q"])]


class _ReactionMap:
    """Constraint force on each joint's reporting body (:func:`_reporting_body`):
    ``-(C_q rows of the joint, columns of the body's first 3 coordinates)^T lambda``, from the
    nonzeros of ``C_q`` (free columns, pattern ``cq``) by index maps built once."""

    def __init__(self, model, cq: ca.Sparsity):
        self.names = list(dict.fromkeys(n.split("[")[0] for n in model.row_names))
        slots = {}  # (joint, coordinate) -> (position in the (n_joint, 3) output, sign)
        for j, name in enumerate(self.names):
            body = _reporting_body(model, name)
            if body is not None:
                sign, ref = body
                slots.update({(j, col): (3 * j + axis, sign) for axis, col in enumerate(_first3(model, ref))})
        position = {name: j for j, name in enumerate(self.names)}
        joint_of_row = [position[n.split("[")[0]] for n in model.row_names]
        rows, cols = cq.get_triplet()
        hits = [(e, r, slots[joint_of_row[r], model.free[c]]) for e, (r, c) in enumerate(zip(rows, cols))
                if (joint_of_row[r], model.free[c]) in slots]
        self._nz = np.array([e for e, _, _ in hits], int)
        self._rows = np.array([r for _, r, _ in hits], int)
        self._select = np.zeros((len(hits), 3 * len(self.names)))
        for h, (_, _, (slot, sign)) in enumerate(hits):
            self._select[h, slot] = -sign

    def __call__(self, cq_nz: np.ndarray, lam: np.ndarray) -> dict:
        """Joint name -> (n, 3) forces for the nonzeros ``cq_nz`` (n, nnz) and multipliers ``lam``
        (n, n_c) of n states."""
        forces = (cq_nz[:, self._nz] * lam[:, self._rows]) @ self._select
        return {name: forces[:, 3 * j : 3 * j + 3] for j, name in enumerate(self.names)}


def joint_reactions(model, cq_free, lam) -> dict:
    """Joint reactions of one state (see :class:`SimulationResult`).

    Parameters
    ----------
    model : MultibodyModel
    cq_free : ndarray (n_c, n_f)
        Dense constraint Jacobian in the free coordinates.
    lam : ndarray (n_c,)
        Multipliers.

    Returns
    -------
    dict
        Joint name -> (3,) force (N).
    """
    cq_free = np.asarray(cq_free)
    # its nonzeros only (in CCS order): on a line the dense Jacobian has hundreds of thousands
    rows, cols = np.nonzero(cq_free)
    order = np.lexsort((rows, cols))
    rows, cols = rows[order], cols[order]
    reaction_map = _ReactionMap(model, ca.Sparsity.triplet(*cq_free.shape, rows.tolist(), cols.tolist()))
    forces = reaction_map(cq_free[rows, cols][None, :], np.asarray(lam)[None, :])
    return {name: force[0] for name, force in forces.items()}


def _reporting_body(model, name):
    """``(sign, body)``: the force on the joint is ``sign`` times that on ``body`` -- ``body`` of
    sliding and driving joints, ``body_j`` of two-body joints, or minus the force on ``body_i``
    for joints to the ground; None for rows of no joint (Euler-parameter normalization)."""
    joint = next((j for j in model.scene.joints if j.name == name), None)
    if joint is None:
        return None
    ref = getattr(joint, "body", None) or joint.body_j
    if ref == "ground":
        return -1.0, joint.body_i
    return 1.0, ref


def _first3(model, ref):
    if isinstance(ref, tuple):
        body = model.scene.find(ref[0])
        return model.ancf.dofs.node_indices(body, ref[1])[:3]
    start = model.rigid_offset[ref]
    return np.arange(start, start + 3)
