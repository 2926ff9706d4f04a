"""A line-scale passage of any multibody pantograph under the form-found catenary, on the shared
multibody pipeline, with EN 50318 statistics of its contact force.

:func:`run_scene_passage` form-finds the catenary (:func:`~symcat.catenary.find_form`), turns it
into a :class:`~symcat.scene.Scene` (:func:`~symcat.catenary.scene.catenary_scene`), adds a
pantograph *scene fragment* under the contact wire at the passage's start position
(:func:`~.passage.passage_plan`: the analysis section, lead-in and duration), trims the
pantograph's uplift so that the static contact force is the target, starts from the joint static
equilibrium (:func:`~symcat.analysis.equilibrium.solve_equilibrium`) and integrates by
generalized-alpha (:func:`symcat.integrate.generalized_alpha`, one output per step). The contact
force history goes through the statistics function of every passage
(:func:`~.passage.pantograph_statistics`), and the histories are recorded under names with
their SI units (:class:`SceneRecord`) for the summary, the plots, the ``.npz`` and the ParaView
series of :func:`~.model_support.passage_output`.

Your own pantograph
-------------------
A pantograph fragment is a callable

    ``add(scene, wire, x0, speed, uplift) -> contact_name``

that adds the pantograph's bodies, joints and force elements to ``scene`` (a
:class:`~symcat.scene.Scene` holding the catenary), with its pan-head under the ANCF body
``wire`` at ``x0`` (m along the line, the pantograph standing in the plane y = 0, moving along
+x at ``speed`` m/s: a driven carrier), its static uplift ``uplift`` (N) applied where the
pantograph's uplift acts, and returns the name of its pan-head/wire contact: a
:class:`~symcat.scene.PenaltyContact` (loss of contact allowed; works on a staggered wire) or a
:class:`~symcat.scene.SlidingJoint` (bilateral; for a wire in the plane y = 0 only). Wrap it
in a :class:`ScenePantograph` with a first guess of the uplift and a name::

    from symcat.catenary import benchmark2015
    from symcat.interaction.scene_passage import ScenePantograph, run_scene_passage
    from symcat.pantograph.lumped_scene import wire_height
    from symcat.scene import Driving, PenaltyContact, PointLoad, Prismatic, RigidBody, SpringDamper

    def my_pantograph(scene, wire, x0, speed, uplift):
        z, s0, _ = wire_height(scene, wire, x0)           # the wire's height and arc length at x0
        v = (speed, 0.0, 0.0)
        scene.add(RigidBody("roof", 50.0, (1, 1, 1), (x0, 0, z - 1.0), velocity=v))
        scene.add(Prismatic("track", "roof", "ground", at=(x0, 0, z - 1.0), axis=(1, 0, 0)))
        scene.add(Driving("drive", "roof", direction=(1, 0, 0), velocity=speed))
        scene.add(RigidBody("head", 8.0, (0.1, 0.1, 0.1), (x0, 0, z), velocity=v))
        scene.add(Prismatic("guide", "head", "roof", at=(x0, 0, z), axis=(0, 0, 1)))
        scene.add(SpringDamper("suspension", "roof", "head", at_i=(x0, 0, z - 1.0), at_j=(x0, 0, z),
                               stiffness=500.0, damping=50.0, free_length=1.0))
        scene.add(PointLoad("uplift", "head", force=(0, 0, uplift)))
        scene.add(PenaltyContact("head_contact", wire, "head", s0=s0, stiffness=5e4, damping=0.0))
        return "head_contact"

    res = run_scene_passage(benchmark2015(5), ScenePantograph(my_pantograph, uplift=160.0, name="mine"),
                            200 / 3.6, target_force=90.0, elements_per_span=10)
    res.statistics[0]["contact_force_std_N"], res.uplift_N, res.record.contact_force_N

The uplift trim solves the static state twice (and more only if the force is not affine in the
uplift to ``force_rtol``: the pantograph's geometry changes a little with its height): the
static contact force of a pantograph pressing on the wire is affine in its uplift. The seed
paper's four-body pantograph plugs in through the same mechanism (:func:`seo2005_fragment`).

Several pantographs: pass a list of fragments with distinct element names (penalty contacts),
``spacing`` apart, leading first (:func:`lumped_fragment` takes a ``name``). On a line of several
tension sections each pan-head starts under the wire in running, and its penalty contact is
copied onto the other sections' contact wires (:func:`~.scene_pantographs.add_section_contacts`),
which hand it over in the overlaps.

The energy balance (``energy_balance_error_J``, ``contact_work_J``) is that of the whole scene
(:mod:`symcat.assembly.energy`): its energy against the work of the prescribed train speed (the
horizontal contact forces on the pan-heads) minus what the dampers dissipate, at every step.
Not recorded on this path (a :class:`SceneRecord` lists it in ``not_computed``): the Newton
iterations per step.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..catenary.design import CatenaryDesign
from ..catenary.formfinding import FormFindingResult, find_form
from ..errors import ParameterError
from ..progress import notice
from .passage import pantograph_statistics, passage_plan
from .scene_pantographs import (
    PantographFragment,
    ScenePantograph,
    lumped_fragment,
    seo2005_fragment,
    static_force,
    trim_uplift,
    trim_uplifts,
)
from .scene_record import SceneRecord, _monitor, record_histories

__all__ = ["PantographFragment", "ScenePantograph", "ScenePassageResult", "SceneRecord", "lumped_fragment",
           "record_histories", "run_scene_passage", "seo2005_fragment", "static_force", "trim_uplift",
           "trim_uplifts"]

class SceneLine:
    """What the passage outputs (:mod:`.output`) need of the line: speed, contact model, the
    static catenary and where the pan-head is."""

    def __init__(self, form: FormFindingResult, speed: float, contact: str, n: int, record: SceneRecord | None,
                 x_start):
        self.speed, self.contact, self.n = speed, contact, n
        self.q_static = np.asarray(form.q, float).copy()
        self._record, self.x_start = record, np.atleast_1d(np.asarray(x_start, float))

    def x_contact(self, t: float) -> np.ndarray:
        """Pan-head positions (m, leading first) at ``t`` (s), from the record."""
        rec = self._record
        if rec is None:
            return self.x_start.copy()
        return np.array([np.interp(t, rec.t_s, rec.x_contact_m[:, k]) for k in range(rec.x_contact_m.shape[1])])


@dataclass
class ScenePassageResult:
    """Outcome of :func:`run_scene_passage` (the fields :func:`~.model_support.passage_output`
    reads).

    Attributes
    ----------
    form : FormFindingResult
    line : SceneLine
    record : SceneRecord or None (static only)
    section_m : (float, float)
        Analysis section (m).
    statistics : list of dict
        EN 50318 statistics (one pantograph).
    uplift_N : float
        Uplift (N) the trim found.
    static_contact_force_N : float
        Static contact force (N) with it.
    target_force_N : float
    static_solves : int
        Static equilibria solved by the trim.
    pantograph : ScenePantograph
    model : MultibodyModel
    simulation : SimulationResult or None
    wall_s, simulated_s : float
    """

    form: FormFindingResult
    line: SceneLine
    record: SceneRecord | None
    section_m: tuple[float, float]
    statistics: list[dict] = field(default_factory=list)
    uplift_N: float = 0.0
    static_contact_force_N: float = 0.0
    target_force_N: float = 0.0
    static_solves: int = 0
    pantograph: ScenePantograph | None = None
    model: object = None
    simulation: object = None
    wall_s: float = 0.0
    simulated_s: float = 0.0

    def pantograph_text(self) -> str:
        """The pantograph(s) in words (plot titles)."""
        p = self.pantograph
        what = p.description or f"{p.name} pantograph"
        up, force = np.atleast_1d(self.uplift_N), np.atleast_1d(self.static_contact_force_N)
        text = f"{what} ({up[0]:.1f} N uplift, {force[0]:.0f} N static contact force)"
        if up.size > 1:
            spacing = abs(self.line.x_start[0] - self.line.x_start[1])
            text = f"{up.size} x {text}, {spacing:g} m apart"
        return text


def run_scene_passage(design: CatenaryDesign, pantograph: ScenePantograph, speed: float, target_force: float,
                      elements_per_span: int = 60, element: str = "cable3d", analysis_spans: int = 2,
                      lead_in: float | None = None, dt: float = 1e-3, rho_inf: float = 0.8, tol: float = 1e-4,
                      t_end: float | None = None, record_every: float = 0.05, progress: bool = True,
                      form: FormFindingResult | None = None, wire: str = "contact", contact: str = "penalty",
                      force_rtol: float = 1e-5, spacing: float = 200.0, wires: str = "nonlinear") -> ScenePassageResult:
    """Run a multibody ``pantograph`` over the form-found ``design`` at ``speed`` (m/s) with the
    static contact force ``target_force`` (N); EN 50318 statistics of each pantograph's contact
    force over the analysis section.

    Parameters
    ----------
    design : CatenaryDesign
        One or several tension sections (penalty contacts for several).
    pantograph : ScenePantograph
        The fragment (module docstring) and a first guess of its uplift.
    speed : float
        Train speed (m/s), > 0.
    target_force : float
        Static contact force (N) the uplift is trimmed to.
    elements_per_span : int
        Wire elements per span of the form finding (unused with ``form``).
    element : str
        ANCF element of the wires (``"cable3d"`` or ``"beam3d"``).
    analysis_spans, lead_in, t_end
        The analysis section, the run before it (m) and the duration (s; None: until the last
        pantograph has left the section; ``t_end=0``: the static state only), as
        :func:`~.passage.passage_plan` places them.
    dt, rho_inf : float
        Generalized-alpha step (s) and spectral radius at infinity.
    tol : float
        Generalized-alpha's Newton tolerance on the coordinates (m; absolute, so the same
        anywhere along the line).
    record_every : float
        Interval (s) of the wire snapshots (ParaView).
    progress : bool
        Progress bar of the integration.
    form : FormFindingResult, optional
        A form-found ``design`` (skips form finding).
    wire : str
        Scene name of the contact wire (``catenary_scene``: ``"contact"``).
    contact : str
        The contact model in words (plot titles); the fragment decides the actual one.
    force_rtol : float
        Relative accuracy of the static contact force (1e-5: 2 mN on 170 N, far below what
        the statistics resolve; each further digit may cost a static solve).
    spacing : float
        Distance (m) between pantographs when ``pantograph`` is a list (leading first, as
        :func:`~.passage.passage_plan` places them; penalty contacts, distinct element names).
    wires : {"nonlinear", "linear"}
        The wires' elasticity: ANCF, or linearized about the static catenary without
        pantographs (:func:`~symcat.catenary.scene.catenary_scene`).

    Returns
    -------
    ScenePassageResult
        ``uplift_N`` and ``static_contact_force_N`` are lists with several pantographs.
    """
    from ..integrate import generalized_alpha

    t0 = time.perf_counter()
    if not speed > 0:
        raise ParameterError(f"speed={speed:g} m/s: must be > 0")
    if not target_force > 0:
        raise ParameterError(f"target_force={target_force:g} N: must be > 0")
    pantographs = list(pantograph) if isinstance(pantograph, (list, tuple)) else [pantograph]
    n_p = len(pantographs)
    section, x_trail, duration = passage_plan(design, n_p, speed, spacing, analysis_spans, lead_in, t_end)
    positions = [x_trail + spacing * (n_p - 1 - k) for k in range(n_p)]  # leading first
    if form is None:
        form = find_form(design, elements_per_span, element, progress=progress)
    placed0 = time.perf_counter()  # the passage's wall: static placement and integration
    if progress:
        notice(f"trimming the uplift of the {pantographs[0].name} pantograph{'s' if n_p > 1 else ''} to a static "
               f"contact force of {target_force:g} N (static solves of the joint equilibrium)")
    uplifts, forces, (_, model, elements, eq), solves = trim_uplifts(form, pantographs, target_force, wire, positions,
                                                                     speed, force_rtol, wires=wires)
    from ..scene import PenaltyContact

    eq.apply(model)
    line = SceneLine(form, speed, contact, model.n_q, None, positions)
    out = ScenePassageResult(form, line, None, section, [], uplifts[0] if n_p == 1 else uplifts,
                             forces[0] if n_p == 1 else forces, float(target_force), solves, pantographs[0], model)
    if duration == 0:
        out.wall_s = time.perf_counter() - t0
        return out
    n_steps = math.ceil(duration / dt - 1e-9)
    # A penalty contact's passage is recorded at every step by a monitor, with full outputs only
    # for the snapshots; a sliding joint's force comes from the outputs' joint reactions.
    from ..assembly.energy import EnergyTerms

    energy = EnergyTerms(model)
    monitor = _monitor(form, model, elements, energy, record_every) if isinstance(elements[0], PenaltyContact) else None
    # Snapshots every `per` steps, between half and all of the snapshot interval: a divisor of
    # the steps if there is one (the step stays duration / n_steps), else the fewest steps added
    # (generalized-alpha fits a whole number of steps per output by shortening the step). A
    # divisor searched below (a prime number of steps would make every step an output, and
    # their post-processing cost more than the run) is not needed.
    target = max(1, round(record_every / dt))
    per = min(range(max(1, target // 2), target + 1), key=lambda d: (d * math.ceil(n_steps / d) - n_steps, -d))
    n_out = n_steps if monitor is None else math.ceil(n_steps / per)
    # Penalty contacts: the contact force is a function of the state, which the index-3 form
    # integrates to order 2 with half the multiplier unknowns of the stabilized one (the same
    # statistics to 1e-9 on the benchmark, 13 % less wall time); a sliding joint's force is a
    # multiplier, whose index-3 start-up transient is of order dt.
    variant = "index3" if monitor is not None else "stabilized"
    res = generalized_alpha(model, duration, dt, rho_inf, variant=variant, n_out=n_out, tol=tol, progress=progress,
                            multipliers="integrator", monitor=monitor)  # no KKT solve per output
    rec = SceneRecord(record_histories(res, form, model, elements, record_every, energy), form, speed,
                      dict(res.stats))
    rec.stats["passage_wall_s"] = time.perf_counter() - placed0
    rec.uplift_N, rec.static_contact_force_N = out.uplift_N, out.static_contact_force_N
    line._record = rec
    stats = [pantograph_statistics(rec.t_s, rec.x_contact_m[:, k], rec.contact_force_N[:, k], section,
                                   form.structure, rec.support_z_m, rec.static_support_z_m) for k in range(n_p)]
    out.record, out.statistics, out.simulation = rec, stats, res
    out.simulated_s = float(rec.t_s[-1])
    out.wall_s = time.perf_counter() - t0
    return out
