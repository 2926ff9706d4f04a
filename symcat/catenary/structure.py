"""A meshed catenary: ANCF wires, droppers, supports and lumped masses, as numeric functions.

The contact and messenger wires are ANCF bodies meshed through the same stations (supports,
droppers and equal subdivisions between them), so every dropper and support sits on a node of
both wires. Wire elastic forces and tangent stiffness come from the compiled element kernels;
droppers (tension-only) and support springs are a few vectorised NumPy lines on top.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sps

from ..assembly.system import System
from ..errors import ParameterError
from ..scene import AncfBody, Material, NodalForce, Scene, Section
from .design import CatenaryDesign

MODULUS = 1.0e11  # nominal E (Pa); only E A and E I reach the kernels


def stations(design: CatenaryDesign, elements_per_span: int) -> np.ndarray:
    """Node positions along the line (m): supports, droppers, and subdivisions in between.

    Each interval between consecutive supports/droppers gets ``round(elements_per_span *
    interval / span_length)`` elements (at least one).
    """
    if int(elements_per_span) != elements_per_span or elements_per_span < 1:
        raise ParameterError(f"elements_per_span={elements_per_span}: must be an integer >= 1")
    marks = np.concatenate([[0.0], design.dropper_positions, [design.span_length]])
    local = []
    for a, b in zip(marks[:-1], marks[1:]):
        n = max(1, int(round(elements_per_span * (b - a) / design.span_length)))
        local.extend(a + (b - a) * np.arange(n) / n)
    local = np.asarray(local)
    xs = (design.span_length * np.arange(design.n_spans)[:, None] + local[None, :]).ravel()
    return np.concatenate([xs, [design.length]])


def _wire_body(name, element, x, y, z, wire) -> AncfBody:
    nodes_xyz = np.column_stack([x, y, z])
    tangent = np.gradient(nodes_xyz, x, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    lengths = np.linalg.norm(np.diff(nodes_xyz, axis=0), axis=1)
    prestrain = wire.tension / wire.EA
    section = Section.from_stiffness(wire.EA, wire.EI, MODULUS)
    material = Material(E=MODULUS, rho=wire.mass_per_length * (1 + prestrain) / section.A)
    if element == "cable3d":
        nodes = np.column_stack([nodes_xyz, tangent])
    elif element == "beam3d":
        up = np.array([0.0, 0.0, 1.0])
        d2 = np.cross(up, tangent)
        d2 /= np.linalg.norm(d2, axis=1)[:, None]
        d3 = np.cross(tangent, d2)
        nodes = np.column_stack([nodes_xyz, tangent, d2, d3])
    else:
        raise ParameterError(f"element={element!r}: must be one of cable3d, beam3d")
    return AncfBody.from_nodes(name, element, nodes, lengths, material, section, prestrain=prestrain)


@dataclass
class Supports:
    """Spring supports: node numbers, stiffness (N/m) and preload (N, upward at design height)."""

    nodes: np.ndarray
    stiffness: float
    height: np.ndarray
    preload: np.ndarray


class CatenaryStructure:
    """The catenary meshed and assembled: every tension section's contact and messenger wire.

    Parameters
    ----------
    design : CatenaryDesign
        What to build.
    elements_per_span : int
        Target number of elements per span (rounded per dropper interval).
    element : str
        ``"cable3d"`` (default) or ``"beam3d"``.
    messenger_z : ndarray, optional
        Initial messenger-wire heights at the stations (m); default: a parabolic guess.

    Attributes
    ----------
    x : ndarray
        Stations (m) of all sections, section after section (so not sorted where sections
        overlap). Row ``i`` of ``cw_xyz`` / ``mw_xyz`` holds the coordinates of the contact /
        messenger wire node at station ``i``; ``dropper_nodes`` and ``support_nodes`` index
        these rows.
    sections : list of TensionSection
        Where each section lies; ``section_rows[k]`` is its slice of the rows.
    contacts, messengers : list of AncfBody
        The wires of each section.
    system : System
        The wires assembled (elastic forces, mass matrix, gravity and end tensions).
    dropper_length : ndarray
        Unstretched dropper lengths (m); set by form finding.
    target_z : ndarray
        Design contact-wire height at every station (m).
    """

    def __init__(self, design: CatenaryDesign, elements_per_span: int, element: str = "cable3d",
                 messenger_z: np.ndarray | None = None):
        self.design = design
        self.element = element
        d = design
        local = stations(design, elements_per_span)
        self.elements_per_span = (len(local) - 1) // design.n_spans
        self.sections = design.sections()
        n_local = local.size
        self.section_rows = [slice(k * n_local, (k + 1) * n_local) for k in range(len(self.sections))]
        self.x = np.concatenate([sec.x0 + local for sec in self.sections])
        drop_local = np.searchsorted(local, design.dropper_x() - 1e-9)
        sup_local = np.searchsorted(local, design.support_x() - 1e-9)
        starts = n_local * np.arange(len(self.sections))
        self.dropper_nodes = (starts[:, None] + drop_local[None, :]).ravel()
        self.support_nodes = (starts[:, None] + sup_local[None, :]).ravel()
        inner = (starts[:, None] + sup_local[None, 1:-1]).ravel()
        self._local = dict(drop=drop_local, support=sup_local)
        y = np.concatenate([sec.stagger_y(sec.x0 + local) for sec in self.sections])
        z_cw = np.concatenate([sec.target_height(sec.x0 + local) for sec in self.sections])
        mw_support = np.concatenate([sec.messenger_support_height() for sec in self.sections])
        if messenger_z is None:
            w = d.gravity * (d.contact_wire.mass_per_length + d.messenger_wire.mass_per_length)
            span_local = local - d.span_length * np.minimum(np.floor(local / d.span_length), d.n_spans - 1)
            sag = w * span_local * (d.span_length - span_local) / (2 * d.messenger_wire.tension)
            messenger_z = np.concatenate([np.interp(sec.x0 + local, sec.support_x(), sec.messenger_support_height()) - sag
                                          for sec in self.sections])
        messenger_z = np.asarray(messenger_z, float)
        self.target_z = z_cw
        single = len(self.sections) == 1
        name = lambda base, k: base if single else f"{base}_{k + 1}"
        self.contacts = [_wire_body(name("contact", k), element, self.x[r], y[r], z_cw[r], d.contact_wire)
                         for k, r in enumerate(self.section_rows)]
        self.messengers = [_wire_body(name("messenger", k), element, self.x[r], y[r], messenger_z[r], d.messenger_wire)
                           for k, r in enumerate(self.section_rows)]
        self.dropper_length = np.full(self.dropper_nodes.size, np.nan)
        inner_sup = np.concatenate([np.arange(k * sup_local.size, (k + 1) * sup_local.size)[1:-1]
                                    for k in range(len(self.sections))])
        self.cw_supports = Supports(inner, d.steady_arm_stiffness, z_cw[inner], np.zeros(inner.size))
        self.mw_supports = Supports(inner, d.messenger_support_stiffness, mw_support[inner_sup], np.zeros(inner.size))
        self._build_system()

    # --- assembly -------------------------------------------------------------------------
    def _build_system(self) -> None:
        d = self.design
        scene = Scene(gravity=(0.0, 0.0, -d.gravity))
        for cw, mw in zip(self.contacts, self.messengers):
            for body, wire in ((cw, d.contact_wire), (mw, d.messenger_wire)):
                body.fixed.clear()
                body.pin(0)
                body.fix(-1, ["y", "z"])
                for node in self._local["support"][1:-1]:
                    body.fix(int(node), ["y"])
                if self.element == "beam3d":
                    body.fix(0, ["z_y", "y_z"])  # torsion about the wire axis
                scene.add(body)
                scene.add(NodalForce(body.name, -1, (wire.tension, 0.0, 0.0)))
        self.scene = scene
        self.system = System(scene)
        dofs = self.system.dofs
        self.n = dofs.n
        self.free = dofs.free
        # a fill-reducing ordering of the free stiffness, kept by the static solves that
        # factorize it (its pattern changes only with the droppers' slackness)
        self.free_ordering = None
        idx = lambda body, c: np.array([dofs.index(body, k, c) for k in range(body.n_nodes)], dtype=np.int64)
        self.cw_xyz = np.concatenate([np.stack([idx(b, c) for c in "xyz"], axis=1) for b in self.contacts])
        self.mw_xyz = np.concatenate([np.stack([idx(b, c) for c in "xyz"], axis=1) for b in self.messengers])
        self.cw_zx = np.concatenate([idx(b, "z_x") for b in self.contacts])
        self.cw_xx = np.concatenate([idx(b, "x_x") for b in self.contacts])
        self._lumped = self._lumped_masses()
        self._linear = None
        self._f_ext = self.system.external_force_value(self.system.dofs.q0) - self._lumped * d.gravity * self._z_mask()

    def _z_mask(self) -> np.ndarray:
        mask = np.zeros(self.n)
        mask[self.cw_xyz[:, 2]] = 1.0
        mask[self.mw_xyz[:, 2]] = 1.0
        return mask

    def _lumped_masses(self) -> np.ndarray:
        """Lumped mass (kg) on each translational coordinate: clamps, half droppers, steady arms."""
        d = self.design
        m = np.zeros(self.n)
        length = np.where(np.isfinite(self.dropper_length), self.dropper_length, self._dropper_distance(self.q0))
        half = 0.5 * d.dropper_mass_per_length * length
        for axis in range(3):
            np.add.at(m, self.cw_xyz[self.dropper_nodes, axis], d.clamp_mass_contact + half)
            np.add.at(m, self.mw_xyz[self.dropper_nodes, axis], d.clamp_mass_messenger + half)
            np.add.at(m, self.cw_xyz[self.cw_supports.nodes, axis], d.steady_arm_mass)
        return m

    @property
    def q0(self) -> np.ndarray:
        return self.system.dofs.q0.copy()

    def set_dropper_lengths(self, lengths: np.ndarray) -> None:
        """Set the unstretched dropper lengths (m) and update the lumped dropper masses."""
        lengths = np.asarray(lengths, dtype=float)
        if lengths.shape != self.dropper_length.shape or np.any(~(lengths > 0)):
            raise ParameterError(f"dropper lengths: need {self.dropper_length.size} positive values (m)")
        self.dropper_length = lengths
        self._lumped = self._lumped_masses()
        self._f_ext = self.system.external_force_value(self.q0) - self._lumped * self.design.gravity * self._z_mask()

    # --- droppers -------------------------------------------------------------------------
    def _dropper_distance(self, q: np.ndarray) -> np.ndarray:
        a = q[self.cw_xyz[self.dropper_nodes]]
        b = q[self.mw_xyz[self.dropper_nodes]]
        return np.linalg.norm(b - a, axis=1)

    def dropper_stiffness(self) -> np.ndarray:
        """Axial stiffness of each dropper (N/m)."""
        d = self.design
        return np.full(self.dropper_length.shape, d.dropper_stiffness) if d.dropper_stiffness > 0 else d.dropper_EA / self.dropper_length

    def dropper_state(self, q: np.ndarray, v: np.ndarray | None = None):
        """Unit vectors CW -> MW, current lengths (m) and tensions (N, >= 0) of the droppers
        (of the states of ``q``'s, and ``v``'s, leading axes: each row a state)."""
        ia, ib = self.cw_xyz[self.dropper_nodes], self.mw_xyz[self.dropper_nodes]
        delta = q[..., ib] - q[..., ia]
        length = np.linalg.norm(delta, axis=-1)
        e = delta / length[..., None]
        tension = self.dropper_stiffness() * (length - self.dropper_length)
        if v is not None and self.design.dropper_damping > 0:
            rate = np.einsum("...ij,...ij->...i", e, v[..., ib] - v[..., ia])
            tension = np.where(tension > 0, tension + self.design.dropper_damping * rate, tension)
        return e, length, np.maximum(tension, 0.0)

    # --- forces ---------------------------------------------------------------------------
    def forces(self, q: np.ndarray, v: np.ndarray | None = None) -> np.ndarray:
        """Total generalized force (N) on the catenary except contact and Rayleigh damping:
        wire elasticity, gravity, end tensions, droppers and support springs."""
        f = (self.system.eval_internal_force(q) if self._linear is None else self._linear(q)) + self._f_ext
        e, _, tension = self.dropper_state(q, v)
        ft = tension[:, None] * e
        ia, ib = self.cw_xyz[self.dropper_nodes], self.mw_xyz[self.dropper_nodes]
        np.add.at(f, ia.ravel(), ft.ravel())
        np.add.at(f, ib.ravel(), -ft.ravel())
        for sup, xyz in ((self.cw_supports, self.cw_xyz), (self.mw_supports, self.mw_xyz)):
            iz = xyz[sup.nodes, 2]
            f[iz] += sup.preload - sup.stiffness * (q[iz] - sup.height)
        return f

    def stiffness(self, q: np.ndarray, droppers_taut: bool | None = None) -> sps.csc_matrix:
        """Tangent stiffness ``-d forces / d q`` (sparse). ``droppers_taut=True`` counts every
        dropper as taut (the iteration matrix of a dynamic run); default: the current state."""
        k = (self.system.eval_tangent_stiffness(q) if self._linear is None else self._k_lin).tocoo()
        rows, cols, vals = [k.row], [k.col], [k.data]
        e, length, tension = self.dropper_state(q)
        kd = self.dropper_stiffness()
        if droppers_taut is None:
            active = (length - self.dropper_length) > 0
            kd = np.where(active, kd, 0.0)
        block = kd[:, None, None] * e[:, :, None] * e[:, None, :] + (tension / length)[:, None, None] * (
            np.eye(3)[None] - e[:, :, None] * e[:, None, :])
        ia, ib = self.cw_xyz[self.dropper_nodes], self.mw_xyz[self.dropper_nodes]
        for ra, ca_, sign in ((ia, ia, 1), (ib, ib, 1), (ia, ib, -1), (ib, ia, -1)):
            rows.append(np.repeat(ra, 3, axis=1).ravel())
            cols.append(np.tile(ca_, (1, 3)).ravel())
            vals.append(sign * block.ravel())
        for sup, xyz in ((self.cw_supports, self.cw_xyz), (self.mw_supports, self.mw_xyz)):
            iz = xyz[sup.nodes, 2]
            rows.append(iz), cols.append(iz), vals.append(np.full(iz.size, sup.stiffness))
        return sps.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(self.n, self.n))

    def linearize_wires(self, q_ref: np.ndarray | None) -> None:
        """Replace the wires' nonlinear elastic forces by their linearization about ``q_ref``
        (typically the static equilibrium), ``f(q_ref) - K(q_ref) (q - q_ref)``; droppers,
        supports and contact stay nonlinear. ``None`` restores the nonlinear wires.

        Around a static catenary the wires move by centimetres, so this is the usual model of
        the field; comparing both tells the size of the geometric nonlinearity.
        """
        if q_ref is None:
            self._linear = None
            return
        q_ref = np.array(q_ref, dtype=float)
        f_ref = self.system.eval_internal_force(q_ref)
        k_ref = self.system.eval_tangent_stiffness(q_ref).tocsr()
        self._k_lin = k_ref
        self._linear = lambda q: f_ref - k_ref @ (q - q_ref)

    @property
    def mass_matrix(self) -> sps.csc_matrix:
        """Consistent wire mass plus lumped masses (kg)."""
        return (self.system.mass_matrix + sps.diags(self._lumped)).tocsc()

    # --- geometry helpers -----------------------------------------------------------------
    def contact_wire_z(self, q: np.ndarray) -> np.ndarray:
        """Contact-wire heights at the stations (m)."""
        return q[self.cw_xyz[:, 2]]

    def running_height(self, x: float) -> float:
        """Design height of the lowest contact wire at ``x`` (m): the wire a pan-head meets."""
        heights = [float(sec.target_height(x)) for sec in self.sections if sec.covers(x)]
        if not heights:
            raise ParameterError(f"x={x:g} m: off the line (0..{self.design.line_length:g} m)")
        return min(heights)
