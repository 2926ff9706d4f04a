"""Semi-explicit DAEs for IDAS from an assembled :class:`MultibodyModel`.

Notation: ``q`` free generalized coordinates (fixed ANCF coordinates are eliminated), ``v`` their
velocities, ``s`` the arc-length parameters, ``M a + C_q^T lambda = Q`` the dynamics.

augmented, index 1 (seed eq. 25)
    x = [q, s, v, w], z = [a, s_dd, lambda];  q' = v, s' = w, v' = a, w' = s_dd;
    0 = M a + C_q^T lambda - Q,  0 = C_s^T lambda,
    0 = C_q a + C_s s_dd + Q_d + 2 alpha C_dot + beta^2 C   (Baumgarte).
augmented, GGL (stabilized index 2)
    x = [q, s, v], z = [a, w, lambda, mu];  q' = v + C_q^T mu, s' = w + C_s^T mu, v' = a;
    0 = M a + C_q^T lambda - Q,  0 = C_s^T lambda,  0 = C,  0 = C_q v + C_s w + C_t.
embedded, index 1 (seed eq. 26)
    The first (tangency) row ``C_T`` of every sliding joint is kept as the algebraic equation
    that defines ``s(q)`` (``s`` becomes algebraic); the other rows ``C_R`` get the Jacobian
    ``H = C_Rq - C_Rs C_Ts^-1 C_Tq`` and ``Q_cn = Q_dR - C_Rs C_Ts^-1 Q_dT`` with
    ``s' = -C_Ts^-1 C_Tq v``: x = [q, v], z = [a, s, lambda_n];
    0 = M a + H^T lambda_n - Q,  0 = C_T,  0 = H a + Q_cn + 2 alpha C_R' + beta^2 C_R.
embedded, GGL
    x = [q, v], z = [a, s, lambda_n, mu];  q' = v + H^T mu;
    0 = M a + H^T lambda_n - Q,  0 = C_T,  0 = C_R,  0 = H v + C_Rt.

Penalty contacts (:class:`symcat.scene.PenaltyContact`) add, in every form, algebraic arc lengths
``s_c`` (z block ``sc``) with the tangency equations ``0 = T(q, s_c)`` (no multiplier, seed
Section 8) and their normal forces to ``Q``.

Wheel/rail contacts in the rail-frame form (eq. 22) may be *open* (lifted off): the DAE's
parameter is ``p = [t0, open]`` with ``open`` 0 or 1 per wheel/rail contact, and an open
contact's gap row (position, velocity or acceleration level) is replaced by its multiplier
(``lambda = 0``, in GGL also ``mu = 0``): the surface parameters still follow the closest point
(the four other rows), and the gap is free. :mod:`symcat.wheelrail_events.contact_switching` opens and
closes them.

Creep forces depend on the normal forces, linear in the multipliers
(:meth:`Formulation.normal_forces`: minus the gap row's multiplier in the rail-frame form, minus
the three coincidence rows' multipliers projected on the rail normal in the global form).

Accelerations and multipliers are algebraic; the driver keeps them out of IDAS's error test.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ..assembly.contact import contact_terms
from ..assembly.multibody import MultibodyModel
from ..assembly.sparse import to_casadi_sparse
from ..assembly.wheelrail import GAP_ROW, creep_terms, has_creep, normal_directions
from ..errors import ParameterError

FORMULATIONS = ("augmented", "embedded")
INDICES = ("1", "ggl")


@dataclass
class Block:
    name: str
    start: int
    size: int

    @property
    def slice(self) -> slice:
        return slice(self.start, self.start + self.size)


class Formulation:
    """One DAE form of a multibody model.

    Parameters
    ----------
    model : MultibodyModel
    formulation : {"augmented", "embedded"}
    index : {"1", "ggl"}
    baumgarte : float
        Baumgarte parameter (1/s) of the index-1 forms: ``alpha = beta = baumgarte``.
    cholesky : bool
        Use Cholesky coordinates ``p = U e`` for the free ANCF coordinates (seed, Section 5):
        their mass matrix becomes the identity, at the price of ``U^-1``, which is dense, in
        every Jacobian (see the benchmark for whether it pays).
    """

    def __init__(self, model: MultibodyModel, formulation: str = "augmented", index: str = "1", baumgarte: float = 10.0,
                 cholesky: bool = False):
        if formulation not in FORMULATIONS:
            raise ParameterError(f"formulation={formulation!r}: must be one of {', '.join(FORMULATIONS)}")
        if str(index) not in INDICES:
            raise ParameterError(f"index={index!r}: must be one of {', '.join(INDICES)}")
        self.model = model
        self.formulation = formulation
        self.index = str(index)
        self.baumgarte = float(baumgarte)
        n_q = model.n_q
        self.n_f = len(model.free)
        p = sps.csc_matrix((np.ones(self.n_f), (model.free, np.arange(self.n_f))), shape=(n_q, self.n_f))
        self.cholesky = bool(cholesky)
        self._transform = None
        if self.cholesky:
            p = p @ self._cholesky_transform()
        self.P = ca.DM(to_casadi_sparse(sps.csc_matrix(p)))
        q_fixed = model.q0.copy()
        q_fixed[model.free] = 0.0
        self.q_fixed = ca.DM(q_fixed)
        self.n_s, self.n_c = model.n_s, model.n_c
        self.n_sc = model.n_sc
        if formulation == "embedded" and any(e.joint.form == "global" for e in model.wheelrail):
            names = ", ".join(e.joint.name for e in model.wheelrail if e.joint.form == "global")
            raise ParameterError(f"formulation='embedded' needs the rail-frame form (eq. 22) of the wheel/rail "
                                 f"contacts ({names} use form='global'): its rows split into the four that fix "
                                 f"the surface parameters and the normal gap")
        tang = model.tangency_rows
        self.rows_t = tang
        self.rows_r = [r for r in range(self.n_c) if r not in set(tang)]

    def _cholesky_transform(self) -> sps.csc_matrix:
        """``T`` with physical free coordinates ``= T *`` internal ones: ``U^-1`` on the ANCF block."""
        from ..assembly.cholesky import CholeskyCoordinates

        model = self.model
        ancf = np.flatnonzero(model.free < model.ancf.n)
        if ancf.size == 0:
            raise ParameterError("cholesky=True: the model has no free ANCF coordinates")
        free_ancf = model.free[ancf]
        chol = CholeskyCoordinates(model.ancf.mass_matrix[free_ancf][:, free_ancf])
        u_inv = chol.from_cholesky(np.eye(ancf.size))  # dense: the price of Cholesky coordinates
        t = np.eye(self.n_f)
        t[np.ix_(ancf, ancf)] = u_inv
        self._transform = (t, np.linalg.inv(t))
        return sps.csc_matrix(t)

    def to_internal(self, y_free: np.ndarray) -> np.ndarray:
        """Physical free coordinates (or velocities) -> the DAE's coordinates."""
        return y_free if self._transform is None else self._transform[1] @ y_free

    def to_physical(self, y: np.ndarray) -> np.ndarray:
        """The DAE's coordinates -> physical free coordinates."""
        return y if self._transform is None else self._transform[0] @ y

    # --- shared pieces ------------------------------------------------------------------------
    def terms(self, q_f, v_f, s, w, t, sc=None, part: str = "all", contacts: bool = True):
        """Mass matrix, forces and constraint terms in free coordinates (MX); ``sc`` are the
        contact arc lengths (required when the model has penalty contacts). ``part="rest"``
        leaves the bulk's mass and forces out of ``M`` and ``Q`` (see
        :meth:`~symcat.assembly.multibody.MultibodyModel.forces`); constraints and contacts
        belong to the rest. ``contacts=False`` leaves the penalty contacts out (no ``T``,
        ``gap``, ``fc``, nor their forces in ``Q``): for a caller that has their values."""
        m = self.model
        q = self.q_fixed + ca.mtimes(self.P, q_f)
        v = ca.mtimes(self.P, v_f)
        c = m.constraints(q, v, s, w, t)
        mass = ca.mtimes(self.P.T, ca.mtimes(m.mass_matrix(q, part), self.P))
        f = m.forces(q, v, t, part)
        out = {"T": ca.MX(0, 1), "gap": ca.MX(0, 1), "fc": ca.MX(0, 1)}
        if self.n_sc and contacts:
            if sc is None:
                raise ValueError("terms: the model has penalty contacts; pass their arc lengths sc")
            ct = contact_terms(m, q, v, sc)
            f += ct["Q"]
            out = {"T": ct["T"], "gap": ct["gap"], "fc": ct["force"]}
        force = ca.mtimes(self.P.T, f)
        return {"q": q, "v": v, "M": mass, "Q": force, "C": c["c"], "Cq": ca.mtimes(c["c_q"], self.P),
                "Cs": c["c_s"], "Ct": c["c_t"], "Qd": c["q_d"], **out}

    def embedded_terms(self, q_f, v_f, s, t, sc=None):
        """``s_dot`` from the tangency rows, then ``H``, ``Q_cn`` and the reduced constraint terms."""
        probe = self.terms(q_f, v_f, s, ca.MX.zeros(self.n_s), t, sc)
        tr, rr = self.rows_t, self.rows_r
        if self.model.wheelrail:
            # 4x4 blocks per wheel/rail contact (1x1 per sliding joint): a sparse solve.
            s_dot = -ca.solve(probe["Cs"][tr, :], ca.mtimes(probe["Cq"][tr, :], v_f))
            k = self.terms(q_f, v_f, s, s_dot, t, sc)
            c_rs = k["Cs"][rr, :]
            both = ca.solve(k["Cs"][tr, :], ca.horzcat(k["Cq"][tr, :], k["Qd"][tr]))
            h = k["Cq"][rr, :] - ca.mtimes(c_rs, both[:, :-1])
            q_cn = k["Qd"][rr] - ca.mtimes(c_rs, both[:, -1])
        else:
            c_ts = ca.diag(probe["Cs"][tr, :])           # one s per tangency row
            s_dot = -ca.mtimes(probe["Cq"][tr, :], v_f) / c_ts
            k = self.terms(q_f, v_f, s, s_dot, t, sc)
            c_rs = k["Cs"][rr, :]
            inv = 1 / ca.diag(k["Cs"][tr, :])
            h = k["Cq"][rr, :] - ca.mtimes(c_rs, ca.mtimes(ca.diag(inv), k["Cq"][tr, :]))
            q_cn = k["Qd"][rr] - ca.mtimes(c_rs, inv * k["Qd"][tr])
        c_dot_r = ca.mtimes(h, v_f) + k["Ct"][rr]
        return {**k, "H": h, "Qcn": q_cn, "s_dot": s_dot, "CR": k["C"][rr], "CT": k["C"][tr], "CRdot": c_dot_r}

    def releasable(self) -> list[int]:
        """Wheel/rail contacts (positions in ``model.wheelrail``) that can open: those in the
        rail-frame form, whose gap is a constraint row of its own."""
        return [k for k, e in enumerate(self.model.wheelrail) if e.joint.form == "railframe"]

    def open_rows(self, open_mask) -> list[int]:
        """Constraint rows (model numbering) released by the open contacts ``open_mask``."""
        return [e.row_start + GAP_ROW for k, e in enumerate(self.model.wheelrail)
                if open_mask[k] and k in self.releasable()]

    def _release(self, rows, replacement, open_p):
        """``rows`` (the constraint rows of this form, or their multipliers' equations) with the
        gap rows of open contacts replaced by ``replacement`` (their multipliers)."""
        index = self.gap_row_index()
        keep = self.releasable()
        if not keep:
            return rows
        sel = sps.csc_matrix((np.ones(len(keep)), ([index[k] for k in keep], keep)),
                             shape=(rows.shape[0], len(self.model.wheelrail)))
        mask = ca.mtimes(ca.DM(to_casadi_sparse(sel)), open_p)
        return (1 - mask) * rows + mask * replacement

    def gap_row_index(self) -> list[int]:
        """Positions, in this form's multiplier vector, of row 2 of every wheel/rail contact: the
        gap row of the rail-frame form (its normal force is minus that multiplier)."""
        rows = [e.row_start + GAP_ROW for e in self.model.wheelrail]
        if self.formulation == "augmented":
            return rows
        return [self.rows_r.index(r) for r in rows]

    def normal_force_rows(self, full: bool = False) -> np.ndarray:
        """(n_w, 3) positions of the multipliers that carry each wheel/rail contact's normal force
        (:func:`symcat.assembly.wheelrail.normal_directions` weighs them): its rows 0-2 in this
        form's multiplier vector, or in the model's rows with ``full``. The embedded form keeps
        only the gap row of a (rail-frame) contact; its weightless rows 0-1 point there too."""
        rows = np.array([[e.row_start + i for i in range(3)] for e in self.model.wheelrail], int).reshape(-1, 3)
        if full or self.formulation == "augmented":
            return rows
        gap = self.gap_row_index()
        return np.array([[g, g, g] for g in gap], int).reshape(-1, 3)

    def normal_forces(self, q, s, lam):
        """Normal force (N) of every wheel/rail contact (MX) for all coordinates ``q``, surface
        parameters ``s`` and this form's multipliers ``lam``."""
        if not self.model.wheelrail:
            return ca.MX(0, 1)
        w = normal_directions(self.model, q, s)
        rows = self.normal_force_rows()
        return ca.vertcat(*[-ca.dot(w[3 * k : 3 * k + 3], lam[list(r)]) for k, r in enumerate(rows)])

    def normal_direction_function(self) -> ca.Function:
        """``(q, s) -> w`` (3 per wheel/rail contact; free internal coordinates ``q``): the weights
        of :func:`symcat.assembly.wheelrail.normal_directions` (numeric use, see
        :func:`normal_forces_numeric`)."""
        if getattr(self, "_normal_fn", None) is None:
            q, s = ca.MX.sym("q", self.n_f), ca.MX.sym("s", self.n_s)
            w = normal_directions(self.model, self.q_fixed + ca.mtimes(self.P, q), s)
            self._normal_fn = ca.Function("normal_directions", [q, s], [w], ["q", "s"], ["w"])
        return self._normal_fn

    def creep_force(self, k: dict, s, s_dot, lam):
        """Generalized creep forces in free coordinates and the creep record (see
        :func:`symcat.assembly.wheelrail.creep_terms`) for multipliers ``lam`` of this form."""
        normal = self.normal_forces(k["q"], s, lam)
        q_c, record = creep_terms(self.model, k["q"], k["v"], s, s_dot, normal)
        return ca.mtimes(self.P.T, q_c), record

    def creep_function(self) -> ca.Function:
        """``(q, v, s, s_dot, N) -> (Q_creep, record)`` in free coordinates (numeric use)."""
        if getattr(self, "_creep_fn", None) is not None:
            return self._creep_fn
        m = self.model
        q, v = ca.MX.sym("q", self.n_f), ca.MX.sym("v", self.n_f)
        s, w, normal = ca.MX.sym("s", self.n_s), ca.MX.sym("w", self.n_s), ca.MX.sym("N", len(m.wheelrail))
        q_c, record = creep_terms(m, self.q_fixed + ca.mtimes(self.P, q), ca.mtimes(self.P, v), s, w, normal)
        self._creep_fn = ca.Function("creep", [q, v, s, w, normal], [ca.mtimes(self.P.T, q_c), record])
        return self._creep_fn

    # --- the DAE ------------------------------------------------------------------------------
    def blocks(self):
        n_f, n_s, n_c = self.n_f, self.n_s, self.n_c
        n_r = n_c - n_s
        if self.formulation == "augmented":
            x = [("q", n_f), ("s", n_s), ("v", n_f)] + ([("w", n_s)] if self.index == "1" else [])
            z = [("a", n_f)] + ([("s_dd", n_s)] if self.index == "1" else [("w", n_s)]) + [("lambda", n_c)]
            z += [("mu", n_c)] if self.index == "ggl" else []
        else:
            x = [("q", n_f), ("v", n_f)]
            z = [("a", n_f), ("s", n_s), ("lambda", n_r)] + ([("mu", n_r)] if self.index == "ggl" else [])
        z += [("sc", self.n_sc)] if self.n_sc else []
        return _layout(x), _layout(z)

    def dae_function(self) -> ca.Function:
        """:meth:`dae` as the function IDAS takes: ``(t, x, z, p, u) -> (ode, alg, quad, zero)``
        with an empty control and no quadratures or zero crossings. One per window: integrators
        built from it share its cached Jacobian."""
        d = self.dae()
        return ca.Function("dae", [d["t"], d["x"], d["z"], d["p"], ca.MX.sym("u", 0)],
                           [d["ode"], d["alg"], ca.MX(0, 1), ca.MX(0, 1)], ca.dyn_in(), ca.dyn_out())

    def dae(self) -> dict:
        """CasADi DAE dict ``{x, z, p, t, ode, alg}``; ``p`` is the time offset of the chunk and
        the open flags of the wheel/rail contacts (see the module's notes)."""
        xb, zb = self.blocks()
        x = ca.MX.sym("x", sum(b.size for b in xb.values()))
        z = ca.MX.sym("z", sum(b.size for b in zb.values()))
        t_rel = ca.MX.sym("t")
        t0 = ca.MX.sym("t0")
        open_p = ca.MX.sym("open", len(self.model.wheelrail))
        t = t0 + t_rel
        X = {k: x[b.slice] for k, b in xb.items()}
        Z = {k: z[b.slice] for k, b in zb.items()}
        al = be = self.baumgarte
        sc = Z.get("sc")
        if self.formulation == "augmented":
            w = X["w"] if self.index == "1" else Z["w"]
            k = self.terms(X["q"], X["v"], X["s"], w, t, sc)
            dyn = ca.mtimes(k["M"], Z["a"]) + ca.mtimes(k["Cq"].T, Z["lambda"]) - k["Q"]
            if has_creep(self.model):
                dyn -= self.creep_force(k, X["s"], w, Z["lambda"])[0]
            free_s = ca.mtimes(k["Cs"].T, Z["lambda"])
            c_dot = ca.mtimes(k["Cq"], X["v"]) + ca.mtimes(k["Cs"], w) + k["Ct"]
            lam = Z["lambda"]
            if self.index == "1":
                acc = ca.mtimes(k["Cq"], Z["a"]) + ca.mtimes(k["Cs"], Z["s_dd"]) + k["Qd"] + 2 * al * c_dot + be**2 * k["C"]
                ode = ca.vertcat(X["v"], w, Z["a"], Z["s_dd"])
                alg = ca.vertcat(dyn, free_s, self._release(acc, lam, open_p))
            else:
                ode = ca.vertcat(X["v"] + ca.mtimes(k["Cq"].T, Z["mu"]), w + ca.mtimes(k["Cs"].T, Z["mu"]), Z["a"])
                alg = ca.vertcat(dyn, free_s, self._release(k["C"], Z["mu"], open_p), self._release(c_dot, lam, open_p))
        else:
            k = self.embedded_terms(X["q"], X["v"], Z["s"], t, sc)
            dyn = ca.mtimes(k["M"], Z["a"]) + ca.mtimes(k["H"].T, Z["lambda"]) - k["Q"]
            if has_creep(self.model):
                dyn -= self.creep_force(k, Z["s"], k["s_dot"], Z["lambda"])[0]
            lam = Z["lambda"]
            if self.index == "1":
                acc = ca.mtimes(k["H"], Z["a"]) + k["Qcn"] + 2 * al * k["CRdot"] + be**2 * k["CR"]
                ode = ca.vertcat(X["v"], Z["a"])
                alg = ca.vertcat(dyn, k["CT"], self._release(acc, lam, open_p))
            else:
                ode = ca.vertcat(X["v"] + ca.mtimes(k["H"].T, Z["mu"]), Z["a"])
                alg = ca.vertcat(dyn, k["CT"], self._release(k["CR"], Z["mu"], open_p),
                                 self._release(k["CRdot"], lam, open_p))
        alg = ca.vertcat(alg, k["T"])
        return {"x": x, "z": z, "p": ca.vertcat(t0, open_p), "t": t_rel, "ode": ode, "alg": alg}

    def residual_names(self) -> list[str]:
        """Names of the algebraic residual rows (for failure reports)."""
        contacts = [f"tangency of contact {ct.joint.name}" for ct in self.model.contacts]
        return self._residual_names() + contacts

    def _residual_names(self) -> list[str]:
        coords = [self.model.coordinate_names()[i] for i in self.model.free]
        rows = self.model.row_names
        sliding = [sl.joint.name for sl in self.model.sliding]
        sliding += [f"{e.joint.name}.{p}" for e in self.model.wheelrail for p in ("s1w", "s2w", "s1r", "s2r")]
        dyn = [f"dynamics of {c}" for c in coords]
        if self.formulation == "augmented":
            names = dyn + [f"C_s^T lambda of {n}" for n in sliding]
            if self.index == "1":
                return names + [f"acceleration constraint {r}" for r in rows]
            return names + [f"position constraint {r}" for r in rows] + [f"velocity constraint {r}" for r in rows]
        kept = [rows[r] for r in self.rows_r]
        names = dyn + [f"tangency of {n}" for n in sliding]
        if self.index == "1":
            return names + [f"acceleration constraint {r}" for r in kept]
        return names + [f"position constraint {r}" for r in kept] + [f"velocity constraint {r}" for r in kept]


def _layout(entries) -> dict[str, Block]:
    out, start = {}, 0
    for name, size in entries:
        out[name] = Block(name, start, size)
        start += size
    return out


def normal_forces_numeric(weights, lam, rows) -> np.ndarray:
    """Normal forces ``N_k = -w_k . lam[rows_k]`` of the wheel/rail contacts (numeric).

    Parameters
    ----------
    weights : ndarray (..., 3 n_w)
        :meth:`Formulation.normal_direction_function`'s output, one row per state.
    lam : ndarray (..., n_lam)
        Multipliers, one row per state.
    rows : ndarray (n_w, 3)
        :meth:`Formulation.normal_force_rows` for the layout of ``lam``.

    Returns
    -------
    ndarray (..., n_w)
    """
    w = np.asarray(weights, float)
    w = w.reshape(w.shape[:-1] + (-1, 3))
    return -(w * np.asarray(lam, float)[..., rows]).sum(axis=-1)
