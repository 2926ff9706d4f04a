"""The form-found catenary as a multibody :class:`~symcat.scene.Scene`.

:func:`catenary_scene` expresses a :class:`~symcat.catenary.FormFindingResult` with scene
elements only, so that :class:`~symcat.assembly.multibody.MultibodyModel` assembles it like any
other scene (and a pantograph, a vehicle or a sliding/penalty contact can be added to it):

=======================  =====================================================================
structure term           scene element
=======================  =====================================================================
contact / messenger      :class:`AncfBody` per wire and tension section: the structure's own
wires                    bodies (same element type, mesh, per-element prestrain and density
                         from form finding, same pins: first node pinned, last node fixed in
                         y and z, inner supports fixed in y, beam3d torsion at node 0), placed
                         at the static state ``form.q``
wire weight              scene gravity ``(0, 0, -g)``
balance weights          :class:`NodalForce` ``(T, 0, 0)`` on the last node of each wire
droppers                 tension-only :class:`SpringDamper` between the contact- and messenger-
                         wire nodes: form-found unstretched length, the structure's stiffness
                         (``dropper_stiffness`` or ``dropper_EA / L``) and ``dropper_damping``
clamps, half droppers,   :class:`NodalMass` on the wire nodes (mass on x, y, z and its weight),
steady arms              as the structure lumps them
steady arms, messenger   linear :class:`SpringDamper` from the node to a ground point ``anchor``
supports                 metres straight above it: force ``preload - k (z - height)`` along
                         the spring, i.e. the structure's vertical spring with its form-found
                         preload (the spring leans, and adds a horizontal stiffness of
                         ``force / anchor``, only when the node moves along the line)
stagger, overlaps        in the node positions (one pair of wires per tension section)
Rayleigh damping         one :class:`RayleighDamping` on all wires: the structure's damping
                         matrix ``alpha M + beta K`` (the design's coefficients) with ``M``
                         the structure's mass matrix (the scene's, wires and lumped masses) and ``K`` the structure's tangent stiffness at the static
                         state ``form.q`` with every dropper taut, handed over as a constant
                         matrix (``CatenaryStructure.stiffness(form.q, droppers_taut=True)``:
                         wires, droppers, vertical supports; not the scene's own tangent, whose
                         leaning support springs add ``force / anchor`` horizontally)
=======================  =====================================================================

Not expressed (yet): wires linearized with :meth:`CatenaryStructure.linearize_wires`.
"""
from __future__ import annotations

import copy

import numpy as np

from ..errors import ParameterError
from ..scene import GROUND, NodalMass, RayleighDamping, Scene, SpringDamper
from .formfinding import FormFindingResult

#: Height (m) of the ground anchor of each support spring above its node.
SUPPORT_ANCHOR = 10.0


def _node_ref(structure, row: int, wire: str) -> tuple[str, int]:
    """``(body name, node)`` of station row ``row`` of the contact (``"cw"``) or messenger wire."""
    for k, rows in enumerate(structure.section_rows):
        if rows.start <= row < rows.stop:
            body = (structure.contacts if wire == "cw" else structure.messengers)[k]
            return body.name, int(row - rows.start)
    raise ParameterError(f"station row {row}: not in any tension section")


def catenary_scene(form: FormFindingResult, start: str = "static", rayleigh: str | None = None,
                   anchor: float = SUPPORT_ANCHOR, scene: Scene | None = None, wires: str = "nonlinear") -> Scene:
    """The form-found catenary as scene elements (see the module docstring).

    Parameters
    ----------
    form : FormFindingResult
        Output of :func:`~symcat.catenary.find_form` (any design, any number of sections).
    start : str
        Initial positions of the wires: ``"static"`` (the static state ``form.q``, default) or
        ``"mesh"`` (the structure's reference mesh, the last single-wire solutions of form
        finding; :func:`~symcat.analysis.equilibrium.solve_equilibrium` then finds the static
        state).
    rayleigh : None or "omit"
        ``None`` (default): carry the design's Rayleigh damping (a :class:`RayleighDamping`
        on all wires, when a coefficient is nonzero); ``"omit"``: build without it.
    anchor : float
        Height (m) of the support springs' ground points above their nodes.
    scene : Scene, optional
        Add to this scene (its gravity must be the design's) instead of a new one.
    wires : {"nonlinear", "linear"}
        ``"linear"``: the wires' elastic forces linearized about their initial positions (the
        static catenary with ``start="static"``; :attr:`Scene.linear_wires`, which then holds
        for every ANCF body of the scene); droppers, supports and contacts stay nonlinear.

    Notes
    -----
    Element names: bodies as in the structure (``contact``, ``messenger``; ``contact_2`` ...
    with several sections), ``dropper_{i}`` (i in the order of ``structure.dropper_nodes``),
    ``steady_arm_{j}`` and ``messenger_support_{j}`` (j in the order of ``cw_supports.nodes``);
    the Rayleigh damping, if any, is ``scene.damping[-1]``.
    The ANCF coordinates of the assembled scene are laid out as the structure's (same bodies in
    the same order), so ``q[:structure.n]`` indexes like ``form.q``.
    """
    if not isinstance(form, FormFindingResult):
        raise ParameterError(f"form: need a FormFindingResult from symcat.catenary.find_form, got {type(form).__name__}")
    st = form.structure
    d = st.design
    if start not in ("static", "mesh"):
        raise ParameterError(f"start={start!r}: must be 'static' or 'mesh'")
    if rayleigh not in (None, "omit"):
        raise ParameterError(f"rayleigh={rayleigh!r}: must be None (carry the design's Rayleigh damping) or 'omit'")
    if getattr(st, "_linear", None) is not None:
        raise ParameterError("the structure's wires are linearized (linearize_wires); a scene carries the nonlinear "
                             "wires only: call structure.linearize_wires(None) first")
    if not np.all(np.isfinite(st.dropper_length)):
        raise ParameterError("form: the structure has no dropper lengths (not form-found)")
    if not (np.isfinite(anchor) and anchor > 0):
        raise ParameterError(f"anchor={anchor:g} m: must be > 0")
    if wires not in ("nonlinear", "linear"):
        raise ParameterError(f"wires={wires!r}: must be 'nonlinear' or 'linear'")
    gravity = (0.0, 0.0, -d.gravity)
    if scene is None:
        scene = Scene(gravity=gravity)
    elif not np.allclose(scene.gravity_vector(), gravity):
        raise ParameterError(f"scene.gravity={tuple(scene.gravity)}: the catenary needs {gravity}")
    if wires == "linear":
        scene.linear_wires = True

    # Wires, their supports (pins) and balance weights: the structure's own scene.
    q = np.asarray(form.q if start == "static" else st.q0, dtype=float)
    dofs = st.system.dofs
    for body in st.scene.bodies:
        body = copy.deepcopy(body)
        off = dofs.offset[body.name]
        body.q0 = q[off: off + body.q0.size].reshape(body.q0.shape).copy()
        for (node, coord), value in body.fixed.items():
            body.q0[node, body.coordinate_index(coord)] = value
        scene.add(body)
    for load in st.scene.loads:
        scene.add(copy.deepcopy(load))

    pos = lambda xyz_rows, row: tuple(float(v) for v in q[xyz_rows[row]])

    # Droppers: tension-only springs between the wire nodes.
    stiffness = st.dropper_stiffness()
    for i, row in enumerate(st.dropper_nodes):
        scene.add(SpringDamper(f"dropper_{i}", _node_ref(st, row, "cw"), _node_ref(st, row, "mw"),
                               at_i=pos(st.cw_xyz, row), at_j=pos(st.mw_xyz, row), stiffness=float(stiffness[i]),
                               damping=float(d.dropper_damping), free_length=float(st.dropper_length[i]),
                               tension_only=True))

    # Lumped masses: clamps with half of their dropper, steady arms (as CatenaryStructure._lumped_masses).
    half = 0.5 * d.dropper_mass_per_length * st.dropper_length
    for i, row in enumerate(st.dropper_nodes):
        for wire, clamp in (("cw", d.clamp_mass_contact), ("mw", d.clamp_mass_messenger)):
            if clamp + half[i] > 0:
                scene.add(NodalMass(*_node_ref(st, row, wire), float(clamp + half[i])))
    if d.steady_arm_mass > 0:
        for row in st.cw_supports.nodes:
            scene.add(NodalMass(*_node_ref(st, row, "cw"), float(d.steady_arm_mass)))

    # Steady arms and messenger supports: springs to a ground point straight above the node.
    for prefix, sup, xyz in (("steady_arm", st.cw_supports, st.cw_xyz), ("messenger_support", st.mw_supports, st.mw_xyz)):
        for j, row in enumerate(sup.nodes):
            x, y, z = pos(xyz, row)
            top = (x, y, float(sup.height[j]) + anchor)
            scene.add(SpringDamper(f"{prefix}_{j}", _node_ref(st, row, "cw" if xyz is st.cw_xyz else "mw"), GROUND,
                                   at_i=(x, y, z), at_j=top, stiffness=float(sup.stiffness),
                                   free_length=float(anchor - sup.preload[j] / sup.stiffness)))

    # Rayleigh damping: the structure's C (see the module docstring).
    if rayleigh is None and (d.rayleigh_alpha or d.rayleigh_beta):
        scene.add(RayleighDamping(tuple(b.name for b in st.scene.bodies), float(d.rayleigh_alpha),
                                  float(d.rayleigh_beta),
                                  stiffness=st.stiffness(np.asarray(form.q, float), droppers_taut=True)))
    return scene


def support_forces(form: FormFindingResult, scene: Scene, q: np.ndarray) -> np.ndarray:
    """Vertical forces (N, up) of the scene's support springs (steady arms, then messenger
    supports) at the ANCF coordinates ``q`` (laid out as the structure's)."""
    st = form.structure
    out = []
    for prefix, sup, xyz in (("steady_arm", st.cw_supports, st.cw_xyz), ("messenger_support", st.mw_supports, st.mw_xyz)):
        springs = {f.name: f for f in scene.force_elements}
        for j, row in enumerate(sup.nodes):
            f = springs[f"{prefix}_{j}"]
            delta = np.asarray(f.at_j) - q[xyz[row]]
            length = np.linalg.norm(delta)
            out.append(f.stiffness * (length - f.free_length) * delta[2] / length)
    return np.array(out)
