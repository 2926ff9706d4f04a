"""Multibody pantographs as scene fragments for a line passage (:mod:`.scene_passage`, whose
docstring states the fragment contract): :class:`ScenePantograph`, the seed paper's and the
lumped pantographs as fragments, and the static states that trim their uplift to a static
contact force."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..catenary.formfinding import FormFindingResult
from ..errors import ParameterError, SolverError

#: ``add(scene, wire, x0, speed, uplift) -> contact name`` (module docstring).
PantographFragment = Callable[..., str]

@dataclass
class ScenePantograph:
    """A pantograph scene fragment for :func:`run_scene_passage`.

    Attributes
    ----------
    add : callable
        ``add(scene, wire, x0, speed, uplift) -> contact name`` (module docstring); units m,
        m/s, N.
    uplift : float
        First guess of the uplift (N) that gives the target static contact force.
    name : str
        Shown in plot titles and the summary.
    description : str
        One line about the model (plot titles).
    placed : bool
        Whether ``add`` places the pantograph in its static equilibrium on the wire loaded by
        the static contact force: the static solve then starts as Newton's method (two
        iterations) instead of a pseudo-transient continuation from rest (ten), which a
        linkage placed by its geometry alone needs. Such an ``add`` also takes the keyword
        ``loaded``: the catenary's coordinates in its static state under every pantograph's
        force, to place it on when several pantographs share the line (each lifts the wire
        under the others).
    """

    add: PantographFragment
    uplift: float = 100.0
    name: str = "pantograph"
    description: str = ""
    placed: bool = False


def seo2005_fragment(contact: str = "penalty", contact_stiffness: float = 5.0e4, contact_damping: float = 0.0,
                     contact_smoothing: float = 1.0e-5, aero_force: float = 0.0, rod_stiffness: float = 5.0e5,
                     prefix: str = "pantograph_", base: str | None = None) -> ScenePantograph:
    """The seed paper's four-body pantograph (:func:`symcat.pantograph.add_seo2005_pantograph`)
    as a :class:`ScenePantograph`.

    Parameters
    ----------
    contact : {"penalty", "bilateral"}
        Pan-head/wire contact (bilateral: a sliding joint, for an unstaggered wire only).
    contact_stiffness, contact_damping, contact_smoothing : float
        Penalty law (N/m, N s/m, m).
    aero_force : float
        Constant aerodynamic uplift (N) on the pan-head (``c v^2`` at the run's speed).
    rod_stiffness : float
        Coupling rod (N/m).
    prefix : str
        Before every element name.
    base : str, optional
        A rigid body of the scene the pantograph stands on (a car body,
        :mod:`.scene_vehicle`) instead of its own driven carrier; the uplift's reaction then
        pushes ``base`` down at the base hinge (:func:`~symcat.pantograph.add_seo2005_pantograph`).
    """
    from ..pantograph.seo2005 import add_seo2005_pantograph
    from ..scene import PointLoad

    def add(scene, wire, x0, speed, uplift):
        names = add_seo2005_pantograph(scene, wire, x0, None, contact, base, speed, uplift, rod_stiffness,
                                       contact_stiffness, contact_damping, contact_smoothing, prefix=prefix)
        if aero_force:
            scene.add(PointLoad(prefix + "aero", names["panhead"], force=(0.0, 0.0, float(aero_force))))
        return names["contact"]

    return ScenePantograph(add, uplift=265.0, name="seo2005",
                           description="seo2005 four-body pantograph")


def lumped_fragment(pantograph, contact: str = "penalty", contact_stiffness: float = 5.0e4,
                    contact_damping: float = 0.0, contact_smoothing: float = 1.0e-5,
                    form: FormFindingResult | None = None, name: str = "pantograph") -> ScenePantograph:
    """A lumped-mass pantograph (:class:`~symcat.pantograph.LumpedPantograph`: its stages,
    springs, dampers, uplift and aerodynamic force) as scene bodies
    (:func:`symcat.pantograph.lumped_scene.add_lumped_pantograph`), a :class:`ScenePantograph`.
    The trimmed uplift replaces ``pantograph.uplift``. With the catenary's ``form``, the pan-head
    is placed on the wire's static height under the pantograph's static force
    (:func:`~symcat.pantograph.lumped_scene.loaded_wire_height`), so that the nominal uplift gives
    the static force and the trim takes one static solve. ``name`` prefixes its elements (two
    pantographs on one line need two names)."""
    from dataclasses import replace

    from ..pantograph.lumped_scene import add_lumped_pantograph, loaded_wire_height

    def add(scene, wire, x0, speed, uplift, loaded=None):
        # loaded: the catenary's static state under every pantograph's force (several
        # pantographs interact through the wire; placed on it, their trim takes one solve)
        panto = replace(pantograph, uplift=float(uplift))
        head_z = None if form is None else loaded_wire_height(form, x0, float(panto.static_force(speed).sum()),
                                                              state=loaded)
        info = add_lumped_pantograph(scene, panto, wire, x0, speed, contact=contact, contact_stiffness=contact_stiffness,
                                     contact_damping=contact_damping, smoothing=contact_smoothing, head_z=head_z,
                                     name=name)
        return info["contact"]

    return ScenePantograph(add, uplift=float(pantograph.uplift), name=f"{pantograph.name} (scene)",
                           description=f"{pantograph.name} pantograph ({len(pantograph.masses)} masses)",
                           placed=form is not None)


def contact_element(scene, name: str):
    from ..scene import PenaltyContact, SlidingJoint

    for e in scene.force_elements + scene.joints:
        if e.name == name and isinstance(e, (PenaltyContact, SlidingJoint)):
            return e
    raise ParameterError(f"pantograph fragment: returned {name!r}, which is not a PenaltyContact or SlidingJoint of "
                         "the scene; it must return the name of its pan-head/wire contact")


#: Separates a pan-head's contact name from the contact wire of its copies on the other
#: tension sections' wires (:func:`add_section_contacts`).
SECTION_MARK = "@"


def static_force(eq, element) -> float:
    """Static contact force (N, pressing the pan-head down) of the contact ``element`` in the
    equilibrium ``eq``: the penalty force (with its copies on other sections' wires), or minus
    the sliding joint's vertical reaction."""
    from ..scene import PenaltyContact

    if isinstance(element, PenaltyContact):
        return float(sum(f for name, f in eq.contact_force_N.items()
                         if name == element.name or name.startswith(element.name + SECTION_MARK)))
    return -float(eq.reactions_N[element.name][2])


def running_contact_wire(form: FormFindingResult, x: float) -> str:
    """Scene name of the contact wire in running at ``x`` (m): the lowest one there in the
    static catenary (the one a pan-head at ``x`` touches)."""
    from ..catenary.contact_wire import contact_wire_locators, running_wire

    st = form.structure
    return st.contacts[running_wire(st, contact_wire_locators(st), np.asarray(form.q, float), x)].name


def add_section_contacts(form: FormFindingResult, scene, element, x0: float) -> list:
    """Copies of the pan-head's penalty contact ``element`` on the contact wires of the other
    tension sections (named ``<element>@<wire>``), so that the pan-head runs through overlaps:
    each copy acts where its wire comes down to the pan-head and, off its wire, follows the
    wire's straight continuation past its anchor, far above (see
    :meth:`~symcat.assembly.windows.ElementWindows._selection`). Their first arc lengths are
    ``x0`` (m) projected on each wire. Returns the copies."""
    from dataclasses import replace

    from ..pantograph.lumped_scene import wire_height

    copies = []
    for body in form.structure.contacts:
        if body.name == element.wire:
            continue
        wire = scene.find(body.name)
        xs = np.asarray(wire.q0, float)[:, wire.coordinate_index("x")]
        length = float(np.sum(wire.params[:, 0]))
        if xs[0] <= x0 <= xs[-1]:
            s0 = wire_height(scene, body.name, x0)[1]
        else:  # on the continuation past an anchor (about along x there)
            s0 = x0 - xs[0] if x0 < xs[0] else length + x0 - xs[-1]
        copies.append(scene.add(replace(element, name=f"{element.name}{SECTION_MARK}{body.name}", wire=body.name,
                                        s0=float(s0))))
    return copies


def _static(form, pantographs, wire: str, positions, speed: float, uplifts, wires: str = "nonlinear",
            load: float | None = None):
    """Scene, model, contact elements and equilibrium of the ``pantographs`` at ``positions``
    (m) with ``uplifts`` (N) under the catenary with ``wires`` (:func:`catenary_scene`). The
    solve starts with the wires in the catenary's static state under ``load`` (N, the
    expected contact force) at each pantograph (:func:`~symcat.pantograph.lumped_scene.
    loaded_catenary`): from the unloaded wires it would first have to lift them by the
    pantographs' uplift, several times the iterations."""
    from ..analysis.equilibrium import solve_equilibrium
    from ..assembly.multibody import MultibodyModel
    from ..catenary.scene import catenary_scene
    from ..pantograph.lumped_scene import loaded_catenary

    from ..scene import PenaltyContact

    scene = catenary_scene(form, wires=wires)
    sections = len(form.structure.contacts) > 1
    loaded = None if load is None else loaded_catenary(form, positions, [load] * len(positions))
    elements = []
    for panto, x0, u in zip(pantographs, positions, uplifts):
        running = running_contact_wire(form, x0) if sections else wire
        # a pantograph placed in equilibrium is placed on the wires loaded by all of them
        extra = {"loaded": loaded} if panto.placed and loaded is not None and len(positions) > 1 else {}
        element = contact_element(scene, panto.add(scene, running, x0, speed, float(u), **extra))
        if sections:
            if not isinstance(element, PenaltyContact):
                raise ParameterError(f"pantograph {panto.name}: a sliding joint (bilateral contact) cannot pass the "
                                     f"overlaps of {len(form.structure.contacts)} tension sections; allowed: a "
                                     "penalty contact (contact=penalty)")
            add_section_contacts(form, scene, element, x0)
        elements.append(element)
    model = MultibodyModel(scene)
    if loaded is not None:  # the structure's coordinates lead the scene's (catenary_scene)
        model.q0[: form.structure.n] = loaded
    # A pantograph placed in equilibrium on the loaded wires needs no pseudo-inertia (h of 1 s).
    eq = solve_equilibrium(model, pseudo_time_step=1.0 if load is not None and all(p.placed for p in pantographs)
                           else 1e-2)
    return scene, model, elements, eq


def trim_uplifts(form, pantographs, target_force: float, wire: str, positions, speed: float,
                 force_rtol: float = 1e-9, max_solves: int = 8, wires: str = "nonlinear"):
    """The uplifts (N) whose static contact forces are ``target_force`` (N), the ``pantographs``
    standing at ``positions`` (m): two static solves (a pantograph's force is affine in its
    uplift), then secant steps while a force is off by more than ``force_rtol`` relative (the
    pantograph's geometry moves slightly with its height; several pantographs interact through
    the wire, weakly, so each has its own secant). ``wires``: the catenary's wire model
    (:func:`~symcat.catenary.scene.catenary_scene`).

    Returns
    -------
    uplifts, forces, (scene, model, elements, eq), solves
        The uplifts (N) and their static forces (N), lists in the order of ``pantographs``, the
        static state built with them (``elements``: the contact of each) and the number of
        static solves.
    """
    who = ("pantograph " if len(pantographs) == 1 else "pantographs ") + ", ".join(p.name for p in pantographs)

    def text(values):
        return "/".join(f"{v:g}" for v in values)

    def done(f):
        return np.abs(f - target_force).max() <= force_rtol * abs(target_force)

    u0 = np.array([float(p.uplift) for p in pantographs])
    built = _static(form, pantographs, wire, positions, speed, u0, wires, target_force)
    f0 = np.array([static_force(built[3], e) for e in built[2]])
    solves = 1
    u1 = u0 + (target_force - f0)  # unit sensitivity as the first guess (uplift at the pan-head)
    while solves < max_solves and not done(f0):
        built1 = _static(form, pantographs, wire, positions, speed, u1, wires, target_force)
        f1 = np.array([static_force(built1[3], e) for e in built1[2]])
        solves += 1
        if not np.all((f1 > 0) | (f0 > 0)):
            raise ParameterError(f"{who}: no contact at uplifts {text(u0)} N and {text(u1)} N; give a first uplift "
                                 "guess that presses the pan-head on the wire")
        step = np.where(u1 != u0, u1 - u0, 1.0)
        slope = np.where(u1 != u0, (f1 - f0) / step, 0.0)
        if not np.all(slope > 0):
            raise SolverError(f"{who}: the static contact force does not grow with the uplift ({text(f0)} N at "
                              f"{text(u0)} N, {text(f1)} N at {text(u1)} N)")
        u0, f0, built = u1, f1, built1
        u1 = u1 + (target_force - f1) / slope
    if done(f0):
        return u0.tolist(), f0.tolist(), built, solves
    raise SolverError(f"{who}: the uplift trim did not reach the static contact force {target_force:g} N in "
                      f"{max_solves} static solves (last {text(f0)} N at {text(u0)} N uplift)")


def trim_uplift(form, pantograph: ScenePantograph, target_force: float, wire: str, x0: float, speed: float,
                force_rtol: float = 1e-9, max_solves: int = 8):
    """:func:`trim_uplifts` of one pantograph at ``x0`` (m): ``uplift, force, (scene, model,
    element, eq), solves``."""
    u, f, (scene, model, elements, eq), solves = trim_uplifts(form, [pantograph], target_force, wire, [x0], speed,
                                                              force_rtol, max_solves)
    return u[0], f[0], (scene, model, elements[0], eq), solves
