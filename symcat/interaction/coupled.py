"""Catenary and lumped pantographs coupled by contact, as ``M y'' = F(y, y', t) + contact``.

The unknowns ``y`` are the free catenary coordinates followed by the stage displacements of
each pantograph. Pantograph ``p`` runs at ``speed`` from ``x_start``; its pan-head height is
``z_ref + u_head`` and its penetration into the wire ``delta = z_head - z_wire(x_c(t))``.
Contact is either a penalty (``f = max(k delta + c delta', 0)`` while ``delta > 0``) or a
bilateral constraint ``delta = 0`` with the contact force as multiplier. On a line of several
tension sections a pan-head has one contact candidate per contact wire above it; in an overlap
it presses on both (penalty contact only).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..catenary.formfinding import FormFindingResult, coupled_equilibrium
from ..errors import ParameterError, SolverError
from ..pantograph.lumped import LumpedPantograph
from ..catenary.contact_wire import WireLocator, WirePoint, contact_wire_locators, hermite, point_loads, running_wire

CONTACT_MODELS = ("penalty", "bilateral")


@dataclass(frozen=True)
class PantographRun:
    """A pantograph on the line: its model and where it starts (m along the line)."""

    pantograph: LumpedPantograph
    x_start: float


@dataclass
class ContactState:
    """Contact of one pantograph with one contact wire at one instant."""

    point: WirePoint
    delta: float  # penetration (m), > 0 when pressing into the wire
    delta_rate: float  # m/s
    g: np.ndarray  # d delta / d y on the entries ``g_index``
    g_index: np.ndarray
    slope: float = 0.0  # dz/dx of the wire at the contact point
    pantograph: int = 0
    wire: int = 0  # tension section of the contact wire


class CoupledLine:
    """Catenary + pantographs: mass, damping and iteration stiffness, forces, contact.

    Parameters
    ----------
    form : FormFindingResult
        The catenary in static equilibrium (without pantographs).
    runs : list of PantographRun
    speed : float
        Train speed (m/s); must stay below the contact-wire wave speed.
    contact : str
        ``"penalty"`` or ``"bilateral"``.
    contact_stiffness : float
        Penalty stiffness (N/m).
    contact_damping : float
        Penalty damping (N s/m), acting only while in contact; the force never pulls.
    """

    def __init__(self, form: FormFindingResult, runs: list[PantographRun], speed: float, contact: str = "penalty",
                 contact_stiffness: float = 5.0e4, contact_damping: float = 0.0):
        st = form.structure
        d = st.design
        if contact not in CONTACT_MODELS:
            raise ParameterError(f"contact={contact!r}: must be one of {', '.join(CONTACT_MODELS)}")
        if not 0 < speed < d.wave_speed:
            raise ParameterError(f"speed={speed:g} m/s ({speed * 3.6:g} km/h): must be > 0 and below the contact-wire "
                                 f"wave speed {d.wave_speed:.1f} m/s ({d.wave_speed * 3.6:.1f} km/h)")
        if contact == "penalty" and not contact_stiffness > 0:
            raise ParameterError(f"contact_stiffness={contact_stiffness:g} N/m: must be > 0")
        if contact_damping < 0:
            raise ParameterError(f"contact_damping={contact_damping:g} N s/m: must be >= 0")
        for k, run in enumerate(runs):
            if not 0 <= run.x_start <= d.line_length:
                raise ParameterError(f"pantograph {k + 1} x_start={run.x_start:g} m: off the wire; must be within "
                                     f"0..{d.line_length:g} m")
        if contact == "bilateral" and d.n_sections > 1:
            raise ParameterError(f"contact='bilateral' with n_sections={d.n_sections}: a pan-head cannot stay on both "
                                 "wires of an overlap; use contact='penalty'")
        self.form, self.structure, self.runs = form, st, list(runs)
        self.speed, self.contact = float(speed), contact
        self.k_c, self.c_c = float(contact_stiffness), float(contact_damping)
        self.q_static = form.q.copy()
        self.free = st.free
        self.n_cat = self.free.size
        self.in_free = np.full(st.n, -1)
        self.in_free[self.free] = np.arange(self.n_cat)
        offsets = np.cumsum([self.n_cat] + [r.pantograph.n for r in runs])
        self.panto_slices = [slice(a, b) for a, b in zip(offsets[:-1], offsets[1:])]
        self.head_index = np.array([s.stop - 1 for s in self.panto_slices], dtype=int)
        self.n = int(offsets[-1])
        self.locators = contact_wire_locators(st)
        self.z_ref = np.array([st.running_height(r.x_start) for r in runs])
        self._matrices()

    # --- constant matrices ----------------------------------------------------------------
    def _matrices(self) -> None:
        st, f = self.structure, self.free
        m_cat = st.mass_matrix[f][:, f]
        k_cat = st.stiffness(self.q_static, droppers_taut=True)[f][:, f]
        d = st.design
        c_cat = d.rayleigh_alpha * m_cat + d.rayleigh_beta * k_cat
        blocks = [r.pantograph.matrices() for r in self.runs]
        self.M = sps.block_diag([m_cat] + [b[0] for b in blocks], format="csc")
        self.C = sps.block_diag([c_cat] + [b[1] for b in blocks], format="csc")
        self.K = sps.block_diag([k_cat] + [b[2] for b in blocks], format="csc")
        self.C_cat = c_cat.tocsr()
        self.M_csr, self.C_csr = self.M.tocsr(), self.C.tocsr()  # faster products in the time loop
        self.K_panto = [b[2] for b in blocks]
        self.C_panto = [b[1] for b in blocks]
        self.f_panto = [r.pantograph.static_force(self.speed) for r in self.runs]

    def catenary_q(self, y: np.ndarray) -> np.ndarray:
        """Full catenary coordinates from ``y``."""
        q = self.q_static.copy()
        q[self.free] = y[: self.n_cat]
        return q

    def x_contact(self, t: float) -> np.ndarray:
        """Pan-head positions along the line at time ``t`` (m)."""
        return np.array([r.x_start + self.speed * t for r in self.runs])

    # --- forces ---------------------------------------------------------------------------
    def contact_states(self, y: np.ndarray, y_dot: np.ndarray, t: float) -> list[ContactState]:
        q = self.catenary_q(y)
        states = []
        sections = self.structure.sections
        for p, x in enumerate(self.x_contact(t)):
            for w, sec in enumerate(sections):
                if not sec.covers(x):
                    continue
                locator = self.locators[w]
                point = locator.locate(q, x)
                z_w = point.height(q)
                head = self.head_index[p]
                delta = self.z_ref[p] + y[head] - z_w
                pos = self.in_free[point.index]
                keep = pos >= 0
                v_full = np.zeros(4)
                v_full[keep] = y_dot[pos[keep]]
                slope = self._slope(q, point, locator)
                rate = y_dot[head] - point.weights @ v_full - slope * self.speed
                g_index = np.concatenate([[head], pos[keep]])
                g = np.concatenate([[1.0], -point.weights[keep]])
                states.append(ContactState(point, float(delta), float(rate), g, g_index, slope, p, w))
        return states

    @staticmethod
    def _slope(q: np.ndarray, point: WirePoint, locator: WireLocator) -> float:
        """dz/dx of the contact wire at the contact point."""
        k, length = point.element, locator.lengths[point.element]
        _, dn = hermite(point.xi)
        lz = np.array([1.0, length, 1.0, length])
        cz = q[point.index] * lz
        ix = [locator.x_index[k], locator.xx_index[k], locator.x_index[k + 1], locator.xx_index[k + 1]]
        cx = q[ix] * lz
        return float((dn @ cz) / (dn @ cx))

    def per_pantograph(self, states: list[ContactState], forces) -> np.ndarray:
        """Total contact force (N) on each pan-head from per-wire contact forces."""
        out = np.zeros(len(self.runs))
        for s, f in zip(states, forces):
            out[s.pantograph] += f
        return out

    def per_wire(self, states: list[ContactState], forces) -> np.ndarray:
        """Contact force (N) of each pan-head on each section's contact wire (n_panto, n_sections)."""
        out = np.zeros((len(self.runs), len(self.structure.sections)))
        for s, f in zip(states, forces):
            out[s.pantograph, s.wire] += f
        return out

    def penalty_force(self, state: ContactState) -> float:
        """Contact force (N, >= 0) of the penalty law."""
        if state.delta <= 0:
            return 0.0
        return max(self.k_c * state.delta + self.c_c * state.delta_rate, 0.0)

    def forces(self, y: np.ndarray, y_dot: np.ndarray, t: float, states=None,
               contact_forces=None) -> tuple[np.ndarray, list[ContactState], np.ndarray]:
        """Generalized force ``F`` (N) including contact; returns (F, contact states, contact forces).

        For bilateral contact pass the multipliers as ``contact_forces``.
        """
        q = self.catenary_q(y)
        v = np.zeros(self.structure.n)
        v[self.free] = y_dot[: self.n_cat]
        out = np.empty(self.n)
        out[: self.n_cat] = self.structure.forces(q, v)[self.free] - self.C_cat @ y_dot[: self.n_cat]
        for p, sl in enumerate(self.panto_slices):
            out[sl] = self.f_panto[p] - self.K_panto[p] @ y[sl] - self.C_panto[p] @ y_dot[sl]
        if states is None:
            states = self.contact_states(y, y_dot, t)
        if contact_forces is None:
            contact_forces = np.array([self.penalty_force(s) for s in states])
        for s, fc in zip(states, contact_forces):
            np.add.at(out, s.g_index, -fc * s.g)
        return out, states, np.asarray(contact_forces, dtype=float)

    # --- energy ---------------------------------------------------------------------------
    def energy(self, y: np.ndarray, y_dot: np.ndarray, t: float) -> dict[str, float]:
        """Kinetic and potential energy (J) of catenary, pantographs and penalty contact.

        The potential's gradient is minus the conservative forces: wire strain energy, gravity
        and end tensions (constant loads), tension-only droppers, preloaded support springs,
        pantograph springs and static forces, the penalty spring. Its explicit time dependence
        (the contact point moves) is the work done on the system, ``-f_c slope v`` per contact.
        """
        st = self.structure
        q = self.catenary_q(y)
        strain = st.system.strain_energy(q) if st._linear is None else float(
            -st._linear(q) @ (q - self.q_static) * 0.5 - st._linear(self.q_static) @ (q - self.q_static) * 0.5)
        ext = -float(st._f_ext @ (q - self.q_static))
        _, length, _ = st.dropper_state(q)
        stretch = np.maximum(length - st.dropper_length, 0.0)
        droppers = float(0.5 * np.sum(st.dropper_stiffness() * stretch**2))
        supports = 0.0
        for sup, xyz in ((st.cw_supports, st.cw_xyz), (st.mw_supports, st.mw_xyz)):
            z = q[xyz[sup.nodes, 2]]
            supports += float(np.sum(0.5 * sup.stiffness * (z - sup.height) ** 2 - sup.preload * z))
        panto = 0.0
        for p, sl in enumerate(self.panto_slices):
            u = y[sl]
            panto += float(0.5 * u @ self.K_panto[p] @ u - self.f_panto[p] @ u)
        contact = 0.0
        if self.contact == "penalty":
            for s in self.contact_states(y, y_dot, t):
                contact += 0.5 * self.k_c * max(s.delta, 0.0) ** 2
        kinetic = float(0.5 * y_dot @ (self.M @ y_dot))
        potential = strain + ext + droppers + supports + panto + contact
        return {"kinetic_J": kinetic, "potential_J": potential, "total_J": kinetic + potential}

    def dissipation_power(self, y_dot: np.ndarray) -> float:
        """Power dissipated by Rayleigh and pantograph dampers (W); dropper and contact
        dampers are not included."""
        return float(y_dot @ (self.C_csr @ y_dot))

    # --- static equilibrium ---------------------------------------------------------------
    def _place_pantographs(self, y: np.ndarray, load: np.ndarray) -> None:
        """Solve the catenary under the static contact forces ``load`` (N) and set each
        pantograph's reference height so that it stands there with exactly that force: the
        static uplift is the static contact force, as the standards define it."""
        q0 = self.catenary_q(y)
        wires = [self._running_wire(q0, x) for x in self.x_contact(0.0)]  # fixed: Newton needs a smooth load

        # the contact forces on the running wire, at the pan-heads' positions
        loads = point_loads(self.structure.n, self.locators, wires, self.x_contact(0.0), load)
        y[: self.n_cat] = coupled_equilibrium(self.structure, self.catenary_q(y), loads)[self.free]
        q = self.catenary_q(y)
        for p, (run, sl) in enumerate(zip(self.runs, self.panto_slices)):
            m, c, k = run.pantograph.matrices()
            rhs = self.f_panto[p].copy()
            rhs[-1] -= load[p]
            u = np.linalg.lstsq(k, rhs, rcond=None)[0]
            y[sl] = u
            gap = load[p] / self.k_c if self.contact == "penalty" else 0.0
            point = self.locators[wires[p]].locate(q, self.x_contact(0.0)[p])
            self.z_ref[p] = point.height(q) + gap - u[-1]

    def _running_wire(self, q: np.ndarray, x: float) -> int:
        """The section whose contact wire is lowest at ``x`` (the one in running)."""
        return running_wire(self.structure, self.locators, q, x)

    def static_state(self, rtol: float = 1e-9, max_iterations: int = 40,
                     z_ref: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Static equilibrium with the pantographs pressing at their start positions.

        Returns ``(y, contact_forces)``. Newton's method on the tangent with the current dropper
        states; the bilateral model solves for the multipliers with ``delta = 0``. By default
        each pantograph's reference height is placed so that it presses with its static force;
        ``z_ref`` (m, one per pantograph) keeps given reference heights instead (a pantograph
        that has travelled from elsewhere, so its frame spring sets the force).
        """
        y = np.zeros(self.n)
        y[: self.n_cat] = self.q_static[self.free]
        zero = np.zeros(self.n)
        lam = np.array([r.pantograph.static_force(self.speed).sum() for r in self.runs], dtype=float)
        self._place_pantographs(y, lam)
        if z_ref is not None:
            self.z_ref = np.array(z_ref, dtype=float)
        lam = lam.copy()
        scale = max(1.0, float(np.abs(self.structure._f_ext).max()))
        for it in range(max_iterations):
            states = self.contact_states(y, zero, 0.0)
            if self.contact == "penalty":
                f, states, fc = self.forces(y, zero, 0.0, states)
            else:
                f, states, fc = self.forces(y, zero, 0.0, states, lam)
            k_cat = self.structure.stiffness(self.catenary_q(y))[self.free][:, self.free]
            k = sps.block_diag([k_cat] + self.K_panto, format="lil")
            g = sps.lil_matrix((self.n, len(states)))
            for p, s in enumerate(states):
                g[s.g_index, p] = s.g[:, None]
                if self.contact == "penalty" and s.delta > 0:
                    k[np.ix_(s.g_index, s.g_index)] = k[np.ix_(s.g_index, s.g_index)].toarray() + self.k_c * np.outer(s.g, s.g)
            delta = np.array([s.delta for s in states])
            done = np.abs(f).max() < rtol * scale and (self.contact == "penalty" or np.abs(delta).max() < 1e-12)
            if done:
                return y, fc
            if self.contact == "penalty":
                dy = spla.spsolve(k.tocsc(), f)
            else:
                kkt = sps.bmat([[k.tocsc(), g.tocsc()], [g.T.tocsc(), None]], format="csc")
                sol = spla.spsolve(kkt, np.concatenate([f, -delta]))
                dy = sol[: self.n]
                lam = lam + sol[self.n:]
            y += dy
            if np.abs(dy).max() < 1e-8 and np.abs(f).max() < 1e-6 * scale:  # at round-off
                return y, self.forces(y, zero, 0.0, None, lam if self.contact == "bilateral" else None)[2]
        raise SolverError(f"static equilibrium with pantographs: residual {np.abs(f).max():.3g} N after {max_iterations} "
                          "iterations; check the pantograph start positions and uplift forces")
