"""A multibody pantograph carried by the railway vehicle under a form-found line: the scene
passage's catenary and pantograph fragment (:mod:`.scene_passage`) with the pantograph standing
on the car body of :func:`symcat.vehicle.add_vehicle` instead of a driven carrier.

The start is the joint static equilibrium, reached in two stages as in ``models/seo2005.py``:

1. the catenary and the pantograph on its driven carrier, its uplift trimmed to the target
   static contact force (:func:`~.scene_pantographs.trim_uplifts`, the scene passage's trim);
2. the full scene: the catenary (:func:`~symcat.catenary.scene.catenary_scene`), the vehicle
   with its suspensions preloaded by the weight of every body and by the load the pantograph
   puts on the roof (so it starts in its own static equilibrium), and the same pantograph
   fragment standing on the car body; the wires', the pantograph's and the contact's
   coordinates are copied by name from stage 1 (:func:`start_from`).

The vehicle does not move the pantograph's base in the static state (the suspensions start
undeflected under their preloads), so stage 1's equilibrium is stage 2's: solving the joint
equilibrium once more would need the wheel/rail contacts in the static solver, which has
none. The fragment must therefore build the pantograph on the car body in the geometry it has
on the carrier (``pantograph_on(base)`` of this module: the same fragment with and without a
base), and must make its uplift a force between frame and base (``seo2005_fragment(...,
base=...)``): an uplift that only pushes the frame up would lift the vehicle too.

Histories and statistics are those of :func:`~.scene_passage.run_scene_passage`
(:class:`~.scene_passage.SceneRecord`, :func:`~.passage.pantograph_statistics`), so the
summary, plots, ``.npz`` and ParaView series of :func:`~.model_support.passage_output` serve
this path too (the ParaView series draws the catenary and the pan-head, not the vehicle).
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..catenary.design import CatenaryDesign
from ..catenary.formfinding import FormFindingResult, find_form
from ..errors import ParameterError
from ..progress import notice
from .passage import pantograph_statistics, passage_plan
from .scene_pantographs import ScenePantograph, contact_element, trim_uplifts
from .scene_passage import SceneLine, ScenePassageResult, SceneRecord, record_histories

#: The car body's name in :func:`symcat.vehicle.add_vehicle`'s scene: the pantograph's base.
CAR_BODY = "car_body"

__all__ = ["CAR_BODY", "VehicleLine", "build_vehicle_line", "start_from", "vehicle_passage_result", "wire_height_at"]


@dataclass
class VehicleLine:
    """The full scene of :func:`build_vehicle_line`, ready to integrate from its static state.

    Attributes
    ----------
    model : MultibodyModel
        Catenary, vehicle and pantograph, at the joint static equilibrium.
    layout : VehicleLayout
        Names of the vehicle's bodies and wheel/rail contacts.
    contact : PenaltyContact or SlidingJoint
        The pan-head/wire contact in ``model``'s scene.
    form : FormFindingResult
    section_m : (float, float)
        Analysis section (m).
    x_start_m, duration_s : float
        Start of the pan-head and of the vehicle centre (m) and simulated time (s) of the
        passage plan.
    pantograph : ScenePantograph
        The fragment on the car body (its description says so, for plot titles).
    uplift_N, static_contact_force_N, target_force_N : float
        The trimmed uplift, the static contact force it gives and the target (N).
    static_solves : int
        Static equilibria the trim solved.
    equilibrium : EquilibriumResult
        Stage 1's (catenary and pantograph on its carrier).
    pantograph_bodies : list of str
        The pantograph's bodies on the car body.
    pantograph_mass_kg, car_body_load_N : float
        Their mass and the vertical load (N, down) the pantograph puts on the car body.
    base_hinge_height_m : float
        Height of the pantograph's base (its base hinge) on the car body (m above the rail).
    copied : int
        Coordinates copied from stage 1.
    wall_s : dict
        Wall time (s) of ``form_finding``, ``trim`` and ``scene`` (stage 2).
    """

    model: object
    layout: object
    contact: object
    form: FormFindingResult
    section_m: tuple[float, float]
    x_start_m: float
    duration_s: float
    pantograph: ScenePantograph
    uplift_N: float
    static_contact_force_N: float
    target_force_N: float
    static_solves: int
    equilibrium: object
    pantograph_bodies: list
    pantograph_mass_kg: float
    car_body_load_N: float
    base_hinge_height_m: float
    copied: int
    wall_s: dict = field(default_factory=dict)


def wire_height_at(design: CatenaryDesign, x: float) -> float:
    """Design height (m) of the contact wire at ``x`` (m along the line): the support height
    minus the presag, linear between the droppers and zero at the supports (the target form
    finding holds; one tension section)."""
    L = design.span_length
    xs = np.r_[0.0, np.asarray(design.dropper_positions, float), L]
    sag = np.r_[0.0, np.asarray(design.presag, float), 0.0]
    return float(design.contact_wire_height - np.interp(x - L * np.floor(x / L), xs, sag))


def start_from(model, source, eq) -> int:
    """Make the equilibrium ``eq`` of the model ``source`` the initial state of ``model`` where
    they share names: every coordinate of ``source`` that ``model`` has (by coordinate name),
    the arc lengths of the sliding joints and penalty contacts (by joint name), and their
    element windows. The rest of ``model`` keeps its initial state.

    Returns
    -------
    int
        Coordinates copied.
    """
    index = {name: k for k, name in enumerate(model.coordinate_names())}
    copied = 0
    for k, name in enumerate(source.coordinate_names()):
        if name in index:
            model.q0[index[name]] = eq.q[k]
            copied += 1
    sliding = {sl.joint.name: s for sl, s in zip(source.sliding, eq.s_m)}
    for k, sl in enumerate(model.sliding):
        if sl.joint.name in sliding:
            model.s0[k] = sliding[sl.joint.name]
    contacts = {ct.joint.name: s for ct, s in zip(source.contacts, eq.sc_m)}
    for k, ct in enumerate(model.contacts):
        if ct.joint.name in contacts:
            model.sc0[k] = contacts[ct.joint.name]
    for sl, s in zip(model.windowed(), np.r_[model.s0[: model.n_sliding], model.sc0]):
        model.set_window(sl, s)
    return copied


def build_vehicle_line(design: CatenaryDesign, pantograph_on: Callable[[str | None], ScenePantograph], speed: float,
                       target_force: float, pair, *, elements_per_span: int = 10, element: str = "cable3d",
                       analysis_spans: int = 2, t_end: float | None = None, creep: str = "linear",
                       friction_coefficient: float = 0.3, lateral_offset_m: float = 0.0, parameters=None,
                       form: FormFindingResult | None = None, wire: str = "contact", force_rtol: float = 1e-9,
                       progress: bool = True) -> VehicleLine:
    """The catenary of ``design``, the vehicle and the pantograph on its car body, at their
    joint static equilibrium (module docstring).

    Parameters
    ----------
    design : CatenaryDesign
        One tension section, placed so that the pantograph on the roof reaches the wire (the
        caller's check).
    pantograph_on : callable
        ``pantograph_on(base) -> ScenePantograph``: the fragment standing on the rigid body
        ``base`` (the car body), or on its own driven carrier for ``base=None`` (the trim), in
        the same geometry.
    speed : float
        Train speed (m/s).
    target_force : float
        Static contact force (N) the uplift is trimmed to.
    pair : ProfilePair
        Wheel and rail profiles (:func:`symcat.wheelrail.profile_pair`).
    elements_per_span, element, analysis_spans, t_end
        As :func:`~.scene_passage.run_scene_passage` (the passage plan: section, start and
        duration; ``t_end=None``: until the pan-head has left the section).
    creep, friction_coefficient, lateral_offset_m, parameters
        The vehicle's (:func:`symcat.vehicle.add_vehicle`; ``creep`` ``none``, ``linear`` or
        ``polach``).
    form : FormFindingResult, optional
        A form-found ``design``.
    wire : str
        Scene name of the contact wire.
    force_rtol : float
        Relative accuracy of the static contact force.
    progress : bool
        Progress notices.

    Returns
    -------
    VehicleLine

    Raises
    ------
    ParameterError
        Several tension sections, a passage plan that does not fit the line, or a fragment
        that adds other bodies on the car body than on its carrier.
    """
    from ..assembly.multibody import MultibodyModel
    from ..catenary.scene import catenary_scene
    from ..vehicle import add_vehicle

    if design.n_sections != 1:
        raise ParameterError(f"tension_sections={design.n_sections}: the vehicle's passage runs on one tension "
                             "section (1)")
    section, x0, duration = passage_plan(design, 1, speed, 200.0, analysis_spans, None, t_end)
    wall = {}
    t0 = time.perf_counter()
    if form is None:
        form = find_form(design, elements_per_span, element, progress=progress)
    wall["form_finding"] = time.perf_counter() - t0
    t1 = time.perf_counter()
    carried = pantograph_on(None)
    if progress:
        notice(f"trimming the uplift of the {carried.name} pantograph to a static contact force of {target_force:g} N "
               "(on a driven carrier), then the vehicle under it")
    uplifts, forces, (_, model1, _, eq), solves = trim_uplifts(form, [carried], target_force, wire, [x0], speed,
                                                                force_rtol)
    wall["trim"] = time.perf_counter() - t1
    t2 = time.perf_counter()
    # Catenary first: its coordinates lead the model's, laid out as the structure's (SceneRecord).
    scene = catenary_scene(form)
    on_roof = pantograph_on(CAR_BODY)
    # The vehicle's preloads need the roof load before the pantograph can stand on the car body:
    # read the pantograph's bodies and loads from the fragment on a stand-in base.
    bodies, mass, net_up, hinge_z = _pantograph_loads(on_roof, form, wire, x0, speed, uplifts[0])
    g = -float(scene.gravity_vector()[2])
    roof_load = mass * g + forces[0] - net_up  # weight + the wire's push - external lift (aerodynamic)
    layout = add_vehicle(scene, pair, speed_ms=speed, parameters=parameters, creep=creep,
                         friction_coefficient=friction_coefficient, lateral_offset_m=lateral_offset_m, x_m=x0,
                         car_body_load_N=roof_load)
    if layout.car_body != CAR_BODY:
        raise RuntimeError(f"add_vehicle named the car body {layout.car_body!r}, not {CAR_BODY!r}")
    contact = contact_element(scene, on_roof.add(scene, wire, x0, speed, uplifts[0]))
    model = MultibodyModel(scene)
    n_cat = form.structure.n
    if model.coordinate_names()[:n_cat] != model1.coordinate_names()[:n_cat]:
        raise RuntimeError("the full scene's catenary coordinates are not laid out as the structure's")
    missing = [b for b in bodies if f"{b}.x" not in model1.coordinate_names()]
    if missing:
        raise ParameterError(f"pantograph {on_roof.name}: its bodies {', '.join(missing)} on the car body are not "
                             "those on its carrier; pantograph_on(base) must add the same bodies for any base")
    copied = start_from(model, model1, eq)
    wall["scene"] = time.perf_counter() - t2
    shown = replace(on_roof, description=f"{on_roof.description or on_roof.name + ' pantograph'} on the vehicle")
    return VehicleLine(model, layout, contact, form, section, float(x0), float(duration), shown, float(uplifts[0]),
                       float(forces[0]), float(target_force), solves, eq, bodies, mass, float(roof_load), hinge_z,
                       copied, wall)


def _pantograph_loads(fragment: ScenePantograph, form, wire: str, x0: float, speed: float, uplift: float):
    """The rigid bodies a base-standing fragment adds, their mass (kg), the net vertical
    external force (N, up; constant parts) of the point loads it adds (on its bodies and on the
    base), and the
    height (m) of its base hinge, read from the fragment added to a copy of the catenary
    standing on a stand-in base body."""
    from ..catenary.scene import catenary_scene
    from ..scene import PointLoad, RigidBody

    scene = catenary_scene(form, rayleigh="omit")
    scene.add(RigidBody(CAR_BODY, 1.0, (1.0, 1.0, 1.0), (x0, 0.0, 0.0)))
    before = {b.name for b in scene.rigid_bodies}
    loads_before = {e.name for e in scene.force_elements}
    fragment.add(scene, wire, x0, speed, uplift)
    added = [b for b in scene.rigid_bodies if b.name not in before]
    net = sum(float(e.force[2]) for e in scene.force_elements
              if e.name not in loads_before and isinstance(e, PointLoad))
    hinges = [float(j.at[2]) for j in scene.joints if getattr(j, "body_j", None) == CAR_BODY and hasattr(j, "at")]
    return [b.name for b in added], float(sum(b.mass for b in added)), net, min(hinges) if hinges else float("nan")


def vehicle_passage_result(line: VehicleLine, res, speed: float, contact: str, record_every: float = 0.05,
                           wall_s: float = 0.0) -> ScenePassageResult:
    """The scene passage's result (histories under the passage recorder's names, EN 50318
    statistics of the contact force) of a run ``res`` (:class:`SimulationResult`, or None for
    the static state only) of ``line.model``."""
    form = line.form
    scene_line = SceneLine(form, speed, contact, line.model.n_q, None, [line.x_start_m])
    out = ScenePassageResult(form, scene_line, None, line.section_m, [], line.uplift_N, line.static_contact_force_N,
                             line.target_force_N, line.static_solves, line.pantograph, line.model, res,
                             wall_s=wall_s)
    if res is None:
        return out
    rec = SceneRecord(record_histories(res, form, line.model, line.contact, record_every), form, speed, dict(res.stats))
    rec.uplift_N, rec.static_contact_force_N = out.uplift_N, out.static_contact_force_N
    scene_line._record = rec
    out.record = rec
    out.statistics = [pantograph_statistics(rec.t_s, rec.x_contact_m[:, 0], rec.contact_force_N[:, 0], line.section_m,
                                            form.structure, rec.support_z_m, rec.static_support_z_m)]
    out.simulated_s = float(rec.t_s[-1])
    return out

