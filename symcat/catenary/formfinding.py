"""Static form finding: dropper lengths that make the contact wire hang at its design height.

1. The contact wire alone, held at its target height at every dropper and (with the design's
   ``steady_arm="held"``) at every support, carries its weight, the clamps and half of each
   dropper; the vertical reactions there are the dropper tensions and the steady-arm preloads.
   With ``steady_arm="free"`` the steady arms carry nothing in the static state: the wire hangs
   freely across each support between the droppers on either side, and the steady-arm springs
   are set unloaded at the height it takes there.
2. The messenger, held at the supports, carries its weight and those dropper tensions; its
   shape gives the dropper directions and lengths.
3. Steps 1-2 repeat with the dropper directions (not quite vertical once the wires stretch)
   until the lengths settle; the unstretched length of a dropper is its length less its
   elastic stretch under its tension.
4. The assembled catenary with these droppers and support preloads is solved once more as a
   whole (a check: it must stay at the design height) and is the starting state of every run.

With ``dropper_statics="strings"`` the dropper lengths and support forces of steps 1-3 are
replaced by those of perfectly flexible wires (:func:`symcat.catenary.span_statics.section_statics`
with ``bending=False``, the usual design calculation) before step 4; the model's wires, stiff in
bending, then hold the contact wire a few millimetres off its design height, which
``height_error_m`` reports.
"""
from __future__ import annotations

import copy
import time
from dataclasses import dataclass

import numpy as np

from ..analysis.statics import solve_static
from ..assembly.banded import BandedCholesky
from ..assembly.system import System
from ..errors import ParameterError, SolverError
from ..progress import Status
from ..scene import NodalForce, Scene
from ..threads import serially
from .design import CatenaryDesign
from .structure import CatenaryStructure


@dataclass
class FormFindingResult:
    """Outcome of :func:`find_form`.

    Attributes
    ----------
    structure : CatenaryStructure
        The catenary with dropper lengths and support preloads set.
    q : ndarray
        Static equilibrium of the whole catenary (m, -).
    dropper_length_m, dropper_tension_N : ndarray
        Unstretched lengths and static tensions of all droppers.
    height_error_m : float
        Largest deviation of the contact wire from its target height at the droppers and (with
        ``steady_arm="held"``) the supports in the final coupled equilibrium: round-off for
        ``dropper_statics="wires"``, millimetres for ``"strings"`` (the bending stiffness the
        flexible-wire droppers leave out, and the mesh).
    iterations : int
        Contact/messenger iterations.
    wall_s : float
    """

    structure: CatenaryStructure
    q: np.ndarray
    dropper_length_m: np.ndarray
    dropper_tension_N: np.ndarray
    height_error_m: float
    iterations: int
    wall_s: float


def _solve_wire(body, fixed_nodes, loads, gravity) -> tuple[np.ndarray, np.ndarray, System]:
    """Static equilibrium of one wire with the given pins and loads; returns (nodes, reactions)."""
    body = copy.deepcopy(body)
    body.fixed.clear()
    for node, coords in fixed_nodes:
        body.fix(int(node), coords)
    scene = Scene(gravity=(0.0, 0.0, -gravity))
    scene.add(body)
    for node, force in loads:
        scene.add(NodalForce(body.name, int(node), tuple(float(f) for f in force)))
    system = System(scene)
    result = solve_static(system, rtol=1e-11, max_iterations=30)
    residual, _ = system.eval_static(result.q, 1.0)
    reactions = -residual.reshape(body.q0.shape)
    return result.q.reshape(body.q0.shape), reactions, system


def _balance_axial_forces(body, nodes: np.ndarray, reactions_x: np.ndarray, wire) -> None:
    """Adopt the solved shape and correct each element's stress-free length so that the pins
    along the line carry no force: element e must then carry the horizontal force of the loads
    beyond it, so its tension changes by minus the sum of the pin reactions beyond it. Without
    the pins the wire then keeps its stations and the droppers hang vertically, as installed
    (otherwise the sag-induced shortening piles up span after span along a long section)."""
    names = body.element.param_names
    chord = np.linalg.norm(np.diff(nodes[:, :3], axis=0), axis=1)
    cos = np.abs(np.diff(nodes[:, 0])) / chord
    beyond = np.cumsum(reactions_x[::-1])[::-1][1:]  # sum over nodes e+1..N
    col = names.index("prestrain")
    body.params[:, col] += -beyond / (wire.EA * cos)
    body.params[:, names.index("rho")] = wire.mass_per_length * (1 + body.params[:, col]) / body.params[:, names.index("A")]
    body.q0[:] = nodes


@serially
def find_form(design: CatenaryDesign, elements_per_span: int, element: str = "cable3d", tol: float = 1e-8,
              max_iterations: int = 30, progress: bool = True) -> FormFindingResult:
    """Dropper lengths and static equilibrium for ``design`` (see the module docstring);
    ``progress`` shows the iterations on stderr when they take more than two seconds.

    The tension sections of a line are independent until a pantograph couples them, so each
    is form-found on its own; the final check solves them together.

    Raises
    ------
    ParameterError
        If the presag target needs a dropper in compression or the messenger hangs below the
        contact wire (the design cannot be reached).
    """
    t0 = time.perf_counter()
    status = Status("form finding", enabled=progress)
    try:
        st = CatenaryStructure(design, elements_per_span, element)
        n_inner = design.n_spans - 1
        lengths, iterations = [], 0
        for k, sec in enumerate(st.sections):
            out = _form_section(st, k, tol, max_iterations, status)
            if design.dropper_statics == "strings":
                out = _string_droppers(design, k, out)
            lengths.append(out[0])
            rows = slice(k * n_inner, (k + 1) * n_inner)
            st.cw_supports.preload[rows], st.mw_supports.preload[rows], st.mw_supports.height[rows] = out[1:4]
            st.cw_supports.height[rows] = out[4]
            iterations = max(iterations, out[5])
        length0 = np.concatenate(lengths)
        st._build_system()
        st.set_dropper_lengths(length0)
        status.show("the static equilibrium of the whole line")
        q = _static_state(st)
    finally:
        status.close()
    nodes = st.dropper_nodes if design.steady_arm == "free" else np.concatenate([st.dropper_nodes, st.cw_supports.nodes])
    height_error = float(np.max(np.abs(st.contact_wire_z(q)[nodes] - st.target_z[nodes])))
    _, _, tension = st.dropper_state(q)
    return FormFindingResult(st, q, length0, tension, height_error, iterations, time.perf_counter() - t0)


def _form_section(st: CatenaryStructure, k: int, tol: float, max_iterations: int, status: Status | None = None):
    """Form finding of tension section ``k`` (steps 1-3); returns the unstretched dropper
    lengths, the steady-arm and messenger-support preloads, the messenger support heights, the
    contact-wire heights at the inner supports and the number of iterations."""
    d = st.design
    sec = st.sections[k]
    cw_body, mw_body = st.contacts[k], st.messengers[k]
    drop, sup = st._local["drop"], st._local["support"]
    inner = sup[1:-1]
    held = d.steady_arm == "held"
    n_nodes = cw_body.n_nodes
    pos = lambda nodes: nodes[:, :3]
    direction = np.tile([0.0, 0.0, 1.0], (drop.size, 1))
    tension = np.zeros(drop.size)
    length0 = np.full(drop.size, d.encumbrance)
    beam_extra = ["z_y", "y_z"] if st.element == "beam3d" else []
    support_height = sec.messenger_support_height()
    last_change = np.inf
    for iteration in range(1, max_iterations + 1):
        if status is not None:
            sections = f"tension section {k + 1} of {len(st.sections)}, " if len(st.sections) > 1 else ""
            change = f": dropper lengths changed by {last_change:.2g} m (to converge: {tol:g} m)" if iteration > 1 else ""
            status.show(f"{sections}iteration {iteration}{change}")
        half = 0.5 * d.dropper_mass_per_length * length0 * d.gravity
        # 1. contact wire held at the design height at the droppers (and supports if held)
        fixed = [(0, ["x", "y", "z"] + beam_extra), (n_nodes - 1, ["x", "y", "z"])]
        fixed += [(j, ["x", "y", "z"] if held else ["x", "y"]) for j in inner] + [(j, ["x", "z"]) for j in drop]
        fixed += [(j, ["x"]) for j in np.setdiff1d(np.arange(1, n_nodes - 1), np.concatenate([inner, drop]))]
        loads = [(n_nodes - 1, (d.contact_wire.tension, 0.0, 0.0))]
        for j, node in enumerate(drop):
            w = -(d.clamp_mass_contact * d.gravity + half[j])
            loads.append((node, (tension[j] * direction[j, 0], tension[j] * direction[j, 1], w)))
        for node in inner:
            loads.append((node, (0.0, 0.0, -d.steady_arm_mass * d.gravity)))
        cw, cw_react, _ = _solve_wire(cw_body, fixed, loads, d.gravity)
        vertical = cw_react[drop, 2]
        tension = vertical / direction[:, 2]
        if np.any(tension <= 0):
            j = int(np.argmin(tension))
            what = "presag or overlap_raise" if (sec.lift_start or sec.lift_end) else "presag"
            raise ParameterError(
                f"{what}: the target needs the dropper at x={sec.dropper_x()[j]:g} m in compression "
                f"(tension {tension[j]:.1f} N); reduce the {what} or its curvature")
        # 2. messenger under the dropper tensions
        fixed = [(0, ["x", "y", "z"] + beam_extra), (n_nodes - 1, ["x", "y", "z"])] + [(j, ["x", "y", "z"]) for j in inner]
        fixed += [(j, ["x"]) for j in np.setdiff1d(np.arange(1, n_nodes - 1), inner)]
        loads = [(n_nodes - 1, (d.messenger_wire.tension, 0.0, 0.0))]
        for j, node in enumerate(drop):
            w = -(d.clamp_mass_messenger * d.gravity + half[j])
            loads.append((node, tuple(-tension[j] * direction[j] + np.array([0.0, 0.0, w]))))
        mw_start = copy.deepcopy(mw_body)
        mw_start.q0[sup, 2] = support_height
        mw, mw_react, _ = _solve_wire(mw_start, fixed, loads, d.gravity)
        delta = pos(mw)[drop] - pos(cw)[drop]
        distance = np.linalg.norm(delta, axis=1)
        if np.any(delta[:, 2] <= 0):
            j = int(np.argmin(delta[:, 2]))
            raise ParameterError(
                f"encumbrance={d.encumbrance:g} m: the messenger sags below the contact wire at x={sec.dropper_x()[j]:g} m; "
                "increase the encumbrance or the messenger tension")
        direction = delta / distance[:, None]
        tension = vertical / direction[:, 2]
        k_law = d.dropper_stiffness
        new_length0 = distance - tension / k_law if k_law > 0 else distance / (1 + tension / d.dropper_EA)
        if np.any(new_length0 <= 0):
            raise ParameterError("dropper_stiffness: a dropper stretches beyond its own length; increase it")
        last_change = np.max(np.abs(new_length0 - length0))
        length0 = new_length0
        _balance_axial_forces(cw_body, cw, cw_react[:, 0], d.contact_wire)
        _balance_axial_forces(mw_body, mw, mw_react[:, 0], d.messenger_wire)
        if last_change < tol:
            steady = cw_react[inner, 2].copy() if held else np.zeros(inner.size)
            return length0, steady, mw_react[inner, 2].copy(), mw[inner, 2].copy(), cw[inner, 2].copy(), iteration
    raise SolverError(f"form finding: dropper lengths of tension section {k + 1} still changed by {last_change:.3g} m "
                      f"after {max_iterations} iterations (tol={tol:g} m)")


def _string_droppers(design: CatenaryDesign, k: int, wires: tuple) -> tuple:
    """Replace the wire-based results of :func:`_form_section` for section ``k`` by the dropper
    lengths and support forces of flexible strings (``dropper_statics="strings"``); the
    messenger support heights and the iteration count stay."""
    from .span_statics import section_statics

    s = section_statics(design, k, bending=False)
    return (s.dropper_length_m, s.steady_arm_force_N, s.messenger_support_force_N, wires[3],
            s.contact_wire_support_z_m, wires[5])


def _static_state(st: CatenaryStructure) -> np.ndarray:
    """Static equilibrium of the assembled catenary with its dropper lengths and support preloads.

    With ``steady_arm="free"`` the steady arms must carry nothing here: the equilibrium is
    solved without their springs, which are then set unloaded at the heights found.
    """
    if st.design.steady_arm == "held":
        return coupled_equilibrium(st, st.q0)
    stiffness = st.cw_supports.stiffness
    st.cw_supports.stiffness = 0.0
    try:
        q = coupled_equilibrium(st, st.q0)
    finally:
        st.cw_supports.stiffness = stiffness
    st.cw_supports.height[:] = q[st.cw_xyz[st.cw_supports.nodes, 2]]
    st.cw_supports.preload[:] = 0.0
    return q


@serially
def coupled_equilibrium(structure: CatenaryStructure, q: np.ndarray, extra=None, rtol: float = 1e-10,
                        max_iterations: int = 40, xtol: float = 1e-8) -> np.ndarray:
    """Static equilibrium of the assembled catenary by Newton's method (tangent with the
    current dropper states, backtracking on the residual norm). Converged when the residual
    is below ``rtol`` times the largest load, or when a full step moves no coordinate by more
    than ``xtol`` (m) (the residual then sits at round-off of the wire tensions).

    ``extra(q) -> (force, stiffness)`` adds further forces (e.g. pantograph contact) and their
    ``-d force/d q`` (sparse, n x n, or None).
    """
    free = structure.free
    q = np.array(q, dtype=float)

    def residual(q):
        f = structure.forces(q)
        if extra is not None:
            f = f + extra(q)[0]
        return f[free]

    scale = max(1.0, np.abs(structure._f_ext[free]).max())
    r = residual(q)
    for it in range(max_iterations):
        if np.abs(r).max() < rtol * scale:
            return q
        k = structure.stiffness(q)
        if extra is not None:
            k_extra = extra(q)[1]
            if k_extra is not None:
                k = k + k_extra
        factor = BandedCholesky(k[free][:, free], structure.free_ordering)
        structure.free_ordering = factor.permutation  # the pattern changes little: ordered once
        dq = factor.solve(r)
        if np.abs(dq).max() < xtol and np.abs(r).max() < 1e-6 * scale:
            # at the residual's round-off (the wire tensions'): a line search there only
            # halves steps against noise
            q = q.copy()
            q[free] += dq
            return q
        alpha, norm0 = 1.0, np.linalg.norm(r)
        while True:
            trial = q.copy()
            trial[free] += alpha * dq
            r_trial = residual(trial)
            if np.linalg.norm(r_trial) < norm0 or alpha < 1e-3:
                break
            alpha *= 0.5
        q, r = trial, r_trial
        if alpha == 1.0 and np.abs(dq).max() < xtol and np.abs(r).max() < 1e-6 * scale:
            return q
    if np.abs(r).max() < 1e-6 * scale:
        return q
    raise SolverError(f"catenary static equilibrium: residual {np.abs(r).max():.3g} N after {max_iterations} "
                      "Newton iterations; check supports and dropper lengths")
