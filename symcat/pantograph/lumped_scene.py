"""A lumped-mass pantograph (:class:`~symcat.pantograph.LumpedPantograph`) as scene elements,
so that it runs on the shared multibody pipeline (``MultibodyModel``, ``solve_equilibrium``,
``generalized_alpha`` / ``simulate``) under a :func:`~symcat.catenary.scene.catenary_scene`.

Mapping (``name`` = the ``name`` argument; stage 0 sits on the roof, the last stage is the
pan-head):

====================================  ==================================================================
:class:`LumpedPantograph`             scene element
====================================  ==================================================================
pan-head position ``x_start + v t``   rigid body ``{name}_carrier`` holding y, z and its rotation
                                      (``RigidBody.held``), a :class:`Driving` along x at ``speed``
                                      (the roof)
stage displacement ``u_i``            rigid body ``{name}_stage_{i}`` (mass ``masses[i]``) holding y
                                      and its rotation, a :class:`Driving` along x with the carrier:
                                      one free coordinate, its height; same mass, no rotation
                                      (inertia immaterial)
stage spring/damper ``k_i``, ``c_i``  :class:`SpringDamper` ``{name}_spring_{i}`` from stage ``i - 1``
                                      (the carrier for i = 0) to stage ``i``: the points stay vertically
                                      above each other, so its length is linear in the heights and the
                                      law is exactly ``k_i (u_i - u_{i-1}) + c_i (u_i' - u_{i-1}')``
static uplift + ``aero v^2``          :class:`PointLoad` ``{name}_uplift`` (stage ``uplift_stage``) and
                                      ``{name}_aero`` (pan-head), constant
gravity left out                      :class:`PointLoad` ``{name}_weight_{i}`` = ``+m_i g`` on every
                                      stage: cancels the scene's gravity exactly
reference height                      the spring free lengths: the springs carry, in the initial
                                      configuration, the static forces of the pressing pantograph
                                      (stage ``j``'s spring is compressed by the static forces on the
                                      stages below it), and the pan-head is placed at ``head_z``
                                      (default: the contact-wire height at ``x0`` in the scene, or the
                                      height under the static load from :func:`loaded_wire_height`:
                                      the catenary's static state under the pantograph's point force)
penalty ``max(k d + c d', 0)``        :class:`PenaltyContact` ``{name}_contact`` (pan-head centre of
                                      mass), ``stiffness`` and ``damping``
bilateral ``d = 0``                   :class:`SlidingJoint` ``{name}_contact`` on a shoe ``{name}_shoe``
                                      that slides across the pan-head (:class:`Prismatic` along y),
                                      because the joint also fixes the lateral position and the wire
                                      is staggered; the shoe takes ``SHOE_FRACTION`` of the pan-head's
                                      mass (vertical mass unchanged; the wire gets that lateral mass)
====================================  ==================================================================

Modelling choices of the contact:

* Penalty law: C1-smoothed over ``smoothing`` (m): in contact it is ``k (pen - smoothing) + c
  pen'`` (not ``k pen + c pen'``), quadratic below ``2 smoothing`` and exactly zero once
  separated (no kink at ``pen = 0`` for Newton's method to stumble on). The static state absorbs
  the offset (the pan-head sits ``smoothing`` deeper: :func:`add_lumped_pantograph` places it
  so); only contact loss and re-contact see it, of order ``k smoothing`` (0.5 N at 5e4 N/m and
  1e-5 m).
* Contact point: the wire point whose tangent is normal to the segment from the pan-head point
  (tangency condition); the penetration and force act along the wire's normal ``k_t`` (in the
  xz-plane), so the force has a horizontal part ``f dz/dx`` on the wire and on the pan-head
  (taken by the carrier's guide), of the order of the wire's slope (a few 1e-3). The wire's
  stagger (lateral zigzag) does not enter the normal (no y component); the tangency condition
  shifts the point along x by ``stagger * dy/dx``, about a millimetre.
* Penetration rate: the exact time derivative of the normal gap.
* Section overlaps: one contact element per call (call again with the other wire's name in an
  overlap: each contact is zero when separated).
"""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..scene import (
    AncfBody,
    Driving,
    PenaltyContact,
    PointLoad,
    Prismatic,
    RigidBody,
    Scene,
    SlidingJoint,
    SpringDamper,
)
from .lumped import LumpedPantograph

CONTACTS = ("penalty", "bilateral")
#: Vertical distance (m) between consecutive stages (and from the carrier to stage 0); only
#: the springs' free lengths depend on it, not the dynamics.
STAGE_SPACING = 0.3
#: Bilateral contact: share of the pan-head's mass (moved from it) on the lateral shoe.
SHOE_FRACTION = 0.01


def wire_height(scene: Scene, wire: str, x: float) -> tuple[float, float, float]:
    """Height (m) of the centre line of ANCF body ``wire`` at ``x`` in the scene's initial
    configuration, the arc length (m from node 0, along the initial nodes) there and the
    wire's lateral position y (m)."""
    body = scene.find(wire)
    if not isinstance(body, AncfBody):
        raise ParameterError(f"wire={wire!r}: not an ANCF body")
    q0 = np.asarray(body.q0, float)
    ix, iz = body.coordinate_index("x"), body.coordinate_index("z")
    xs, zs = q0[:, ix], q0[:, iz]
    if not xs[0] <= x <= xs[-1]:
        raise ParameterError(f"x={x:g} m: off the wire {wire!r} ({xs[0]:g}..{xs[-1]:g} m)")
    # cubic Hermite on the element, as the structure's WireLocator (symcat.catenary.contact_wire)
    from ..catenary.contact_wire import hermite
    k = int(np.clip(np.searchsorted(xs, x, side="right") - 1, 0, len(xs) - 2))
    ixx, izx = body.coordinate_index("x_x"), body.coordinate_index("z_x")
    length = float(np.linalg.norm(q0[k + 1, [ix, body.coordinate_index("y"), iz]] - q0[k, [ix, body.coordinate_index("y"), iz]]))
    cx = np.array([xs[k], length * q0[k, ixx], xs[k + 1], length * q0[k + 1, ixx]])
    cz = np.array([zs[k], length * q0[k, izx], zs[k + 1], length * q0[k + 1, izx]])
    xi = (x - xs[k]) / (xs[k + 1] - xs[k])
    for _ in range(4):
        n, dn = hermite(xi)
        xi -= (n @ cx - x) / (dn @ cx)
    n, _ = hermite(float(np.clip(xi, 0, 1)))
    pts = q0[:, [ix, body.coordinate_index("y"), iz]]
    s = float(np.sum(np.linalg.norm(np.diff(pts[: k + 1], axis=0), axis=1)) + xi * length)
    iy, iyx = body.coordinate_index("y"), body.coordinate_index("y_x")
    cy = np.array([q0[k, iy], length * q0[k, iyx], q0[k + 1, iy], length * q0[k + 1, iyx]])
    return float(n @ cz), s, float(n @ cy)


def running_sections(form, xs) -> list[int]:
    """The contact wire in running (the lowest) at each ``x`` (m) of ``xs`` in the static
    catenary ``form`` (indices of ``form.structure.contacts``)."""
    from ..catenary.contact_wire import contact_wire_locators, running_wire

    st = form.structure
    _check_covered(st, xs)
    locators = contact_wire_locators(st)
    return [running_wire(st, locators, form.q, float(x)) for x in xs]


def _check_covered(structure, xs) -> None:
    for x in xs:
        if not any(sec.covers(x) for sec in structure.sections):
            raise ParameterError(f"x={x:g} m: no contact wire there")


def loaded_catenary(form, xs, forces, sections=None) -> np.ndarray:
    """The catenary ``form``'s coordinates in its static state pressed up by ``forces`` (N) at
    ``xs`` (m) on the contact wires ``sections`` (indices; default: the wire in running,
    :func:`running_sections`), by ``coupled_equilibrium``. Kept on ``form`` for the same loads
    (a pantograph's placement and the static solve's starting state ask for the same state)."""
    from ..catenary.formfinding import coupled_equilibrium
    from ..catenary.contact_wire import contact_wire_locators, point_loads

    st = form.structure
    xs, forces = [float(x) for x in xs], [float(f) for f in forces]
    _check_covered(st, xs)
    sections = running_sections(form, xs) if sections is None else sections
    key = (tuple(xs), tuple(forces), tuple(int(k) for k in sections))
    kept = form.__dict__.setdefault("_loaded_states", {})
    if key not in kept:
        if len(kept) > 16:
            kept.clear()
        kept[key] = coupled_equilibrium(st, _loaded_start(form, kept, key),
                                        point_loads(st.n, contact_wire_locators(st), list(key[2]), xs, forces))
    return kept[key].copy()


def _loaded_start(form, kept: dict, key: tuple) -> np.ndarray:
    """Newton's start for the loaded state ``key`` (points, forces, wires): a kept state of the
    same points under other forces (an uplift trim's next solve), else the sum of the kept
    states of each point alone, scaled to its force (the catenary's deflection under these
    loads is nearly linear: several pantographs placed one by one), else the unloaded state."""
    xs, forces, wires = key
    q0 = np.asarray(form.q, float)
    for (x_k, _, w_k), q in reversed(kept.items()):
        if x_k == xs and w_k == wires:
            return q.copy()
    start = q0.copy()
    for x, f, w in zip(xs, forces, wires):
        alone = [(f_k[0], q) for (x_k, f_k, w_k), q in kept.items() if x_k == (x,) and w_k == (w,) and f_k[0]]
        if not alone:
            return q0.copy()
        f_k, q = alone[-1]
        start += (f / f_k) * (q - q0)
    return start


def loaded_wire_height(form, x: float, force: float, section: int | None = None, state=None) -> float:
    """Height (m) of the contact wire at ``x`` in the static state of the catenary ``form``
    pressed up by ``force`` (N) at ``x``: where a pantograph pressing with that force stands (the
    structure's static equilibrium under the point load, :func:`loaded_catenary`). ``state``:
    the catenary's coordinates to read the height from instead (a static state under several
    pantographs' forces, ``force`` then unused)."""
    from ..catenary.contact_wire import contact_wire_locators

    _check_covered(form.structure, [x])
    section = running_sections(form, [x])[0] if section is None else section
    q = loaded_catenary(form, [x], [force], [section]) if state is None else np.asarray(state, float)
    return contact_wire_locators(form.structure)[section].locate(q, x).height(q)


def add_lumped_pantograph(scene: Scene, pantograph: LumpedPantograph, wire: str, x0: float, speed: float,
                          contact: str = "penalty", contact_stiffness: float = 5.0e4, contact_damping: float = 0.0,
                          smoothing: float = 1.0e-5, head_z: float | None = None, name: str = "pantograph",
                          y: float = 0.0, spacing: float = STAGE_SPACING) -> dict:
    """Add ``pantograph`` to ``scene`` under ANCF body ``wire`` at ``x0`` (m), running at
    ``speed`` (m/s) along +x (see the module docstring for the mapping).

    Parameters
    ----------
    contact : "penalty" or "bilateral"
    contact_stiffness, contact_damping : float
        Penalty law (N/m, N s/m).
    smoothing : float
        Smoothing depth (m) of the scene's penalty law.
    head_z : float, optional
        Height (m) of the pan-head's contact point along the wire in the static state (default:
        the wire's height at ``x0`` in the scene's initial configuration; pass
        :func:`loaded_wire_height` for the catenary's static state under the pantograph). The
        pan-head is placed ``force / k + smoothing`` above it (penalty) or on it (bilateral),
        with the springs preloaded for the static force ``sum(static_force(speed))``.
    y : float
        Lateral position (m) of the pan-head's contact point (track centre by default).

    Returns
    -------
    dict
        Names of the elements: ``carrier``, ``stages`` (list, last = pan-head), ``springs``,
        ``contact`` and the static contact force ``static_force_N``.
    """
    p = pantograph
    if contact not in CONTACTS:
        raise ParameterError(f"contact={contact!r}: must be one of {', '.join(CONTACTS)}")
    if not speed >= 0:
        raise ParameterError(f"speed={speed:g} m/s: must be >= 0")
    if contact == "penalty" and not contact_stiffness > 0:
        raise ParameterError(f"contact_stiffness={contact_stiffness:g} N/m: must be > 0")
    if not spacing > 0:
        raise ParameterError(f"spacing={spacing:g} m: must be > 0")
    z_wire, s0, y_wire = wire_height(scene, wire, x0)
    z_contact = z_wire if head_z is None else float(head_z)
    f_static = p.static_force(speed)
    force = float(f_static.sum())
    z_head = z_contact + (force / contact_stiffness + smoothing if contact == "penalty" else 0.0)
    n = p.n
    heights = [z_head - (n - 1 - i) * spacing for i in range(n)]
    z_carrier = heights[0] - spacing
    vel = (float(speed), 0.0, 0.0)
    g = -float(scene.gravity_vector()[2])
    carrier = f"{name}_carrier"
    # Bodies that only translate hold their other coordinates (RigidBody.held) instead of being
    # guided by prismatic joints: the carrier keeps x (driven), a stage x (driven) and z.
    scene.add(RigidBody(carrier, float(sum(p.masses)), (1.0, 1.0, 1.0), (x0, y, z_carrier), velocity=vel,
                        held=("y", "z", "rotation")))
    scene.add(Driving(f"{name}_drive", carrier, direction=(1.0, 0.0, 0.0), velocity=float(speed)))
    stages, springs = [], []
    below, z_below = carrier, z_carrier
    shoe_mass = SHOE_FRACTION * float(p.masses[-1]) if contact == "bilateral" else 0.0
    for i in range(n):
        stage = f"{name}_stage_{i}"
        m = float(p.masses[i]) - (shoe_mass if i == n - 1 else 0.0)
        at = (x0, y, heights[i])
        scene.add(RigidBody(stage, m, (0.1 * m,) * 3, at, velocity=vel, held=("y", "rotation")))
        scene.add(Driving(f"{name}_drive_{i}", stage, direction=(1.0, 0.0, 0.0), velocity=float(speed)))
        # compression of spring i in the static state: the static forces on the stages below it
        # (stage i and up carry f_i.. and the contact force = all of them)
        preload = float(f_static[:i].sum())
        k = float(p.stiffness[i])
        if k == 0 and preload != 0:
            raise ParameterError(f"stiffness[{i}] = 0 N/m under a static load of {preload:g} N: no static state")
        length = heights[i] - z_below
        free = length + (preload / k if k > 0 else 0.0)
        spring = f"{name}_spring_{i}"
        scene.add(SpringDamper(spring, below, stage, at_i=(x0, y, z_below), at_j=at, stiffness=k,
                               damping=float(p.damping[i]), free_length=free))
        if g:
            scene.add(PointLoad(f"{name}_weight_{i}", stage, force=(0.0, 0.0, m * g)))
        stages.append(stage)
        springs.append(spring)
        below, z_below = stage, heights[i]
    scene.add(PointLoad(f"{name}_uplift", stages[p.uplift_stage], force=(0.0, 0.0, float(p.uplift))))
    aero = float(p.aero_coefficient * speed**2)
    if aero:
        scene.add(PointLoad(f"{name}_aero", stages[-1], force=(0.0, 0.0, aero)))
    head_at = (x0, y, z_head)
    if contact == "penalty":
        scene.add(PenaltyContact(f"{name}_contact", wire, stages[-1], s0=s0, stiffness=float(contact_stiffness),
                                 damping=float(contact_damping), smoothing=float(smoothing), at=head_at))
    else:  # a shoe sliding across the pan-head follows the wire's stagger (the joint fixes y too)
        shoe = f"{name}_shoe"
        shoe_at = (x0, y_wire, z_head)
        scene.add(RigidBody(shoe, shoe_mass, (0.1 * shoe_mass,) * 3, shoe_at, velocity=vel))
        scene.add(Prismatic(f"{name}_shoe_guide", shoe, stages[-1], at=shoe_at, axis=(0.0, 1.0, 0.0)))
        if g:
            scene.add(PointLoad(f"{name}_shoe_weight", shoe, force=(0.0, 0.0, shoe_mass * g)))
        scene.add(SlidingJoint(f"{name}_contact", wire, shoe, s0=s0, at=shoe_at))
    return {"carrier": carrier, "stages": stages, "springs": springs, "contact": f"{name}_contact",
            "static_force_N": force, **({"shoe": f"{name}_shoe"} if contact == "bilateral" else {})}
