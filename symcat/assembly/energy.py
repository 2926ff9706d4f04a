"""Mechanical energy of a multibody model and the power of what is not conservative in it: the
two sides of a run's energy balance.

The energy is ``E = T + V``: the kinetic energy and a potential ``V`` of every force that has one
here: the wires' strain energy, gravity and the constant loads (:meth:`MultibodyModel.potential_energy`),
the springs of :class:`~symcat.scene.SpringDamper` elements (``k e^2 / 2 + k3 e^4 / 4`` of the
stretch ``e``; tension-only ones while stretched), the constant part ``F0`` of point loads
(``-F0 . r``) and the penalty springs of wire contacts (the integral of their smoothed law over
the penetration). Over a run, ``E(t) - E(0)`` equals the
work of the rest: the power

``P = v . (Q_e + grad V_e) - v^T C v + lambda . C_t``

summed over the force elements whose force is not the gradient of their potential here (dampers,
time-varying loads and torques, rotational springs and bushings, contacts), then Rayleigh
damping, then the work of the constraint forces, which only rheonomic constraints (prescribed
motions: a train's speed) do: ``-v . C_q^T lambda = lambda . (C_s s_dot + C_t)``, and
``C_s^T lambda = 0`` (a sliding joint is frictionless). A conservative element costs nothing
per step; what an integrator gains or loses is ``E(t) - E(0) - int P dt``.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ..codegen.library import BufferedFunction, kernel_library, library_interface
from .multibody import _gather
from .sparse import to_scipy


def _points(kind: str, y: ca.MX, u: np.ndarray) -> ca.MX:
    """Global positions (3 x m) of the body points ``u`` (3 x m: body frame; ground: global)
    of ``m`` sides whose coordinates are the columns of ``y`` (as the kernels: a node's point
    is offset from its position, a rigid body's turns with its Euler parameters)."""
    u_dm = ca.DM(u)
    if kind == "ground":
        return u_dm
    if kind == "node":
        return y[0:3, :] + u_dm
    e0, e = y[3, :], y[4:7, :]
    e_dot_u = ca.repmat(ca.sum1(e * u_dm), 3, 1)
    cross = ca.vertcat(e[1, :] * u_dm[2, :] - e[2, :] * u_dm[1, :], e[2, :] * u_dm[0, :] - e[0, :] * u_dm[2, :],
                       e[0, :] * u_dm[1, :] - e[1, :] * u_dm[0, :])
    return y[0:3, :] + ca.repmat(2 * e0**2 - 1, 3, 1) * u_dm + 2 * (e * e_dot_u + ca.repmat(e0, 3, 1) * cross)


_SIZES = {"ground": 0, "node": 3, "rigid": 7}


def _group_potentials(library: str, y: ca.MX, par: dict) -> ca.MX | None:
    """Potentials (J, 1 x m) of ``m`` force elements of ``library`` at their coordinates ``y``
    (columns) with parameters ``par`` (name -> 1 x m values); None where they have none here
    (their whole power is then counted as work)."""
    def vec(name):
        return np.vstack([par[f"{name}_{k}"] for k in range(3)])

    if library.startswith("springdamper_"):
        ka, kb = library.split("_")[1:3]
        n_a = _SIZES[ka]
        d = _points(kb, y[n_a:, :], vec("uj")) - _points(ka, y[:n_a, :], vec("ui"))
        e = ca.sqrt(ca.sum1(d**2)) - ca.DM(par["l0"]).T
        slack = ca.DM((par["tension_only"] > 0.5).astype(float)).T
        e = slack * ca.fmax(e, 0.0) + (1 - slack) * e
        return 0.5 * ca.DM(par["k"]).T * e**2 + 0.25 * ca.DM(par["k3"]).T * e**4
    if library == "pointload_rigid":
        return -ca.sum1(ca.DM(vec("F0")) * _points("rigid", y, vec("ui")))
    return None


def _conservative(library: str, par: dict) -> np.ndarray:
    """Which elements' forces are exactly minus the gradient of :func:`_group_potentials`."""
    m = len(next(iter(par.values())))
    if library.startswith("springdamper_"):
        return par["c"] == 0.0
    if library == "pointload_rigid":
        return np.all([par[f"{n}_{k}"] == 0.0 for n in ("F1", "T0", "T1") for k in range(3)], axis=0)
    return np.zeros(m, bool)


def penalty_law(pen, k, delta) -> tuple[np.ndarray, np.ndarray]:
    """Potential (J) and force (N) of the smoothed penalty law of the contact kernels without
    damping, ``f = ramp(k ramp(p, delta), k delta)`` (:func:`symcat.codegen.multibody_kernels._ramp`),
    at the penetrations ``p`` (m): ``f = k p^4 / (8 delta^3)`` up to ``delta``,
    ``k (p - delta/2)^2 / (2 delta)`` up to ``3 delta / 2``, ``k (p - delta)`` beyond."""
    potential, force = np.vectorize(_penalty_scalar, otypes=[float, float])(pen, k, delta)
    return potential, force


def _contact_terms(library: str) -> BufferedFunction:
    """``(y, y_dot, p) -> (Q . y_dot, gap, d penetration / dt)`` of a contact kernel on one
    element and body: the contact point moves along the wire as the tangency ``T(y) = 0``
    holds it (``s_dot = -T_y y_dot / T_s``); the penetration's rate is a central difference of
    the gap along ``[y_dot, s_dot]`` (exact to round-off for the energy balance, and a tenth of
    the cost of the kernel's Jacobian, most of which is the generalized force's)."""
    lib = kernel_library(library)
    tangency_fn, force_fn = lib[f"{library}_tangency"], lib[f"{library}_force"]
    n_y = tangency_fn.size1_in(0)
    y, y_dot, p = ca.MX.sym("y", n_y), ca.MX.sym("y_dot", n_y - 1), ca.MX.sym("p", tangency_fn.size1_in(1))
    q_loc, gap, _ = force_fn(y, y_dot, p)
    t_y = ca.jacobian(tangency_fn(y, p), y)
    s_dot = -ca.mtimes(t_y[:, : n_y - 1], y_dot) / t_y[:, n_y - 1]
    w = ca.vertcat(y_dot, s_dot)
    eps = 1e-7 / ca.fmax(ca.norm_inf(w), 1e-12)  # moves the point by 1e-7 m at most
    gap_rate = (force_fn(y + eps * w, y_dot, p)[1] - force_fn(y - eps * w, y_dot, p)[1]) / (2 * eps)
    return BufferedFunction(ca.Function(f"{library}_energy_terms", [y, y_dot, p],
                                        [ca.dot(q_loc, y_dot), gap, -gap_rate]))


class _ContactEnergy:
    """The penalty contacts' potential and the power of their non-conservative part (damping,
    and the normal held fixed in their generalized force), each contact evaluated on the
    element that holds its point: the element windows of the model's graphs follow the
    integrator, not this."""

    def __init__(self, model):
        self.contacts = []
        built = {}
        for ct in model.contacts:
            if ct.library not in built:
                built[ct.library] = _contact_terms(ct.library)
            names = list(library_interface(ct.library)["params"])
            self.contacts.append((ct, np.array(model._rigid_indices(ct.body.name)), built[ct.library],
                                  ct.params[names.index("k")], ct.params[names.index("delta")]))

    def _evaluated(self, q, v, sc):
        """Per contact on its wire at some of the states of the rows of ``q``, ``v`` and
        ``sc``: ``(on, q_v, gap, penetration rate, k, delta)``, ``on`` the states where it is
        (off its wire a contact has no force, as in ``contact_terms``), its terms evaluated
        for all of them in one call."""
        for i, (ct, rigid, terms, k, delta) in enumerate(self.contacts):
            starts, s = np.asarray(ct.element_start), sc[:, i]
            on = (starts[0] <= s) & (s <= starts[-1])
            if not on.any():
                continue
            e = np.clip(np.searchsorted(starts, s[on], side="right") - 1, 0, len(starts) - 2)
            rows = np.asarray(ct.element_indices)[e]  # (states on, n_local)
            q_on, v_on = q[on], v[on]
            y = np.concatenate((np.take_along_axis(q_on, rows, 1), q_on[:, rigid], (s[on] - starts[e])[:, None]), 1)
            y_dot = np.concatenate((np.take_along_axis(v_on, rows, 1), v_on[:, rigid]), 1)
            p = np.tile(ct.params, (len(e), 1))
            p[:, 0] = starts[e + 1] - starts[e]
            yield (on, *_mapped(terms, len(e)).nonzeros(y.ravel(), y_dot.ravel(), p.ravel()), k, delta)

    def powers(self, q, v, sc) -> np.ndarray:
        """The non-conservative power (W) of all contacts at the states of the rows of ``q``,
        ``v`` and ``sc`` (the states after several steps)."""
        power = np.zeros(len(q))
        for on, q_v, gap, pen_dot, k, delta in self._evaluated(q, v, sc):
            power[on] += q_v + penalty_law(-gap, k, delta)[1] * pen_dot
        return power

    def potential(self, q, v, sc) -> float:
        """The potential (J) of all contacts at the state ``(q, v, sc)``."""
        return float(sum(penalty_law(-gap, k, delta)[0].sum()
                         for _, _, gap, _, k, delta in self._evaluated(q[None], v[None], np.asarray(sc)[None])))


_MAPPED: dict = {}


def _mapped(fn: BufferedFunction, k: int) -> BufferedFunction:
    """``fn`` mapped over ``k`` columns (kept per function and ``k``)."""
    key = (id(fn), k)
    if key not in _MAPPED:
        _MAPPED[key] = (fn, BufferedFunction(fn.function.map(k)))  # (fn kept: its id stays its own)
    return _MAPPED[key][1]


def _penalty_scalar(u: float, k: float, d: float) -> tuple[float, float]:
    """:func:`penalty_law` of one penetration, in plain Python (the per-step path, where NumPy's
    overhead would be the cost)."""
    if u <= 0:
        return 0.0, 0.0
    if u < d:
        return k * u**5 / (40 * d**3), k * u**4 / (8 * d**3)
    if u < 1.5 * d:
        return k * d**2 / 40 + k / (6 * d) * ((u - d / 2) ** 3 - (d / 2) ** 3), k * (u - d / 2) ** 2 / (2 * d)
    return k * d**2 / 40 + 7 * k * d**2 / 48 + k * (u - d) ** 2 / 2 - k * d**2 / 8, k * (u - d)


class EnergyTerms:
    """Energy and non-conservative power of a :class:`~symcat.assembly.multibody.MultibodyModel`
    (module docstring), as compiled-graph CasADi functions of the physical state.

    Parameters
    ----------
    model : MultibodyModel
    """

    def __init__(self, model):
        self.model = model
        n_q, n_sc, n_a = model.n_q, len(model.contacts), model.ancf.n
        q, v = ca.MX.sym("q", n_q), ca.MX.sym("v", n_q)
        t = ca.MX.sym("t")
        potential = model.potential_energy(q)
        power = ca.MX(0)
        for lib, group in model.force_groups.items():
            rows, values = np.array(group.rows), np.array(group.params, float)
            par = dict(zip(library_interface(lib)["params"], values.T))
            v_pot = _group_potentials(lib, _gather(q, rows), par)
            work = ~_conservative(lib, par)
            if v_pot is not None:
                potential += ca.sum2(v_pot)
                if work.any():  # the element's power minus the rate of its potential
                    power += ca.jtimes(ca.sum2(v_pot[:, np.flatnonzero(work).tolist()]), q, v)
            if work.any():
                w_rows = rows[work]
                fn = kernel_library(lib)[lib].map(len(w_rows))
                out = fn(_gather(q, w_rows), _gather(v, w_rows), t, ca.DM(values[work].T))
                power += ca.dot(ca.vec(out), v[w_rows.ravel().tolist()])
        if n_a and any(es.damped for es in model.ancf.element_sets):
            f_v = model.ancf.force_function()(q[:n_a], v[:n_a]) - model.ancf.force_function()(q[:n_a], ca.MX.zeros(n_a))
            power += ca.dot(f_v, v[:n_a])
        self._contacts = _ContactEnergy(model) if n_sc else None
        # evaluated in place on NumPy memory: a DM conversion of a line's state costs more
        self._energy = BufferedFunction(ca.Function("energy", [q, v], [model.kinetic_energy(q, v), potential]))
        self._power = BufferedFunction(ca.Function("power_nonconservative", [q, v, t], [power]))
        c = model.ancf.rayleigh_matrix
        self._rayleigh = None
        if c is not None:
            # v^T C v of the symmetric C from its strict upper triangle and diagonal: half the
            # sparse product of a line's length at every step
            full = to_scipy(model._rayleigh_dm()).tocsr()
            self._rayleigh = (sps.triu(full, k=1, format="csr"), full.diagonal())
        # the rheonomic constraints' rows (prescribed motions): lambda . C_t
        self._ct = self._constraint_rates(model, q, t)

    @staticmethod
    def _constraint_rates(model, q, t):
        """``C_t`` of the constraint groups (the first rows; the sliding joints and wheel/rail
        contacts that follow them are scleronomic) as a function of ``(q, t)``."""
        parts = []
        for lib, group in model.groups.items():
            rows = np.array(group.rows)
            p = ca.DM(np.array(group.params).T)
            c_t = kernel_library(lib)[f"{lib}_jac"].map(len(rows))(_gather(q, rows), t, p)[1]
            parts.append(ca.vec(c_t))
        if not parts:
            return None
        return BufferedFunction(ca.Function("constraint_rates", [q, t], [ca.densify(ca.vertcat(*parts))]))

    def energy(self, q: np.ndarray, v: np.ndarray, sc: np.ndarray | None = None) -> tuple[float, float]:
        """Kinetic and potential energy (J) at coordinates ``q`` and velocities ``v`` (all of
        the model's, ``model.coordinate_names()``) and contact arc lengths ``sc`` (m)."""
        sc = np.zeros(0) if sc is None else sc
        kinetic, potential = self._energy.nonzeros(q, v)
        contact = self._contacts.potential(q, v, sc) if self._contacts is not None else 0.0
        return float(kinetic[0]), float(potential[0]) + contact

    def power(self, q: np.ndarray, v: np.ndarray, sc: np.ndarray | None, multipliers: np.ndarray,
              t: float) -> tuple[float, float]:
        """The work rates (W) at the state ``(q, v, sc)``, multipliers ``multipliers`` (the
        model's constraint rows) and time ``t``: of the constraint forces (the prescribed
        motions' driving) and of the non-conservative forces (dampers, time-varying loads,
        Rayleigh damping; <= 0 when they only dissipate)."""
        sc = np.zeros(0) if sc is None else np.asarray(sc)
        driving, other = self.powers(q[None], v[None], sc[None], np.asarray(multipliers)[None], np.array([t]))
        return float(driving[0]), float(other[0])

    def powers(self, q: np.ndarray, v: np.ndarray, sc: np.ndarray, multipliers: np.ndarray,
               t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`power` at several states (a monitor's, after consecutive steps): each
        argument's first axis the states (``t`` (k,)); the two work rates (W), (k,) each."""
        k = len(t)
        other = np.array([self._power.nonzeros(q[i], v[i], t[i])[0][0] for i in range(k)])
        if self._contacts is not None:
            other += self._contacts.powers(q, v, sc)
        if self._rayleigh is not None:  # v C v of each state: one product for all
            upper, diagonal = self._rayleigh
            other -= 2.0 * np.einsum("ij,ji->i", v, upper @ v.T) + np.einsum("ij,ij->i", v * diagonal, v)
        driving = np.zeros(k)
        if self._ct is not None:
            for i in range(k):
                c_t = self._ct.nonzeros(q[i], t[i])[0]
                driving[i] = np.asarray(multipliers[i])[: c_t.size] @ c_t
        return driving, other


def balance(t: np.ndarray, driving_W: np.ndarray, other_W: np.ndarray, t_energy: np.ndarray,
            energy_J: np.ndarray) -> dict[str, np.ndarray]:
    """The energy balance of a run: the energy (J) at ``t_energy`` against its start plus the
    work since then (trapezoidal rule over the steps ``t`` of the powers, W). ``error_J`` is
    what the time integration gained (> 0) or lost; ``work_scale_J`` the work of the
    constraint forces in absolute value, the scale of the balance."""
    t = np.asarray(t, float)
    net = np.asarray(driving_W) + np.asarray(other_W)
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (net[1:] + net[:-1]) * np.diff(t))])
    expected = energy_J[0] + np.interp(t_energy, t, cumulative)
    drive = np.abs(np.asarray(driving_W))
    work = float(np.sum(0.5 * (drive[1:] + drive[:-1]) * np.diff(t)))
    return {"t_s": np.asarray(t_energy), "energy_J": np.asarray(energy_J), "expected_J": expected,
            "error_J": np.asarray(energy_J) - expected, "work_scale_J": work}
