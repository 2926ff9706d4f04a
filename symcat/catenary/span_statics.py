"""Statics of a catenary's wires, written apart from the form finding (SI units).

A check on :mod:`symcat.catenary.formfinding`, a tool to ask which convention a published set
of dropper lengths follows, and the source of dropper lengths cut "as for flexible wires"
(``CatenaryDesign.dropper_statics="strings"``). It shares no code with the finite-element form
finding: each wire is a tensioned Euler-Bernoulli beam ``EI w'''' - H w'' = -q`` along the line
(``w`` up, ``q`` the weight per horizontal metre, ``H`` the horizontal tension), solved in
closed form between its nodes; ``bending=False`` takes the wires as perfectly flexible strings
(the beam with a vanishing bending length ``sqrt(EI / H)``).

The contact wire is pinned at its design height at the droppers, at the anchors and (with
``steady_arm="held"``) at the supports; the reactions there are the dropper tensions and the
steady-arm forces. The messenger is pinned at its supports and anchors and carries its weight,
the clamps, half of each dropper and the dropper tensions. A dropper's unstretched length is
the distance between the wires less its elastic stretch. :func:`span_statics` takes the
interior span of a long tension section as periodic (the spans before and after it are the
same); :func:`section_statics` solves one whole tension section between its anchors.

Only vertical statics: the droppers hang vertically (the form finding keeps the wires at their
stations) and the stagger's effect on lengths (parts per 10^5) is left out. The weight of a
wire is per length of wire, so per horizontal metre it is ``m g sqrt(1 + w'^2)`` (averaged
over each stretch between nodes, iterated with the shape).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from ..errors import ParameterError, SolverError
from .design import STEADY_ARM_CONVENTIONS, CatenaryDesign, Wire

#: Bending length (m) that stands for a perfectly flexible wire (``bending=False``): the
#: bending effects it leaves are ``slope * length`` (below 1e-7 m here).
STRING_BENDING_LENGTH = 1e-6


@dataclass(frozen=True)
class _Line:
    """A tensioned beam solved on the stretches between its nodes.

    On stretch ``k`` (from ``x[k]`` to ``x[k+1]``, length ``l``, local ``s``) the deflection is
    ``a0 + a1 s + lam^2 (a2 exp(-s/lam) + a3 exp(-(l-s)/lam)) + q s^2 / (2 H)`` with
    ``lam = sqrt(EI / H)``; ``coef[k]`` holds ``a0..a3``. ``x`` ends with the line's end
    (for a periodic line, one period after ``x[0]``).
    """

    x: np.ndarray
    q: np.ndarray
    H: float
    lam: float
    coef: np.ndarray

    @property
    def n_stretches(self) -> int:
        return self.x.size - 1

    def _exp(self, k: int, s: float):
        l = self.x[k + 1] - self.x[k]
        return math.exp(-s / self.lam), math.exp(-(l - s) / self.lam)

    def height(self, k: int, s: float) -> float:
        """Deflection on stretch ``k`` at local position ``s`` (m)."""
        e0, e1 = self._exp(k, s)
        a0, a1, a2, a3 = self.coef[k]
        return a0 + a1 * s + self.lam**2 * (a2 * e0 + a3 * e1) + self.q[k] * s * s / (2 * self.H)

    def slope(self, k: int, s: float) -> float:
        """Slope on stretch ``k`` at local position ``s`` (-)."""
        e0, e1 = self._exp(k, s)
        _, a1, a2, a3 = self.coef[k]
        return a1 + self.lam * (-a2 * e0 + a3 * e1) + self.q[k] * s / self.H

    def shear(self, k: int, s: float) -> float:
        """Vertical force of the wire beyond ``s`` on the wire before it, ``H w' - EI w'''`` (N)."""
        return self.H * self.coef[k][1] + self.q[k] * s

    def node_heights(self) -> np.ndarray:
        """Deflection at the nodes (m), the line's end included."""
        k_last = self.n_stretches - 1
        heights = [self.height(k, 0.0) for k in range(self.n_stretches)]
        return np.array(heights + [self.height(k_last, self.x[-1] - self.x[-2])])

    def node_force_jumps(self, periodic: bool) -> np.ndarray:
        """``F(x+) - F(x-)`` at each node but the line's end (N): the load there less the
        upward reaction. A line's first node has nothing before it unless it is periodic."""
        n = self.n_stretches
        out = []
        for k in range(n):
            before = self.shear(k - 1, self.x[k] - self.x[k - 1]) if k > 0 else (
                self.shear(n - 1, self.x[-1] - self.x[-2]) if periodic else 0.0)
            out.append(self.shear(k, 0.0) - before)
        return np.array(out)

    def end_force(self) -> float:
        """Upward reaction at the line's end (N) when it is an anchor."""
        return self.shear(self.n_stretches - 1, self.x[-1] - self.x[-2])

    def weight_factors(self) -> np.ndarray:
        """Mean of ``sqrt(1 + w'^2)`` over each stretch (Simpson's rule): wire length per metre."""
        out = []
        for k in range(self.n_stretches):
            l = self.x[k + 1] - self.x[k]
            f = [math.sqrt(1 + self.slope(k, s) ** 2) for s in (0.0, 0.5 * l, l)]
            out.append((f[0] + 4 * f[1] + f[2]) / 6)
        return np.array(out)


def _end_rows(x, k, lam, s_end: bool):
    """Coefficient rows of (w, w', w'', F/H) at the start (or end) of stretch ``k``."""
    l = x[k + 1] - x[k]
    e = math.exp(-l / lam)
    c = 4 * k
    cols = np.arange(c, c + 4)
    if s_end:
        vals = [[1.0, l, lam**2 * e, lam**2], [0.0, 1.0, -lam * e, lam], [0.0, 0.0, e, 1.0], [0.0, 1.0, 0.0, 0.0]]
    else:
        vals = [[1.0, 0.0, lam**2, lam**2 * e], [0.0, 1.0, -lam, lam * e], [0.0, 0.0, 1.0, e], [0.0, 1.0, 0.0, 0.0]]
    return cols, np.array(vals)


def _constants(x, k, q, H, s_end: bool):
    """The load's part of (w, w', w'', F/H) at the start (or end) of stretch ``k``."""
    l = x[k + 1] - x[k]
    if s_end:
        return np.array([q[k] * l * l / (2 * H), q[k] * l / H, q[k] / H, q[k] * l / H])
    return np.array([0.0, 0.0, q[k] / H, 0.0])


def solve_line(x, pinned, z, load, q, wire_H: float, EI: float, periodic: bool) -> _Line:
    """Solve a tensioned beam over the nodes ``x`` (see :class:`_Line`).

    Parameters
    ----------
    x : ndarray
        Node positions (m), increasing; the last is the line's end (for ``periodic``, one
        period after the first, the same node).
    pinned : ndarray of bool
        For every node but the last: held at height ``z`` (m); the others carry the downward
        point ``load`` (N). A non-periodic line is pinned at both ends (``z[-1]`` the end's
        height) with no moment there.
    q : ndarray
        Downward weight per horizontal metre on each stretch (N/m).
    wire_H, EI : float
        Horizontal tension (N) and bending stiffness (N m^2).
    periodic : bool
        Whether the line repeats itself after its last stretch (an interior span).
    """
    x = np.asarray(x, float)
    n = x.size - 1
    lam = math.sqrt(EI / wire_H)
    rows, cols, vals, b = [], [], [], np.zeros(4 * n)

    def put(row, c, v):
        rows.extend([row] * len(c))
        cols.extend(c)
        vals.extend(v)

    for i in range(n):
        c0, r0 = _end_rows(x, i, lam, False)
        k0 = _constants(x, i, q, wire_H, False)
        base = 4 * i
        if i > 0 or periodic:
            j = (i - 1) % n
            c1, r1 = _end_rows(x, j, lam, True)
            k1 = _constants(x, j, q, wire_H, True)
            for m in range(3):  # w, w', w'' continuous across node i
                put(base + m, list(c0) + list(c1), list(r0[m]) + list(-r1[m]))
                b[base + m] = k1[m] - k0[m]
            if pinned[i]:
                put(base + 3, c0, r0[0])
                b[base + 3] = z[i] - k0[0]
            else:  # F(x+) - F(x-) = load
                put(base + 3, list(c0) + list(c1), list(r0[3]) + list(-r1[3]))
                b[base + 3] = load[i] / wire_H - (k0[3] - k1[3])
        else:  # first anchor: pinned, no moment; the last anchor the same
            put(base, c0, r0[0])
            b[base] = z[0] - k0[0]
            put(base + 1, c0, r0[2])
            b[base + 1] = -k0[2]
            c1, r1 = _end_rows(x, n - 1, lam, True)
            k1 = _constants(x, n - 1, q, wire_H, True)
            put(base + 2, c1, r1[0])
            b[base + 2] = z[-1] - k1[0]
            put(base + 3, c1, r1[2])
            b[base + 3] = -k1[2]
    a = sps.csc_matrix((vals, (rows, cols)), shape=(4 * n, 4 * n))
    coef = spla.spsolve(a, b)
    if not np.all(np.isfinite(coef)):
        raise SolverError("wire statics: singular system; a wire needs at least one pinned node")
    return _Line(x, np.asarray(q, float), float(wire_H), lam, coef.reshape(n, 4))


@dataclass(frozen=True)
class WireStatics:
    """Static state from :func:`span_statics` or :func:`section_statics` (heights in m, forces in N).

    Attributes
    ----------
    dropper_x_m : ndarray
        Dropper positions (m): from the span's first support (span) or from the line's first
        support (section).
    dropper_length_m : ndarray
        Unstretched dropper lengths (m).
    dropper_tension_N : ndarray
        Dropper tensions at the contact-wire clamp (N).
    contact_wire_z_m, messenger_z_m : ndarray
        Heights of the wires at the droppers (m).
    support_x_m : ndarray
        Positions of the supports with a steady arm (m): the span's first (span), or the
        section's inner supports (section).
    contact_wire_support_z_m : ndarray
        Contact-wire heights there (m).
    steady_arm_force_N, messenger_support_force_N : ndarray
        Upward forces of the steady arms and messenger supports there (N).
    steady_arm : str
        The convention used (see :class:`~symcat.catenary.design.CatenaryDesign`).
    bending : bool
        Whether the wires' bending stiffness was counted.
    """

    dropper_x_m: np.ndarray
    dropper_length_m: np.ndarray
    dropper_tension_N: np.ndarray
    contact_wire_z_m: np.ndarray
    messenger_z_m: np.ndarray
    support_x_m: np.ndarray
    contact_wire_support_z_m: np.ndarray
    steady_arm_force_N: np.ndarray
    messenger_support_force_N: np.ndarray
    steady_arm: str
    bending: bool


@dataclass(frozen=True)
class _Layout:
    """Nodes of a line of wire: positions, which are supports, which are droppers, heights."""

    x: np.ndarray            # nodes, the line's end included
    support: np.ndarray      # node indices of the inner supports (steady arms, messenger supports)
    drop: np.ndarray         # node indices of the droppers
    cw_z: np.ndarray         # contact-wire design heights at the nodes
    mw_support_z: np.ndarray  # messenger heights at the supports and anchors (node order)
    anchors: np.ndarray      # node indices of the messenger's pins (supports and anchors)
    periodic: bool


def _effective_EI(wire: Wire, bending: bool) -> float:
    return wire.EI if bending else wire.tension * STRING_BENDING_LENGTH**2


def _solve(d: CatenaryDesign, lay: _Layout, steady_arm: str, bending: bool, tol: float,
           max_iterations: int) -> WireStatics:
    """Dropper lengths, tensions and heights of one line of wire (module docstring)."""
    if steady_arm not in STEADY_ARM_CONVENTIONS:
        raise ParameterError(f"steady_arm={steady_arm!r}: must be one of {', '.join(STEADY_ARM_CONVENTIONS)}")
    g, cw, mw = d.gravity, d.contact_wire, d.messenger_wire
    n_nodes = lay.x.size - 1  # nodes with a stretch after them
    drop, sup = lay.drop, lay.support
    length0 = np.full(drop.size, d.encumbrance)
    cw_factor = np.ones(n_nodes)
    mw_factor = np.ones(n_nodes)
    cw_EI, mw_EI = _effective_EI(cw, bending), _effective_EI(mw, bending)
    for _ in range(max_iterations):
        half = 0.5 * d.dropper_mass_per_length * length0 * g
        pinned = np.zeros(n_nodes, bool)
        pinned[drop] = True
        pinned[sup] = steady_arm == "held"
        if not lay.periodic:
            pinned[0] = True
        load = np.zeros(n_nodes)
        load[drop] = d.clamp_mass_contact * g + half
        load[sup] = d.steady_arm_mass * g
        contact = solve_line(lay.x, pinned, lay.cw_z, load, cw.mass_per_length * g * cw_factor, cw.tension, cw_EI,
                             lay.periodic)
        reaction = load - contact.node_force_jumps(lay.periodic)
        tension = reaction[drop]
        if np.any(tension <= 0):
            j = int(np.argmin(tension))
            raise ParameterError(f"presag: the target needs the dropper at x={lay.x[drop[j]]:g} m in compression "
                                 f"(tension {tension[j]:.1f} N)")
        cw_z = contact.node_heights()
        pinned = np.zeros(n_nodes, bool)
        pinned[lay.anchors[lay.anchors < n_nodes]] = True
        z = np.zeros(lay.x.size)
        z[lay.anchors] = lay.mw_support_z
        load = np.zeros(n_nodes)
        load[drop] = tension + d.clamp_mass_messenger * g + half
        messenger = solve_line(lay.x, pinned, z, load, mw.mass_per_length * g * mw_factor, mw.tension, mw_EI,
                               lay.periodic)
        mw_z = messenger.node_heights()
        distance = mw_z[drop] - cw_z[drop]
        if np.any(distance <= 0):
            raise ParameterError(f"encumbrance={d.encumbrance:g} m: the messenger sags below the contact wire")
        if d.dropper_stiffness > 0:
            new_length0 = distance - tension / d.dropper_stiffness
        else:
            new_length0 = distance / (1 + tension / d.dropper_EA)
        change = np.max(np.abs(new_length0 - length0))
        length0 = new_length0
        cw_factor, mw_factor = contact.weight_factors(), messenger.weight_factors()
        if change < tol:
            steady = reaction[sup] if steady_arm == "held" else np.zeros(sup.size)
            mw_support = -messenger.node_force_jumps(lay.periodic)[sup]
            return WireStatics(lay.x[drop], length0, tension, cw_z[drop], mw_z[drop], lay.x[sup], cw_z[sup],
                               steady, mw_support, steady_arm, bending)
    raise SolverError(f"wire statics: dropper lengths still changed by {change:.3g} m after {max_iterations} iterations")


def span_statics(design: CatenaryDesign, steady_arm: str | None = None, bending: bool = True,
                 tol: float = 1e-12, max_iterations: int = 50) -> WireStatics:
    """Statics of an interior span of a long tension section of ``design`` (periodic).

    Parameters
    ----------
    design : CatenaryDesign
        The catenary; its stagger, overlaps, damping and support stiffnesses play no part.
    steady_arm : str, optional
        ``"held"`` or ``"free"`` (see ``CatenaryDesign.steady_arm``); default: the design's.
    bending : bool
        Count the wires' bending stiffness (default) or take them as flexible strings.
    tol : float
        Convergence of the dropper lengths between iterations (m).

    Raises
    ------
    ParameterError
        If ``steady_arm`` is not a known convention, or a dropper would be in compression.
    SolverError
        If the dropper lengths do not settle.
    """
    d = design
    xd = np.asarray(d.dropper_positions, float)
    x = np.concatenate([[0.0], xd, [d.span_length]])
    z = np.concatenate([[d.target_height(0.0)], d.target_height(xd), [d.target_height(0.0)]])
    lay = _Layout(x, np.array([0]), np.arange(1, xd.size + 1), z, np.array([float(z[0]) + d.encumbrance] * 2),
                  np.array([0, x.size - 1]), periodic=True)
    return _solve(d, lay, d.steady_arm if steady_arm is None else steady_arm, bending, tol, max_iterations)


def section_statics(design: CatenaryDesign, section: int = 0, steady_arm: str | None = None, bending: bool = True,
                    tol: float = 1e-12, max_iterations: int = 50) -> WireStatics:
    """Statics of tension section ``section`` of ``design`` between its anchors.

    The anchors hold both wires at their design heights (the contact wire at its target, the
    messenger ``encumbrance`` above it), as the form finding's anchors do. Overlaps (lifted
    wires) follow the section's geometry (:mod:`symcat.catenary.sections`). Parameters and
    errors as :func:`span_statics`.
    """
    d = design
    sections = d.sections()
    if not (int(section) == section and 0 <= section < len(sections)):
        raise ParameterError(f"section={section}: must be an integer from 0 to {len(sections) - 1}")
    sec = sections[int(section)]
    sx, dx = sec.support_x(), sec.dropper_x()
    x = np.concatenate([sx, dx])
    order = np.argsort(x, kind="stable")
    x = x[order]
    rank = np.empty(order.size, int)
    rank[order] = np.arange(order.size)
    anchors = rank[: sx.size]
    lay = _Layout(x, anchors[1:-1], rank[sx.size:], sec.target_height(x), sec.messenger_support_height(), anchors,
                  periodic=False)
    return _solve(d, lay, d.steady_arm if steady_arm is None else steady_arm, bending, tol, max_iterations)
