"""The seed paper's four-body pantograph (Seo, Sugiyama and Shabana 2005, Section 7) as a scene
fragment: :func:`add_seo2005_pantograph` adds it, with its pan-head/wire contact, under any ANCF
wire of a :class:`~symcat.scene.Scene` in one call (the seed's straight wire,
:func:`symcat.catenary.seed.add_seed_catenary`, or a form-found catenary,
:func:`symcat.catenary.catenary_scene`).

From the paper: lower and upper arm 8 kg, plunger 4 kg, pan-head 2 kg; revolute joints lower
arm-carrier, lower arm-upper arm, plunger-upper arm; Table 1: k1 = 40000 N/m, c1 = 100 N s/m
(primary suspension, pan-head-plunger), k2 = 0, c2 = 200 N s/m, k3 = 5000 N/m, c3 = 50 N s/m; a
constant uplift force on the plunger.

Everything else is chosen here (the paper does not give it). Coordinates: x along the track, y
lateral, z up; the pantograph stands in the plane y = 0. All joints are about the lateral y axis;
B = base hinge on the base body, ``B_DEPTH`` = 2.5 m below the wire.

carrier (``base=None``): rigid body, 50 kg, on a prismatic joint along x, driven along x at
    ``speed`` (Driving constraint), or held fixed (``carrier_fixed``). Otherwise the pantograph
    stands on the rigid body ``base`` (a car body).
lower arm: 1.6 m, 8 kg, from B backwards and up to the elbow E = B + (-1.291, 0, 0.945) m.
upper arm: 1.8 m, 8 kg, from E forwards and up to the apex A = B + (0, 0, 2.2) m.
plunger: 4 kg, centre of mass 0.1 m above A, hinged at A; it carries the pan-head guide (top at
    A + 0.2 m) and a 0.4 m lever pointing backwards from A.
pan-head: 2 kg, centre of mass (= contact point) 0.3 m above A, on a vertical prismatic guide of
    the plunger (the paper's spring alone would leave it free to rotate).
Table 1 element 1 (k1, c1): primary suspension, guide top A + (0, 0, 0.2) to the pan-head.
Table 1 element 2 (k2 = 0, c2): main damper, base point B + (0.4, 0, 0) to the lower arm's
    midpoint.
Table 1 element 3 (k3, c3): head-levelling spring, from the end of the plunger's lever
    A + (-0.4, 0, 0) to the upper-arm point 0.8 m below A; it keeps the plunger upright
    (rotational stiffness about 720 N m/rad).
Coupling rod (not in the paper; every single-arm pantograph has one): a stiff spring-damper
    (``rod_stiffness`` 5e5 N/m, 500 N s/m) from B + (-0.35, 0, -0.1) to the upper-arm point
    0.3 m beyond the elbow, which makes the frame a four-bar linkage.
Uplift: ``uplift`` N upward on the plunger's centre of mass; the default 265 N gives a static
    contact force of about 90 N with these masses (the arms' weight is not balanced).
Contact: ``bilateral``, the seed's sliding joint (pan-head centre of mass on the wire centre
    line: meant for a wire in the plane y = 0; a staggered wire would be pulled onto it), or
    ``penalty``, the tangency condition for s and a normal penalty force along the wire's normal
    (``contact_stiffness``, ``contact_damping``, ``contact_smoothing``; the pan-head's lateral
    offset from a staggered wire is left free); contact loss is a positive gap.
"""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..model import Parameter
from ..scene import (AncfBody, Driving, Fixed, PenaltyContact, PointLoad, Prismatic, Revolute, RigidBody, Scene,
                     SlidingJoint, SpringDamper)

G = 9.81
B_DEPTH = 2.5                       # base hinge below the wire (m)
L1, L2 = 1.6, 1.8                   # lower and upper arm lengths (m)
APEX = 2.2                          # apex height above the base hinge (m)
MARGIN = 2.0                        # closest approach of the pan-head to a wire end (m)
MASSES = {"lower_arm": 8.0, "upper_arm": 8.0, "plunger": 4.0, "panhead": 2.0}   # kg, without the carrier
CONTACTS = ("bilateral", "penalty")

_POS = dict(minimum=0.0, exclusive_minimum=True)

#: Model parameters of the pantograph and its contact, by name (as the seed models declare them).
PARAMETERS = {q.name: q for q in (
    Parameter("contact", "bilateral", "", "pan-head/wire contact model", choices=CONTACTS),
    Parameter("start", 5.0, "m", "initial pan-head position along the wire", **_POS),
    Parameter("uplift", 265.0, "N", "static uplift force on the plunger", minimum=0.0),
    Parameter("rod_stiffness", 5e5, "N/m", "stiffness of the coupling rod", **_POS),
    Parameter("contact_stiffness", 5e4, "N/m", "penalty contact stiffness", **_POS),
    Parameter("contact_damping", 50.0, "N s/m", "penalty contact damping (acts only in contact)", minimum=0.0),
    Parameter("contact_smoothing", 1e-5, "m", "depth over which the penalty law is smoothed", **_POS),
)}


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


def check_position(x0: float, x_first: float, x_last: float, name: str = "x0", where: str = "the wire",
                   note: str = "") -> None:
    """Refuse a pan-head start ``x0`` (m) closer than ``MARGIN`` to an end of a wire running from
    ``x_first`` to ``x_last``: a one-line :class:`ParameterError` naming ``name``."""
    lo, hi = x_first + MARGIN, x_last - MARGIN
    if not lo <= x0 <= hi:
        raise ParameterError(f"{name}={x0:g} m: the pantograph must start on {where}, in [{lo:g}, {hi:g}] m{note}")


def check_run(p: dict) -> None:
    """Reject model parameters (``start``, ``speed``, ``t_end`` on a wire from 0 to
    ``wire_length``) that put the pan-head off the wire, before anything is built or written."""
    length = p["wire_length"]
    check_position(p["start"], 0.0, length, "start", "the wire", f" (wire_length={length:g} m)")
    end = p["start"] + p["speed"] * p["t_end"]
    if end > length - MARGIN:
        t_max = (length - MARGIN - p["start"]) / p["speed"]
        raise ParameterError(f"t_end={p['t_end']:g} s: at speed={p['speed']:g} m/s the pantograph would leave the "
                             f"wire (x = {end:g} m > {length - MARGIN:g} m); allowed t_end is in [0, {t_max:.4g}] s, "
                             "or lengthen wire_length")


def _wire_point(body: AncfBody, x0: float) -> tuple[float, float]:
    """Arc length (m from node 0, in the mesh's element lengths) and height of the wire ``body``
    at x = ``x0``, linear between its nodes (which must advance along x)."""
    x, z = body.q0[:, 0], body.q0[:, 2]
    lengths = body.params[:, body.element.param_names.index("length")]
    k = int(np.clip(np.searchsorted(x, x0, side="right") - 1, 0, len(x) - 2))
    t = (x0 - x[k]) / (x[k + 1] - x[k])
    return float(np.sum(lengths[:k]) + t * lengths[k]), float(z[k] + t * (z[k + 1] - z[k]))


def add_seo2005_pantograph(scene: Scene, wire: str, x0: float, z_wire: float | None = None,
                           contact: str = "bilateral", base: str | None = None, speed: float = 0.0,
                           uplift: float = 265.0, rod_stiffness: float = 5e5, contact_stiffness: float = 5e4,
                           contact_damping: float = 50.0, contact_smoothing: float = 1e-5,
                           carrier_fixed: bool = False, prefix: str = "", s0: float | None = None) -> dict:
    """Add the seed's four-body pantograph (module doc) under the ANCF wire ``wire`` of ``scene``,
    with its pan-head/wire contact: one call, nothing added if an input is refused.

    Parameters
    ----------
    scene : Scene
        Holds the wire (and ``base``, if given).
    wire : str
        Name of the ANCF body the pan-head runs on; its nodes must advance along x.
    x0 : float
        Position (m) along x of the base hinge and the pan-head; at least ``MARGIN`` = 2 m from
        either end of the wire.
    z_wire : float, optional
        Height (m) of the wire at ``x0`` in the initial configuration: the pantograph's base
        hinge is ``B_DEPTH`` = 2.5 m below it. Default: the wire's mesh at ``x0``.
    contact : str
        ``"bilateral"`` (sliding joint) or ``"penalty"``.
    base : str, optional
        Rigid body of ``scene`` the pantograph stands on (e.g. a car body); default: a 50 kg
        carrier driven along x at ``speed`` (fixed with ``carrier_fixed``).
    speed : float
        Initial velocity (m/s) along x of all pantograph bodies (and the carrier's drive).
    uplift, rod_stiffness, contact_stiffness, contact_damping, contact_smoothing : float
        As the module doc (N, N/m, N/m, N s/m, m).
    prefix : str
        Put before every name added (to add several pantographs to one scene).
    s0 : float, optional
        Arc length (m from node 0, undeformed) of the wire point at ``x0``; default: from the
        wire's mesh, linear between its nodes.

    Returns
    -------
    dict
        Role -> name in ``scene`` of everything added (bodies ``lower_arm``, ``upper_arm``,
        ``plunger``, ``panhead`` and ``carrier`` (no ``base``); joints ``base_hinge``,
        ``elbow``, ``apex``, ``guide`` and ``track`` + ``drive`` or ``carrier_fixed``; force
        elements ``primary_k1``, ``damper_k2``, ``leveller_k3``, ``coupling_rod``, ``uplift`` and,
        on a given ``base``, ``uplift_reaction`` (the uplift's reaction on the base, at the base
        hinge: the uplift acts between base and frame);
        ``contact``, the sliding joint or penalty contact), plus ``base``, the body the
        pantograph stands on. :func:`static_contact_force` and :func:`contact_history` take
        ``names["contact"]``.

    Raises
    ------
    ParameterError
        ``wire`` not an ANCF body of the scene, ``x0`` off the wire, an unknown ``contact``,
        ``base`` not a rigid body of the scene, or a name already used.
    """
    wires = [b.name for b in scene.bodies]
    if wire not in wires:
        allowed = ", ".join(wires) if wires else "none: add the catenary first"
        raise ParameterError(f"wire={wire!r}: not an ANCF body of the scene; must be one of {allowed}")
    body = scene.body(wire)
    xs = body.q0[:, 0]
    if not np.all(np.diff(xs) > 0):
        raise ParameterError(f"wire={wire!r}: its nodes must advance along x (the pantograph runs along x)")
    check_position(x0, float(xs[0]), float(xs[-1]), "x0", f"wire {wire!r}")
    if contact not in CONTACTS:
        raise ParameterError(f"contact={contact!r}: must be one of {', '.join(CONTACTS)}")
    rigid = [b.name for b in scene.rigid_bodies]
    if base is not None and base not in rigid:
        raise ParameterError(f"base={base!r}: not a rigid body of the scene; must be one of "
                             f"{', '.join(rigid) if rigid else 'none'}, or None (a driven carrier)")
    s_mesh, z_mesh = _wire_point(body, x0)
    s0 = s_mesh if s0 is None else s0
    z0 = z_mesh if z_wire is None else z_wire

    n = {r: prefix + r for r in ("lower_arm", "upper_arm", "plunger", "panhead", "base_hinge", "elbow", "apex",
                                  "guide", "primary_k1", "damper_k2", "leveller_k3", "coupling_rod", "uplift",
                                  "contact")}
    if base is None:
        n["carrier"] = prefix + "carrier"
        for r in (("carrier_fixed",) if carrier_fixed else ("track", "drive")):
            n[r] = prefix + r
    bodies = {n[r] for r in ("lower_arm", "upper_arm", "plunger", "panhead", "carrier") if r in n}
    taken = (bodies & (set(scene.body_names()) | {"ground"})) | \
        ((set(n.values()) - bodies) & {x.name for x in scene.joints + scene.force_elements})
    if taken:
        raise ParameterError(f"prefix={prefix!r}: the names {', '.join(sorted(taken))} are already used in the "
                             "scene; give another prefix")

    g = geometry(x0, z0)
    vel = (speed, 0.0, 0.0)
    user_base = base is not None
    if base is None:
        base = n["carrier"]
        scene.add(RigidBody(base, 50.0, (5.0, 5.0, 5.0), tuple(g["B"]), velocity=vel))
        if carrier_fixed:
            scene.add(Fixed(n["carrier_fixed"], base, "ground", at=tuple(g["B"])))
        else:
            scene.add(Prismatic(n["track"], base, "ground", at=tuple(g["B"]), axis=(1, 0, 0)))
            scene.add(Driving(n["drive"], base, direction=(1, 0, 0), velocity=speed))
    n["base"] = base
    scene.add(_rod(n["lower_arm"], MASSES["lower_arm"], g["B"], g["E"], vel))
    scene.add(_rod(n["upper_arm"], MASSES["upper_arm"], g["E"], g["A"], vel))
    scene.add(RigidBody(n["plunger"], MASSES["plunger"], (0.02, 0.02, 0.02), tuple(g["plunger"]), velocity=vel))
    scene.add(RigidBody(n["panhead"], MASSES["panhead"], (0.375, 0.01, 0.375), tuple(g["head"]), velocity=vel))
    y = (0.0, 1.0, 0.0)
    scene.add(Revolute(n["base_hinge"], n["lower_arm"], base, at=tuple(g["B"]), axis=y))
    scene.add(Revolute(n["elbow"], n["upper_arm"], n["lower_arm"], at=tuple(g["E"]), axis=y))
    scene.add(Revolute(n["apex"], n["plunger"], n["upper_arm"], at=tuple(g["A"]), axis=y))
    scene.add(Prismatic(n["guide"], n["panhead"], n["plunger"], at=tuple(g["guide"]), axis=(0, 0, 1)))
    scene.add(SpringDamper(n["primary_k1"], n["plunger"], n["panhead"], at_i=tuple(g["guide"]), at_j=tuple(g["head"]),
                           stiffness=40000.0, damping=100.0))
    scene.add(SpringDamper(n["damper_k2"], base, n["lower_arm"], at_i=tuple(g["damper_base"]),
                           at_j=tuple(g["lower_mid"]), stiffness=0.0, damping=200.0))
    scene.add(SpringDamper(n["leveller_k3"], n["plunger"], n["upper_arm"], at_i=tuple(g["lever"]),
                           at_j=tuple(g["level"]), stiffness=5000.0, damping=50.0))
    scene.add(SpringDamper(n["coupling_rod"], base, n["upper_arm"], at_i=tuple(g["rod_base"]),
                           at_j=tuple(g["rod_arm"]), stiffness=rod_stiffness, damping=500.0))
    scene.add(PointLoad(n["uplift"], n["plunger"], force=(0.0, 0.0, uplift)))
    if user_base:
        # The uplift is the pantograph's own drive, between its base and its frame: the body
        # it stands on (a car body) carries its reaction, or the vehicle would be lifted by it.
        n["uplift_reaction"] = prefix + "uplift_reaction"
        scene.add(PointLoad(n["uplift_reaction"], base, at=tuple(g["B"]), force=(0.0, 0.0, -uplift)))
    if contact == "bilateral":
        scene.add(SlidingJoint(n["contact"], wire, n["panhead"], s0=s0, at=tuple(g["head"])))
    else:
        scene.add(PenaltyContact(n["contact"], wire, n["panhead"], s0=s0, stiffness=contact_stiffness,
                                 damping=contact_damping, smoothing=contact_smoothing, at=tuple(g["head"])))
    return n


def add_seo2005_pantograph_from(scene: Scene, p: dict, wire: str = "wire", z0: float = 0.0, base: str | None = None,
                                carrier_fixed: bool = False) -> dict:
    """:func:`add_seo2005_pantograph` at ``p["start"]`` with the model parameters ``p`` (keys of
    :data:`PARAMETERS` and ``speed``) under a wire starting at x = 0 along x (the seed's: arc
    length = x)."""
    return add_seo2005_pantograph(scene, wire, p["start"], z0, p["contact"], base, p["speed"], p["uplift"],
                                  p["rod_stiffness"], p["contact_stiffness"], p["contact_damping"],
                                  p["contact_smoothing"], carrier_fixed, s0=p["start"])


def static_contact_force(eq, contact: str = "contact") -> float:
    """Pan-head/wire contact force (N, pushing the head down) of an equilibrium: the penalty
    force, or minus the sliding joint's vertical reaction on the pan-head (``contact``: the
    name the fragment returned)."""
    if contact in eq.contact_force_N:
        return float(eq.contact_force_N[contact])
    return -float(eq.reactions_N[contact][2])


def contact_history(res, contact: str, name: str = "contact", model=None):
    """Contact force (N), contact-loss flags and arc length (m) of the pan-head over a run
    (``contact``: ``"bilateral"`` or ``"penalty"``; ``name``: the contact's name; ``model``: the
    run's model, needed to find a sliding joint's arc length when the scene has several)."""
    if contact == "bilateral":
        force = -res.reactions_N[name][:, 2]
        k = 0 if model is None else [sl.joint.name for sl in model.sliding].index(name)
        return force, force < 0, res.s_m[:, k]  # lost: the joint would have to pull the pan-head
    c = res.contacts[name]
    return c["force_N"], c["gap_m"] > 0, c["s_m"]


def wire_atol(model, atol: float, wires=None) -> np.ndarray:
    """Per-coordinate absolute tolerances: the cross-section gradients r_y, r_z of beam3d wires
    (``wires``: ANCF body names, default all; a 3 mm section has modes near 1e6 rad/s that carry
    no physics here) are not error-controlled more finely than 1e-2 (unit vectors), or IDAS would
    resolve their vibration."""
    names = [b.name for b in model.scene.bodies] if wires is None else list(wires)
    heads = tuple(f"{w}[" for w in names)
    out = np.full(model.n_q, atol)
    for k, name in enumerate(model.coordinate_names()):
        if name.startswith(heads) and name.split(".")[-1][-2:] in ("_y", "_z"):
            out[k] = 1e-2
    return out
