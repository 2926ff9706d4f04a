"""Assembly of a multibody scene: ANCF bodies, rigid bodies, constraints and force elements.

Coordinates are laid out as ``q = [ANCF coordinates of every body | rigid-body coordinates
(R, theta), 7 per body]``; the non-generalized arc-length parameters ``s`` of the sliding joints
form a separate vector. Everything here builds CasADi MX expressions from the mapped, compiled
kernels; :mod:`symcat.dae` composes them into the equations of motion.

Sliding joints use a *global arc-length map*: ``s`` is measured along the whole wire, and the
element that contains it is selected inside a window of elements by masks
``(S_k <= s < S_k+1)``, which have zero derivative. The selected element's coordinates and
``s - S_k`` go to the element kernel, so ``s``, its rate and the constraint force are continuous
across element ends (the ANCF interpolation is C1 there). The window moves with the contact
point; :mod:`symcat.integrate` restarts the integrator, with the same state, when ``s`` nears
its edge.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..codegen.fingerprint import scene_digest
from ..codegen.library import kernel_library, library_interface
from ..errors import ParameterError
from ..scene.joints import Driving, Fixed, Prismatic, Revolute, SlidingJoint, Spherical, perpendiculars, unit
from ..scene.wheelrail import WheelRailJoint
from ..scene.scene import Scene
from .sparse import MatrixScatter, to_casadi_sparse, vector_scatter
from .system import System
from .wire_attachment import Sliding, wire_attachment
from .windows import ElementWindows
from ..wheelrail.identity_memo import IdentityMemo

import scipy.sparse as sps


@dataclass
class Side:
    kind: str               # ground, rigid or node
    indices: list[int]      # global coordinate indices
    body: object = None
    local: dict = field(default_factory=dict)


@dataclass
class KernelGroup:
    """Instances of one constraint or force library (plain gathers of q)."""

    library: str
    rows: list = field(default_factory=list)      # per instance: global indices of y
    params: list = field(default_factory=list)    # per instance: parameter vector
    names: list = field(default_factory=list)     # per instance: joint/force name


class MultibodyModel(ElementWindows):
    """Assembled multibody scene (see the module docstring).

    Parameters
    ----------
    scene : Scene
        ANCF bodies, rigid bodies, joints, force elements and loads.
    window : int
        Elements in the moving window of each sliding joint.
    """

    def __init__(self, scene: Scene, window: int = 16):
        self.scene = scene
        self.scene_digest = scene_digest(scene)  # what the model was built from (compiled steps' cache key)
        self.ancf = System(scene)
        n_a = self.ancf.n
        self.rigid_offset = {b.name: n_a + 7 * k for k, b in enumerate(scene.rigid_bodies)}
        self.n_q = n_a + 7 * len(scene.rigid_bodies)
        self.q0 = np.concatenate([self.ancf.dofs.q0, *[b.q0 for b in scene.rigid_bodies]]) if self.n_q else np.zeros(0)
        self.v0 = np.concatenate([np.zeros(n_a), *[b.v0 for b in scene.rigid_bodies]]) if self.n_q else np.zeros(0)
        fixed = np.concatenate([self.ancf.dofs.fixed, *[b.held_mask for b in scene.rigid_bodies]]).astype(bool)
        self.free = np.flatnonzero(~fixed)
        self.window_size = int(window)
        # id(Sliding) -> (start, length) symbols of the element a one-element window stands in
        # for (generalized-alpha's proxy elements, symcat.integrate.alpha_step)
        self.element_override: dict[int, tuple] = {}
        self.groups: dict[str, KernelGroup] = {}
        self.force_groups: dict[str, KernelGroup] = {}
        self.sliding: list[Sliding] = []
        self.contacts: list[Sliding] = []   # penalty contacts (same window bookkeeping)
        self.wheelrail: list = []           # wheel/rail contacts (symcat.assembly.wheelrail)
        # Functions the wheel/rail contacts share (one per profile or creep model; in the model,
        # not the process, so that the graph, whose serialization keys the compiled DAE, does not
        # depend on what was built before).
        self.wheelrail_shared = IdentityMemo()
        self.row_names: list[str] = []
        for body in scene.rigid_bodies:
            if "rotation" not in body.held:  # held Euler parameters stay normalized
                self._add("normalization_rigid", body.name, [Side("rigid", self._rigid_indices(body.name), body)], {})
        for joint in scene.joints:
            self._add_joint(joint)
        for force in scene.force_elements:
            self._add_force(force)
        # s = [arc lengths of the sliding joints | 4 surface parameters per wheel/rail contact]
        self.n_sliding = len(self.sliding)
        for k, e in enumerate(self.wheelrail):
            e.s_index = self.n_sliding + 4 * k
        self.n_s = self.n_sliding + 4 * len(self.wheelrail)
        self.s0 = np.concatenate([[sl.joint.s0 for sl in self.sliding], *[e.s0 for e in self.wheelrail]])
        self.n_sc = len(self.contacts)
        self.sc0 = np.array([ct.joint.s0 for ct in self.contacts])
        for sl in self.sliding + self.contacts:
            self.set_window(sl, sl.joint.s0)
        self._group_rows()

    # --- bookkeeping ------------------------------------------------------------------------
    def _rigid_indices(self, name: str) -> list[int]:
        start = self.rigid_offset[name]
        return list(range(start, start + 7))

    def side(self, ref, point) -> Side:
        """Kind, coordinates and local geometry of one end of a joint or force element."""
        point = np.asarray(point, float)
        if ref == "ground":
            return Side("ground", [], None, {"u": point, "R": np.eye(3)})
        if isinstance(ref, tuple):
            body = self.scene.find(ref[0])
            if body.element.dim != 3:
                raise ParameterError(f"({ref[0]!r}, {ref[1]}): joints and springs need a 3D ANCF body, not {body.element.name}")
            idx = self.ancf.dofs.node_indices(body, ref[1])[:3].tolist()
            return Side("node", idx, body, {"u": point - body.q0[body.node_index(ref[1]), :3], "R": np.eye(3)})
        body = self.scene.find(ref)
        return Side("rigid", self._rigid_indices(body.name), body, {"u": body.local(point), "R": body.rotation})

    def _add(self, library: str, name: str, sides: list[Side], values: dict, group=None):
        groups = self.groups if group is None else group
        info = library_interface(library)
        g = groups.setdefault(library, KernelGroup(library))
        try:
            params = [values[p] for p in info["params"]]
        except KeyError as exc:
            raise RuntimeError(f"{library}: no value for parameter {exc}") from None
        g.rows.append(sum((s.indices for s in sides), []))
        g.params.append(params)
        g.names.append(name)

    @staticmethod
    def _vectors(values: dict, side: Side, tag: str, **global_vectors):
        """Body-frame components of global vectors (ground: global components)."""
        for name, vec in global_vectors.items():
            local = side.local["R"].T @ np.asarray(vec, float)
            values.update({f"{name}{tag}_{k}": local[k] for k in range(3)})

    def _add_joint(self, joint):
        if isinstance(joint, SlidingJoint):
            self._add_sliding(joint)
            return
        if isinstance(joint, WheelRailJoint):
            from .wheelrail import add_wheelrail

            self.wheelrail.append(add_wheelrail(self, joint))
            return
        if isinstance(joint, Driving):
            side = self.side(joint.body, joint.at if joint.at is not None else self.scene.find(joint.body).position)
            n = unit(joint.direction, f"{joint.name}.direction")
            point = np.asarray(joint.at if joint.at is not None else side.body.position, float)
            values = {f"n_{k}": n[k] for k in range(3)}
            values.update({f"ui_{k}": side.local["u"][k] for k in range(3)})
            values.update(x0=float(n @ point), velocity=joint.velocity, amplitude=joint.amplitude,
                          omega=2 * np.pi * joint.frequency, phase=joint.phase)
            values.update({f"uj_{k}": 0.0 for k in range(3)})
            self._add("driving_rigid_ground", joint.name, [side], values)
            return
        a = self.side(joint.body_i, joint.at)
        b = self.side(joint.body_j, joint.at)
        if a.kind == "ground":
            raise ParameterError(f"joint {joint.name!r}: body_i must not be the ground (swap the bodies)")
        kind = {Spherical: "spherical", Revolute: "revolute", Prismatic: "prismatic", Fixed: "fixed"}[type(joint)]
        library = f"{kind}_{a.kind}_{b.kind}"
        if library not in _available():
            raise ParameterError(f"joint {joint.name!r}: {kind} between a {a.kind} and a {b.kind} body is not supported")
        values = {f"ui_{k}": a.local["u"][k] for k in range(3)}
        values.update({f"uj_{k}": b.local["u"][k] for k in range(3)})
        if kind == "revolute":
            x, y = perpendiculars(joint.axis)
            self._vectors(values, a, "i", z=unit(joint.axis, f"{joint.name}.axis"))
            self._vectors(values, b, "j", x=x, y=y)
        elif kind == "prismatic":
            axis = unit(joint.axis, f"{joint.name}.axis")
            n1, n2 = perpendiculars(axis)
            self._vectors(values, a, "i", n1=n1, n2=n2)
            self._vectors(values, b, "j", m1=n1, a=axis)
        elif kind == "fixed":
            eye = np.eye(3)
            self._vectors(values, a, "i", x=eye[0], y=eye[1], z=eye[2])
            self._vectors(values, b, "j", x=eye[0], y=eye[1], z=eye[2])
        self._add(library, joint.name, [a, b], values)

    def _add_sliding(self, joint: SlidingJoint):
        wire, body, starts = wire_attachment(self.scene, "sliding joint", joint.name, joint.wire, joint.body, joint.s0)
        library = f"sliding_{wire.element.name}_rigid"
        info = library_interface(library)
        point = body.position if joint.at is None else joint.at
        u = body.local(point)
        d_ref = unit(joint.reference_direction, f"{joint.name}.reference_direction")
        values = {"L": 0.0, **{f"d_ref_{k}": d_ref[k] for k in range(3)}, **{f"uj_{k}": u[k] for k in range(3)}}
        params = np.array([values[p] for p in info["params"]])
        self.sliding.append(Sliding(joint, wire, body, library, self.n_q + len(self.sliding), starts,
                                    self.ancf.dofs.element_indices(wire), params))

    def _add_force(self, force):
        from .force_elements import add_force

        add_force(self, force)

    def _group_rows(self):
        """Constraint row numbering: groups in order, then sliding joints (3 rows each)."""
        self.row_start = {}
        n = 0
        for lib, g in self.groups.items():
            n_c = library_interface(lib)["n_c"]
            self.row_start[lib] = n
            for name in g.names:
                self.row_names += [f"{name}[{k}]" for k in range(n_c)]
            n += n_c * len(g.names)
        self.sliding_row_start = n
        for sl in self.sliding:
            self.row_names += [f"{sl.joint.name}[{k}]" for k in range(3)]
            n += 3
        # Rows that define s in the embedded form, in the order of s: the first (tangency) row
        # of each sliding joint, four rows of each wheel/rail contact.
        self.tangency_rows = [self.sliding_row_start + 3 * k for k in range(self.n_sliding)]
        from .wheelrail import TANGENCY_ROWS

        for e in self.wheelrail:
            e.row_start = n
            self.row_names += [f"{e.joint.name}[{k}]" for k in range(5)]
            self.tangency_rows += [n + r for r in TANGENCY_ROWS]
            n += 5
        self.n_c = n

    def coordinate_names(self) -> list[str]:
        names = self.ancf.dofs.names()
        for b in self.scene.rigid_bodies:
            names += [f"{b.name}.{c}" for c in ("x", "y", "z", "e0", "e1", "e2", "e3")]
        return names

    # --- MX builders --------------------------------------------------------------------------
    def mass_matrix(self, q: ca.MX, part: str = "all") -> ca.MX:
        """Mass matrix (kg, kg m^2); ``part`` as for :meth:`forces` (the ANCF block is the bulk)."""
        _check_part(part)
        if part == "rest":
            m = ca.MX(self.n_q, self.n_q)
        else:
            m = ca.MX(self._structure("ancf mass", lambda: to_casadi_sparse(sps.block_diag(
                [self.ancf.mass_matrix, sps.csc_matrix((self.n_q - self.ancf.n,) * 2)], format="csc"))))
        if self.scene.rigid_bodies and part != "bulk":
            idx = np.array([self._rigid_indices(b.name) for b in self.scene.rigid_bodies])
            p = ca.DM(np.array([b.params for b in self.scene.rigid_bodies]).T)
            lib = kernel_library("rigid")
            blocks = lib["rigid_mass"].map(len(idx))(_gather(q, idx), p)
            scatter = self._structure("rigid mass", lambda: MatrixScatter.square(idx, self.n_q,
                                                                               lib["rigid_mass"].sparsity_out(0)))
            m += scatter(blocks)
        return m

    def _structure(self, key, build):
        """``build()``, once per model: the index maps and constant matrices that the MX
        builders assemble from the model's fixed layout (the builders run for every graph made
        of the model, a dozen per run; rebuilding these took half their time)."""
        cache = self.__dict__.setdefault("_structures", {})
        if key not in cache:
            cache[key] = build()
        return cache[key]

    def _rayleigh_dm(self) -> ca.DM:
        """The scene's Rayleigh damping matrix (:attr:`System.rayleigh_matrix`) over all
        coordinates, as a constant CasADi sparse matrix (built once)."""
        if getattr(self, "_rayleigh", None) is None:
            c, n_a = self.ancf.rayleigh_matrix, self.ancf.n
            if self.n_q > n_a:
                c = sps.block_diag([c, sps.csc_matrix((self.n_q - n_a,) * 2)], format="csc")
            self._rayleigh = to_casadi_sparse(c)
        return self._rayleigh

    def forces(self, q: ca.MX, v: ca.MX, t: ca.MX, part: str = "all", rayleigh: bool = True) -> ca.MX:
        """All applied, internal and quadratic-velocity forces (N, N m), Rayleigh damping included
        (unless ``rayleigh=False``: a caller that multiplies the constant matrix itself).

        ``part``: ``"all"``; ``"bulk"``, the terms that act on ANCF coordinates only (element
        forces, Rayleigh damping, force elements between nodes or from a node to the ground),
        whose Jacobian changes little over a run; ``"rest"``, the others (rigid bodies, force
        elements with a rigid end). ``bulk + rest = all``; generalized-alpha keeps the bulk's
        factorized Jacobian and updates the rest's every step."""
        _check_part(part)
        n_a = self.ancf.n
        f = ca.MX(self.n_q, 1)
        if n_a and part != "rest":
            f += ca.vertcat(self.ancf.force_function()(q[:n_a], v[:n_a]), ca.MX(self.n_q - n_a, 1))
            if rayleigh and self.ancf.rayleigh_matrix is not None:  # constant sparse C times v
                f -= ca.mtimes(self._rayleigh_dm(), v)
        if self.scene.rigid_bodies and part != "bulk":
            bodies = self.scene.rigid_bodies
            idx = np.array([self._rigid_indices(b.name) for b in bodies])
            p = ca.DM(np.array([b.params for b in bodies]).T)
            qv = kernel_library("rigid")["rigid_qv"].map(len(bodies))(_gather(q, idx), _gather(v, idx), p)
            f += ca.mtimes(self._structure("rigid forces", lambda: vector_scatter(idx, self.n_q)), ca.vec(qv))
            g = self.scene.gravity_vector()
            weight = np.zeros(self.n_q)
            for b, rows in zip(bodies, idx):
                weight[rows[:3]] += b.mass * g
            f += ca.DM(weight)
        for lib, group in self.force_groups.items():
            rows, params = np.array(group.rows), np.array(group.params)
            if part != "all":
                keep = (rows.max(axis=1) < n_a) == (part == "bulk")
                rows, params = rows[keep], params[keep]
                if not len(rows):
                    continue
            fn = kernel_library(lib)[lib].map(len(rows))
            out = fn(_gather(q, rows), _gather(v, rows), t, ca.DM(params.T))
            f += ca.mtimes(self._structure(("forces", lib, part), lambda: vector_scatter(rows, self.n_q)), ca.vec(out))
        return f

    def _sliding_local(self, sl: Sliding, q: ca.MX, v: ca.MX, s: ca.MX, s_dot: ca.MX):
        """Selected element's coordinates, rates, s - S_k and element length (see _selection)."""
        sel, start, length = self._selection(sl, s)
        rows = self._rigid_indices(sl.body.name)
        y = ca.vertcat(ca.mtimes(sel, q), q[rows], s - start)
        y_dot = ca.vertcat(ca.mtimes(sel, v), v[rows], s_dot)
        return y, y_dot, length, sel

    def constraints(self, q: ca.MX, v: ca.MX, s: ca.MX, s_dot: ca.MX, t: ca.MX) -> dict:
        """Constraint values ``c``, Jacobians ``c_q`` (sparse), ``c_s``, ``c_t`` and ``q_d``."""
        c_parts, cq_parts, cs_parts, ct_parts, qd_parts = [], [], [], [], []
        for lib, group in self.groups.items():
            rows = np.array(group.rows)
            m = len(rows)
            p = ca.DM(np.array(group.params).T)
            kl = kernel_library(lib)
            y = _gather(q, rows)
            y_dot = _gather(v, rows)
            n_c = library_interface(lib)["n_c"]
            c_parts.append(ca.vec(kl[f"{lib}_c"].map(m)(y, t, p)))
            c_y, c_t = kl[f"{lib}_jac"].map(m)(y, t, p)
            scatter = self._structure(("constraints", lib), lambda: MatrixScatter(
                np.arange(m * n_c).reshape(m, n_c), rows, (m * n_c, self.n_q), kl[f"{lib}_jac"].sparsity_out(0)))
            cq_parts.append(scatter(c_y))
            cs_parts.append(ca.MX(m * n_c, self.n_s))
            ct_parts.append(ca.vec(c_t))
            qd_parts.append(ca.vec(kl[f"{lib}_gamma"].map(m)(y, y_dot, t, p)))
        for k, sl in enumerate(self.sliding):
            kl = kernel_library(sl.library)
            y, y_dot, length, sel = self._sliding_local(sl, q, v, s[k], s_dot[k])
            p = ca.vertcat(length, ca.DM(sl.params[1:]))
            c_parts.append(kl[f"{sl.library}_c"](y, t, p))
            c_y, c_t = kl[f"{sl.library}_jac"](y, t, p)
            n_loc = sl.element_indices.shape[1]
            body = self._structure(("sliding body", k), lambda: _placement(self._rigid_indices(sl.body.name), self.n_q))
            cq = ca.mtimes(c_y[:, :n_loc], sel) + ca.mtimes(c_y[:, n_loc : n_loc + 7], body)
            cq_parts.append(cq)
            cs = ca.MX(3, self.n_s)
            cs[:, k] = c_y[:, n_loc + 7]
            cs_parts.append(cs)
            ct_parts.append(c_t)
            qd_parts.append(kl[f"{sl.library}_gamma"](y, y_dot, t, p))
        if self.wheelrail:
            from .wheelrail import constraint_parts

            for c, cq, cs, ct, qd in constraint_parts(self, q, v, s, s_dot, t, _place):
                c_parts.append(c), cq_parts.append(cq), cs_parts.append(cs), ct_parts.append(ct), qd_parts.append(qd)
        if not c_parts:
            z = ca.MX(0, 1)
            return {"c": z, "c_q": ca.MX(0, self.n_q), "c_s": ca.MX(0, self.n_s), "c_t": z, "q_d": z}
        return {"c": ca.vertcat(*c_parts), "c_q": ca.vertcat(*cq_parts), "c_s": ca.vertcat(*cs_parts),
                "c_t": ca.vertcat(*ct_parts), "q_d": ca.vertcat(*qd_parts)}

    def kinetic_energy(self, q: ca.MX, v: ca.MX) -> ca.MX:
        return 0.5 * ca.dot(v, ca.mtimes(self.mass_matrix(q), v))

    def potential_energy(self, q: ca.MX) -> ca.MX:
        """Strain energy plus the potential of gravity and of constant loads (J)."""
        u = ca.MX(0)
        n_a = self.ancf.n
        if n_a:
            qa = q[:n_a]
            u += self.ancf.strain_energy_expr(qa)
            u -= ca.dot(self.ancf.constant_load(), qa)
        g = self.scene.gravity_vector()
        for b in self.scene.rigid_bodies:
            r = q[self._rigid_indices(b.name)[:3]]
            u -= b.mass * ca.dot(ca.DM(g), r)
        return u


#: The parts of :meth:`MultibodyModel.forces` and :meth:`MultibodyModel.mass_matrix`.
PARTS = ("all", "bulk", "rest")


def _check_part(part: str) -> None:
    if part not in PARTS:
        raise ValueError(f"part={part!r}: must be one of {', '.join(PARTS)}")


def _gather(x: ca.MX, rows: np.ndarray) -> ca.MX:
    rows = np.asarray(rows)
    return ca.reshape(x[rows.ravel().tolist()], rows.shape[1], rows.shape[0])


def _place(block: ca.MX, cols, n: int) -> ca.MX:
    """Put the columns of ``block`` at global columns ``cols`` of an (rows x n) matrix."""
    return ca.mtimes(block, _placement(cols, n))


def _placement(cols, n: int) -> ca.MX:
    """The matrix that puts a block's columns at global columns ``cols`` of ``n``."""
    cols = list(cols)
    p = sps.csc_matrix((np.ones(len(cols)), (np.arange(len(cols)), cols)), shape=(len(cols), n))
    return ca.MX(to_casadi_sparse(p))


def _available() -> set[str]:
    from ..codegen.paths import read_manifest

    return set(read_manifest()["libraries"])
