"""The seed paper's numerical example (Seo, Sugiyama and Shabana 2005, Section 7): a four-body
pantograph running at 17 m/s under an 8-element ANCF contact wire held by droppers, with the
bilateral sliding joint of the paper or a unilateral penalty contact (its Section 8), started
from static equilibrium (the paper's first 2 s of oscillation came from not doing this).

From the paper: contact wire rho = 4200 kg/m^3, A = 9 mm^2, E = 9e10 Pa, end tension 5 kN, 8
elements (beam3d); droppers tension-only, k = 2e5 N/m, c = 100 N s/m; no messenger wire; lower
and upper arm 8 kg, plunger 4 kg, pan-head 2 kg; revolute joints lower arm-carrier, lower
arm-upper arm, plunger-upper arm; Table 1: k1 = 40000 N/m, c1 = 100 N s/m (primary suspension,
pan-head-plunger), k2 = 0, c2 = 200 N s/m, k3 = 5000 N/m, c3 = 50 N s/m; a constant uplift
force on the plunger; vehicle speed 17 m/s.

Everything else is chosen here (the paper does not give it). Coordinates: x along the track,
y lateral, z up; the undeformed contact wire is the line y = z = 0, so the pan-head's z is its
vertical displacement from the wire's design height.

Contact wire
    ``wire_length`` = 60 m (8 elements of 7.5 m), pinned at both ends (positions fixed; a
    beam3d wire also has its torsion fixed at node 0). Cross-section 3 mm x 3 mm square
    (A = 9 mm^2 as in the paper; I = 6.75e-12 m^4, EI = 0.61 N m^2). The end tension enters
    as the prestrain T / (EA) = 5000 / 810000 of the mesh. Kelvin-Voigt damping ``wire_damping``
    (1e-4 s, not in the paper; it only calms the highest element modes).
Droppers
    One at each of the 7 interior nodes (x = 7.5, 15, ..., 52.5 m), vertical, hanging from
    fixed points 1.0 m above the wire; free length 1.0 m minus the stretch that carries the
    weight of 7.5 m of wire (9.3e-6 m), so the unloaded wire hangs straight.
Pantograph (all joints about the lateral y axis; B = base hinge on the carrier)
    carrier (roof): rigid body, 50 kg, on a prismatic joint along x and driven along x at
    ``speed`` (Driving constraint); B is 2.5 m below the wire.
    lower arm: 1.6 m, 8 kg, from B backwards and up to the elbow E = B + (-1.291, 0, 0.945) m.
    upper arm: 1.8 m, 8 kg, from E forwards and up to the apex A = B + (0, 0, 2.2) m.
    plunger: 4 kg, centre of mass 0.1 m above A, hinged at A; it carries the pan-head guide
    (top at A + 0.2 m) and a 0.4 m lever pointing backwards from A.
    pan-head: 2 kg, centre of mass (= contact point) 0.3 m above A, on a vertical prismatic
    guide of the plunger (the paper's spring alone would leave it free to rotate).
    Table 1 element 1 (k1, c1): primary suspension, guide top A + (0, 0, 0.2) to the pan-head.
    Table 1 element 2 (k2 = 0, c2): main damper, carrier point B + (0.4, 0, 0) to the lower
    arm's midpoint.
    Table 1 element 3 (k3, c3): head-levelling spring, from the end of the plunger's lever
    A + (-0.4, 0, 0) to the upper-arm point 0.8 m below A; it keeps the plunger upright
    (rotational stiffness about 720 N m/rad).
    Coupling rod (not in the paper; every single-arm pantograph has one): a stiff
    spring-damper (``rod_stiffness`` 5e5 N/m, 500 N s/m) from B + (-0.35, 0, -0.1) to the
    upper-arm point 0.3 m beyond the elbow, which makes the frame a four-bar linkage: without
    it the apex could move horizontally with no stiffness at all.
    Uplift: ``uplift`` N upward on the plunger's centre of mass; the default 265 N gives a
    static contact force of about 90 N with these masses (the arms' weight is not balanced).
Contact
    bilateral: the seed's sliding joint (pan-head centre of mass on the wire centre line).
    penalty: tangency condition for s and a normal penalty force (``contact_stiffness``,
    ``contact_damping``, ``contact_smoothing``); contact loss is a positive gap.
Integrator
    ``integrator`` = ``idas`` (default; index 1 with Baumgarte, ``rtol``) or
    ``generalized_alpha`` (fixed step ``dt``, numerical dissipation ``rho_inf``; the stabilized
    index-2 form). Either contact model runs on both.
"""
from __future__ import annotations

import numpy as np

from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError
from symcat.integrate.choice import integrate_model, integrator_parameters
from symcat.model import Model, ModelOutput, Parameter
from symcat.scene import (AncfBody, Driving, Fixed, Material, PenaltyContact, PointLoad, Prismatic, Revolute, RigidBody,
                          Scene, Section, SlidingJoint, SpringDamper)

G = 9.81
_POS = dict(minimum=0.0, exclusive_minimum=True)

PARAMETERS = [
    Parameter("t_end", 2.0, "s", "simulated time (0: static equilibrium only)", minimum=0.0),
    Parameter("contact", "bilateral", "", "pan-head/wire contact model", choices=("bilateral", "penalty")),
    Parameter("element", "beam3d", "", "contact-wire element type", choices=("beam3d", "cable3d")),
    Parameter("n_elements", 8, "-", "contact-wire elements (droppers at the interior nodes)", minimum=2, maximum=400),
    Parameter("speed", 17.0, "m/s", "carrier speed along the wire", minimum=0.0),
    Parameter("wire_length", 60.0, "m", "contact-wire length between the pinned ends", **_POS),
    Parameter("tension", 5000.0, "N", "contact-wire end tension", **_POS),
    Parameter("wire_damping", 1e-4, "s", "Kelvin-Voigt time constant of the wire strain rates", minimum=0.0),
    Parameter("start", 5.0, "m", "initial pan-head position along the wire", **_POS),
    Parameter("uplift", 265.0, "N", "static uplift force on the plunger", minimum=0.0),
    Parameter("rod_stiffness", 5e5, "N/m", "stiffness of the coupling rod", **_POS),
    Parameter("contact_stiffness", 5e4, "N/m", "penalty contact stiffness", **_POS),
    Parameter("contact_damping", 50.0, "N s/m", "penalty contact damping (acts only in contact)", minimum=0.0),
    Parameter("contact_smoothing", 1e-5, "m", "depth over which the penalty law is smoothed", **_POS),
    Parameter("formulation", "augmented", "", "equations of motion", choices=("augmented", "embedded")),
    Parameter("rtol", 1e-5, "-", "IDAS relative tolerance", minimum=1e-12, maximum=1e-2),
    Parameter("n_out", 400, "-", "output intervals per simulated second", minimum=10, maximum=100000),
] + integrator_parameters()

RHO, AREA, E_MOD, SIDE = 4200.0, 9e-6, 9e10, 3e-3
DROPPER_K, DROPPER_C, DROPPER_LENGTH = 2e5, 100.0, 1.0
B_DEPTH = 2.5                       # base hinge below the wire (m)
L1, L2 = 1.6, 1.8                   # lower and upper arm lengths (m)
APEX = 2.2                          # apex height above the base hinge (m)
MARGIN = 2.0                        # closest approach of the pan-head to a wire end (m)


def _rod(name, mass, a, b, velocity):
    """A slender rigid arm from point a to b (body x along it, y lateral)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = (b - a) / np.linalg.norm(b - a)
    rotation = np.column_stack([d, [0, 1.0, 0], np.cross(d, [0, 1.0, 0])])
    j = mass * np.linalg.norm(b - a) ** 2 / 12
    return RigidBody(name, mass, (0.01 * j, j, j), tuple((a + b) / 2), rotation, velocity=velocity)


def geometry(x0: float, z0: float = 0.0) -> dict:
    """Global points of the pantograph with the base hinge under ``x0``, the wire at height
    ``z0`` (see the module doc)."""
    b = np.array([x0, 0.0, z0 - B_DEPTH])
    a = b + [0.0, 0.0, APEX]
    cos_b = (L1**2 + APEX**2 - L2**2) / (2 * L1 * APEX)
    e = b + L1 * np.array([-np.sqrt(1 - cos_b**2), 0.0, cos_b])
    u2 = (a - e) / np.linalg.norm(a - e)
    return {"B": b, "E": e, "A": a, "u2": u2, "head": a + [0, 0, 0.3], "guide": a + [0, 0, 0.2],
            "plunger": a + [0, 0, 0.1], "lever": a + [-0.4, 0, 0], "level": a - 0.8 * u2,
            "rod_base": b + [-0.35, 0, -0.1], "rod_arm": e - 0.3 * u2, "damper_base": b + [0.4, 0, 0],
            "lower_mid": (b + e) / 2}


def build(p: dict, z0: float = 0.0, base: str | None = None, scene: Scene | None = None,
          carrier_fixed: bool = False) -> Scene:
    """The catenary and the pantograph with the wire at height ``z0`` (m). The pantograph's base
    is a 50 kg carrier driven along the wire (``base=None``; held fixed with ``carrier_fixed``)
    or the rigid body ``base`` already in ``scene`` (a car body)."""
    scene = add_catenary(Scene(gravity=(0.0, 0.0, -G)) if scene is None else scene, p, z0)
    add_pantograph(scene, p, z0, base, carrier_fixed)
    return scene


def add_catenary(scene: Scene, p: dict, z0: float = 0.0) -> Scene:
    """The contact wire (pinned ends, along x at height ``z0``) and its droppers."""
    length, n_el = p["wire_length"], p["n_elements"]
    ea = E_MOD * AREA
    section = Section.rectangle(SIDE, SIDE)
    wire = AncfBody.straight("wire", p["element"], [0, 0, z0], [length, 0, z0], n_el, Material(E_MOD, RHO), section,
                             prestrain=p["tension"] / ea, damping_axial=p["wire_damping"],
                             damping_bending=p["wire_damping"])
    wire.pin(0).pin(-1)
    if p["element"] == "beam3d":
        wire.fix(0, ["z_y", "y_z"])
    scene.add(wire)
    spacing = length / n_el
    stretch = RHO * AREA * G * spacing / DROPPER_K
    for k in range(1, n_el):
        x = k * spacing
        scene.add(SpringDamper(f"dropper_{k}", ("wire", k), "ground", at_i=(x, 0, z0), at_j=(x, 0, z0 + DROPPER_LENGTH),
                               stiffness=DROPPER_K, damping=DROPPER_C, free_length=DROPPER_LENGTH - stretch,
                               tension_only=True))
    return scene


def add_pantograph(scene: Scene, p: dict, z0: float = 0.0, base: str | None = None, carrier_fixed: bool = False):
    """The four-body pantograph under the wire at ``p["start"]`` and its contact (module doc)."""
    g = geometry(p["start"], z0)
    vel = (p["speed"], 0.0, 0.0)
    if base is None:
        base = "carrier"
        scene.add(RigidBody("carrier", 50.0, (5.0, 5.0, 5.0), tuple(g["B"]), velocity=vel))
        if carrier_fixed:
            scene.add(Fixed("carrier_fixed", "carrier", "ground", at=tuple(g["B"])))
        else:
            scene.add(Prismatic("track", "carrier", "ground", at=tuple(g["B"]), axis=(1, 0, 0)))
            scene.add(Driving("drive", "carrier", direction=(1, 0, 0), velocity=p["speed"]))
    scene.add(_rod("lower_arm", 8.0, g["B"], g["E"], vel))
    scene.add(_rod("upper_arm", 8.0, g["E"], g["A"], vel))
    scene.add(RigidBody("plunger", 4.0, (0.02, 0.02, 0.02), tuple(g["plunger"]), velocity=vel))
    scene.add(RigidBody("panhead", 2.0, (0.375, 0.01, 0.375), tuple(g["head"]), velocity=vel))
    y = (0.0, 1.0, 0.0)
    scene.add(Revolute("base_hinge", "lower_arm", base, at=tuple(g["B"]), axis=y))
    scene.add(Revolute("elbow", "upper_arm", "lower_arm", at=tuple(g["E"]), axis=y))
    scene.add(Revolute("apex", "plunger", "upper_arm", at=tuple(g["A"]), axis=y))
    scene.add(Prismatic("guide", "panhead", "plunger", at=tuple(g["guide"]), axis=(0, 0, 1)))
    scene.add(SpringDamper("primary_k1", "plunger", "panhead", at_i=tuple(g["guide"]), at_j=tuple(g["head"]),
                           stiffness=40000.0, damping=100.0))
    scene.add(SpringDamper("damper_k2", base, "lower_arm", at_i=tuple(g["damper_base"]),
                           at_j=tuple(g["lower_mid"]), stiffness=0.0, damping=200.0))
    scene.add(SpringDamper("leveller_k3", "plunger", "upper_arm", at_i=tuple(g["lever"]), at_j=tuple(g["level"]),
                           stiffness=5000.0, damping=50.0))
    scene.add(SpringDamper("coupling_rod", base, "upper_arm", at_i=tuple(g["rod_base"]),
                           at_j=tuple(g["rod_arm"]), stiffness=p["rod_stiffness"], damping=500.0))
    scene.add(PointLoad("uplift", "plunger", force=(0.0, 0.0, p["uplift"])))
    if p["contact"] == "bilateral":
        scene.add(SlidingJoint("contact", "wire", "panhead", s0=p["start"], at=tuple(g["head"])))
    else:
        scene.add(PenaltyContact("contact", "wire", "panhead", s0=p["start"], stiffness=p["contact_stiffness"],
                                 damping=p["contact_damping"], smoothing=p["contact_smoothing"], at=tuple(g["head"])))
    return scene


def check(p: dict) -> None:
    """Reject inputs that put the pan-head off the wire (before anything is built or written)."""
    length = p["wire_length"]
    if not MARGIN <= p["start"] <= length - MARGIN:
        raise ParameterError(f"start={p['start']:g} m: the pantograph must start on the wire, in "
                             f"[{MARGIN:g}, {length - MARGIN:g}] m (wire_length={length:g} m)")
    end = p["start"] + p["speed"] * p["t_end"]
    if end > length - MARGIN:
        t_max = (length - MARGIN - p["start"]) / p["speed"]
        raise ParameterError(f"t_end={p['t_end']:g} s: at speed={p['speed']:g} m/s the pantograph would leave the "
                             f"wire (x = {end:g} m > {length - MARGIN:g} m); allowed t_end is in [0, {t_max:.4g}] s, "
                             "or lengthen wire_length")


def static_contact_force(eq) -> float:
    """Pan-head/wire contact force (N, pushing the head down) of an equilibrium: the penalty
    force, or minus the sliding joint's vertical reaction on the pan-head."""
    if "contact" in eq.contact_force_N:
        return float(eq.contact_force_N["contact"])
    return -float(eq.reactions_N["contact"][2])


def contact_history(res, contact: str):
    """Contact force (N), contact-loss flags and arc length (m) of the pan-head over a run."""
    if contact == "bilateral":
        force = -res.reactions_N["contact"][:, 2]
        return force, force < 0, res.s_m[:, 0]  # lost: the joint would have to pull the pan-head
    c = res.contacts["contact"]
    return c["force_N"], c["gap_m"] > 0, c["s_m"]


def _atol(model, atol: float) -> np.ndarray:
    """Per-coordinate absolute tolerances: the cross-section gradients r_y, r_z of a beam3d
    wire (3 mm section: modes near 1e6 rad/s that carry no physics here) are not error-controlled
    more finely than 1e-2 (unit vectors), or IDAS would resolve their vibration."""
    out = np.full(model.n_q, atol)
    for k, name in enumerate(model.coordinate_names()):
        if name.startswith("wire[") and name.split(".")[-1][-2:] in ("_y", "_z"):
            out[k] = 1e-2
    return out


def _panhead_offset(model) -> int:
    return model.rigid_offset["panhead"]


def run(p: dict) -> ModelOutput:
    check(p)
    scene = build(p)
    model = MultibodyModel(scene)
    eq = solve_equilibrium(model)
    eq.apply(model)
    off = _panhead_offset(model)
    static_force = static_contact_force(eq)
    static = {"static_panhead_z_m": float(eq.q[off + 2]), "static_contact_force_N": static_force,
              "static_residual_N": eq.residual_N, "static_iterations": eq.iterations}
    if p["t_end"] == 0:
        summary = {"panhead_z_mean_m": static["static_panhead_z_m"], "panhead_z_std_m": 0.0,
                   "contact_force_mean_N": static_force, "contact_force_std_N": 0.0, "contact_loss_percent": 0.0,
                   "simulated_s": 0.0, **static}
        return ModelOutput(summary, eq.stats(), {"equilibrium": eq})
    n_out = max(10, int(round(p["n_out"] * p["t_end"])))
    # IDAS: index 1 (Baumgarte); generalized-alpha: the stabilized index-2 form (positions and
    # velocities enforced).
    index = "ggl" if p["integrator"] == "generalized_alpha" else "1"
    res = integrate_model(model, p, p["t_end"], p["formulation"], index, n_out=n_out, rtol=p["rtol"],
                          atol=_atol(model, p["rtol"] * 1e-2))
    z = res.q[:, off + 2]
    acc = res.a[:, off + 2]
    force, lost, s_hist = contact_history(res, p["contact"])
    e = res.energy_J["total"]
    summary = {
        "panhead_z_mean_m": float(z.mean()), "panhead_z_std_m": float(z.std()),
        "contact_force_mean_N": float(force.mean()), "contact_force_std_N": float(force.std()),
        "contact_force_max_N": float(force.max()), "contact_force_min_N": float(force.min()),
        "panhead_acceleration_max_m_s2": float(np.abs(acc).max()),
        "contact_loss_percent": float(100.0 * lost.mean()),
        "max_position_drift_m": float(res.position_drift.max()),
        "max_velocity_drift_m_s": float(res.velocity_drift.max()),
        "energy_change_J": float(e[-1] - e[0]),
        "contact_s_final_m": float(s_hist[-1]),
        "simulated_s": p["t_end"], "steps": res.stats["steps"],
        "wall_per_simulated_s": res.stats["wall_s"] / p["t_end"], **static,
    }

    def write(out):
        from symcat.results.paraview import write_multibody_series
        from symcat.results.timeseries import plot_histories

        npz = out / "seo2005_catenary.npz"
        res.save(npz)
        with np.load(npz) as data:
            arrays = dict(data)
        np.savez_compressed(npz, **arrays, panhead_z_m=z, panhead_acceleration_m_s2=acc, contact_force_N=force)
        plot = plot_histories(res.t_s, {"pan-head z [m]": z, "pan-head acceleration z [m/s^2]": acc,
                                        "contact force [N]": force}, out / "seo2005_catenary.png",
                              title=f"seo2005: {p['contact']} contact, {p['element']}, {p['speed']:g} m/s")
        pvd = write_multibody_series(model, res.t_s, res.q, out / "paraview", "seo2005_catenary")
        return [npz, plot, pvd]

    return ModelOutput(summary, {**res.stats, "equilibrium": eq.stats()},
                       {"result": res, "equilibrium": eq, "panhead_z_m": z, "contact_force_N": force}, write)


MODEL = Model("seo2005_catenary", "the seed paper's example: four-body pantograph under an 8-element ANCF contact wire",
              PARAMETERS, run)
