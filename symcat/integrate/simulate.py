"""Integrate a multibody model with CasADi's IDAS.

The run is split into chunks of output points (progress, window moves of sliding joints);
each chunk continues from the previous state (wheel/rail models: shorter calls with contact
checks between them, :mod:`.contact_stepping`). Accelerations and multipliers are algebraic and
kept out of the error test (``suppress_algebraic``): on stiff ANCF models this cuts the step
count by two orders of magnitude. A failure raises :class:`SolverError` with the time, IDAS's
reason, the largest residual by name and the result up to the last completed chunk.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
import scipy.sparse.linalg as spla

from ..assembly.multibody import MultibodyModel
from ..assembly.wheelrail import GAP_ROW
from ..dae.formulation import Formulation
from ..assembly.sparse import to_scipy
from ..dae.initial import CreepCoupling, consistent_state, kkt_solve
from ..errors import ParameterError, SolverError
from ..progress import Progress
from .contact_switching import initial_open
from .contact_stepping import CallFailed, ContactStepper
from .failure import failure, split_state

STAT_KEYS = ("nsteps", "nfevals", "nlinsetups", "netfails", "nniters", "nncfails")


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


def simulate(model: MultibodyModel, t_end: float, formulation: str = "augmented", index: str = "1",
             rtol: float = 1e-6, atol: float = 1e-8, n_out: int = 200, baumgarte: float = 10.0,
             chunks: int | None = None, max_step: float | None = None, progress: bool = True,
             algebraic_atol: float = 1e-3, max_steps: int = 500000, cholesky: bool = False,
             linear_solver: str | None = None) -> SimulationResult:
    """Simulate ``model`` from 0 to ``t_end`` seconds.

    Parameters
    ----------
    model : MultibodyModel
    t_end : float
        Simulated time (s), > 0.
    formulation, index : str
        ``augmented``/``embedded`` and ``1``/``ggl`` (see :mod:`symcat.dae.formulation`).
    rtol, atol : float
        IDAS tolerances (differential states only). ``atol`` may also be an array over all
        generalized coordinates (``model.coordinate_names()``), used for the coordinates and
        their velocities (e.g. looser on the stiff cross-section gradients of a thin beam).
    n_out : int
        Output intervals.
    baumgarte : float
        Stabilization (1/s) of the index-1 forms.
    chunks : int, optional
        Integrator calls the run is split into (default: adaptive, about 10, shorter while a
        sliding point would otherwise leave its element window).
    max_step : float, optional
        Largest IDAS step (s).
    algebraic_atol : float
        Absolute tolerance of the algebraic variables in IDAS's Newton test (they are not
        error-controlled).
    max_steps : int
        IDAS steps allowed per chunk (wheel/rail models: per call, at most
        :data:`~symcat.integrate.contact_stepping.MAX_CALL_STEPS`).
    cholesky : bool
        Cholesky coordinates for the ANCF bodies (see :class:`symcat.dae.Formulation`).
    linear_solver : str
        CasADi linear solver plugin for IDAS's Newton systems: ``csparse`` (sparse LU, 1.6x
        faster than CasADi's default ``qr`` on a 32-element wire, see the benchmark), ``qr``
        (sparse QR) or ``lapacklu`` (dense LU). Default: ``csparse`` at index 1, ``qr`` for GGL,
        whose ill-conditioned index-2 matrices make the LU's pivoting fail (IDA_LSETUP_FAIL).
    """
    if not t_end > 0:
        raise ParameterError(f"t_end={t_end}: must be > 0 s")
    if not 0 < rtol < 1:
        raise ParameterError(f"rtol={rtol}: must be in (0, 1)")
    wall0 = time.perf_counter()
    form = Formulation(model, formulation, index, baumgarte, cholesky)
    if linear_solver is None:
        linear_solver = "csparse" if form.index == "1" else "qr"
    open_flags = initial_open(form) if model.wheelrail else np.zeros(0)
    x, z = consistent_state(form, 0.0, open_rows=form.open_rows(open_flags))
    t_grid = np.linspace(0.0, t_end, n_out + 1)
    fixed_edges = None
    if chunks:
        fixed_edges = np.unique(np.linspace(0, n_out, int(chunks) + 1).astype(int))
    # Algebraic variables (accelerations, multipliers) are out of the error test, but their
    # absolute tolerance still weighs IDAS's Newton convergence test: with the differential
    # atol, GGL's mu (identically ~0) can never "converge" and IDAS reports IDA_CONV_FAIL.
    n_z = len(z)
    opts = {"reltol": rtol, "abstolv": _atol_vector(form, atol) + [algebraic_atol] * n_z, "suppress_algebraic": True,
            "calc_ic": False, "max_num_steps": int(max_steps), "linear_solver": linear_solver}
    if max_step:
        opts["max_step_size"] = max_step
    xs, zs = [x], [z]
    opens = [open_flags.copy()]  # wheel/rail contacts lifted off, at each output
    events = []                  # their lift-offs and touchdowns (contact_switching.Switch)
    stats = dict.fromkeys(STAT_KEYS, 0)
    stats["restarts"] = 0
    bar = Progress("simulate", t_end, "s", enabled=progress)
    dae_fn = None
    done = 0

    def call(x, z, t_a, times):
        """One IDAS call from ``t_a`` with outputs at ``times``: (x, z) columns per output."""
        # IDAS needs a consistent x_dot at every (re)start; it would otherwise assume zero.
        x_dot = np.asarray(dae_fn(0.0, x, z, t_a, ca.DM(0, 1))[0]).ravel()
        grid = (np.atleast_1d(times) - t_a).tolist()
        integ = ca.integrator("idas", "idas", dae_fn, 0.0, grid, {**opts, "init_xdot": x_dot.tolist()})
        out = integ(x0=x, z0=z, p=t_a)
        st = integ.stats()
        for k in STAT_KEYS:
            stats[k] += int(st.get(k, 0))
        return np.asarray(out["xf"]), np.asarray(out["zf"])

    def dae_function():
        d = form.dae()
        # One Function per window: integrators built from it share its cached Jacobian.
        return ca.Function("dae", [d["t"], d["x"], d["z"], d["p"], ca.MX.sym("u", 0)],
                           [d["ode"], d["alg"], ca.MX(0, 1), ca.MX(0, 1)], ca.dyn_in(), ca.dyn_out())

    try:
        if model.wheelrail:
            # Short calls with contact checks between them (see contact_stepping).
            dae_fn = dae_function()
            stepper = ContactStepper(form, dae_fn, opts, x, z, stats, STAT_KEYS, open_flags)
            events = stepper.switching.events
            for a in range(n_out):
                if _update_windows(model, form, x, z):
                    stats["restarts"] += 1
                    stepper.set_dae(dae_function())
                try:
                    x, z = stepper.advance(x, z, t_grid[a], t_grid[a + 1])
                except CallFailed as exc:
                    raise failure(form, exc.error, exc.t, exc.x, exc.z, stepper.dae_fn, t_grid[a + 1] - exc.t,
                                  stepper.switching.open) from None
                xs.append(x)
                zs.append(z)
                opens.append(stepper.switching.open.copy())
                done = a + 1
                bar.update(t_grid[a + 1])
        a, limit = (n_out if model.wheelrail else 0), None
        while a < n_out:
            b = _chunk_end(model, form, x, z, a, n_out, t_grid, fixed_edges)
            if limit is not None:
                b = min(b, a + limit)
            if _update_windows(model, form, x, z) or dae_fn is None:
                stats["restarts"] += dae_fn is not None
                dae_fn = dae_function()
            try:
                xf, zf = call(x, z, t_grid[a], t_grid[a + 1 : b + 1])
            except RuntimeError as exc:
                if b - a > 1 and model.windowed():
                    # Possibly a sliding point left its window: retry shorter before giving up.
                    stats["retries"] = stats.get("retries", 0) + 1
                    limit = max(1, (b - a) // 2)
                    continue
                raise failure(form, exc, t_grid[a], x, z, dae_fn, t_grid[a + 1] - t_grid[a]) from None
            if b - a > 1 and any(_left_window(model, form, xf[:, j], zf[:, j]) for j in range(b - a)):
                # A sliding point ran out of its window inside the call (the physics there would
                # be an extrapolated element): redo the call, shorter, from the same state.
                stats["retries"] = stats.get("retries", 0) + 1
                limit = max(1, (b - a) // 2)
                continue
            limit = None
            for j in range(b - a):
                xs.append(xf[:, j])
                zs.append(zf[:, j])
            x, z = xf[:, -1], zf[:, -1]
            done = b
            bar.update(t_grid[b])
            a = b
    except SolverError as err:
        bar.close()
        err.partial = _result(form, t_grid[: done + 1], xs, zs, stats, wall0, opens, events)
        raise
    bar.close()
    return _result(form, t_grid, xs, zs, stats, wall0, opens, events)


def _atol_vector(form, atol) -> list:
    """Absolute tolerances of the differential states from a scalar or a per-coordinate array."""
    xb, _ = form.blocks()
    n_x = sum(b.size for b in xb.values())
    per = np.atleast_1d(np.asarray(atol, dtype=float))
    if per.size == 1:
        return [float(per[0])] * n_x
    if per.size != form.model.n_q:
        raise ParameterError(f"atol: give a number or {form.model.n_q} values (one per coordinate), not {per.size}")
    free = per[form.model.free] if not form.cholesky else np.full(form.n_f, per.min())
    out = np.full(n_x, per.min())
    for name in ("q", "v"):
        out[xb[name].slice] = free
    return out.tolist()


def _chunk_end(model, form, x, z, a, n_out, t_grid, fixed_edges) -> int:
    """End (output index) of the next integrator call: about 10 % of the run for progress, and
    short enough that no sliding point travels more than a quarter of its window (the window
    is only moved between calls). Each call builds an integrator and restarts IDAS at order 1,
    so fewer calls are faster."""
    if fixed_edges is not None:
        return int(fixed_edges[np.searchsorted(fixed_edges, a, side="right")])
    dt = t_grid[1] - t_grid[0]
    span = max(1, int(round(0.1 * n_out)))
    if model.windowed():
        s_dot = np.abs(_s_dot(form, x, z))
        for sl, v in zip(model.windowed(), s_dot):
            lo, hi = sl.window
            if lo == 0 and hi == len(sl.element_start) - 1:
                continue  # the window is the whole wire
            reach = 0.25 * (sl.element_start[hi] - sl.element_start[lo])
            if v > 0:
                span = min(span, max(1, int(reach / (v * dt))))
    return min(n_out, a + span)


def _left_window(model, form, x, z) -> bool:
    """True if a sliding point lies outside its window (wire ends excepted)."""
    if not model.windowed():
        return False
    s = _window_s(form, x, z)
    for sl, s_k in zip(model.windowed(), s):
        lo, hi = sl.window
        n_el = len(sl.element_start) - 1
        if (lo > 0 and s_k < sl.element_start[lo]) or (hi < n_el and s_k > sl.element_start[hi]):
            return True
    return False


def _s_dot(form, x, z) -> np.ndarray:
    """Rates of the windowed arc lengths (sliding joints, then contacts)."""
    parts = split_state(form, x, z)
    # Algebraic arc lengths (embedded form, contacts): the largest velocity bounds s_dot well enough here.
    bound = np.abs(parts["v"]).max(initial=0.0)
    n = form.model.n_sliding  # wheel/rail surface parameters have no window
    sliding = parts["w"][:n] if "w" in parts else np.full(n, bound)
    return np.r_[sliding, np.full(form.n_sc, bound)]


def _window_s(form, x, z) -> np.ndarray:
    """Arc lengths of the sliding joints, then of the contacts."""
    parts = split_state(form, x, z)
    return np.r_[parts["s"][: form.model.n_sliding], parts.get("sc", np.zeros(0))]


def _update_windows(model, form, x, z) -> bool:
    if not model.windowed():
        return False
    s = _window_s(form, x, z)
    if model.window_margin(s) >= 2:
        return False
    moved = False
    for sl, s_k in zip(model.windowed(), s):
        moved |= model.set_window(sl, s_k)
    return moved


def _result(form: Formulation, t, xs, zs, stats, wall0, opens, events) -> SimulationResult:
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

            def kkt(f):
                a_k, s_dd, lam_closed = kkt_solve(mass_i, f, cq_i, cs_i, qd_i)
                lam_k = np.zeros(model.n_c)
                lam_k[closed] = lam_closed  # lifted-off contacts carry no force
                return a_k, s_dd, lam_k

            a_i, _, lam[i] = creep.solve(kkt, np.asarray(force).ravel())
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
