"""The seed paper's catenary (Seo, Sugiyama and Shabana 2005, Section 7): a straight ANCF contact
wire, pinned at both ends, held by vertical tension-only droppers at its interior nodes, no
messenger wire.

From the paper: contact wire rho = 4200 kg/m^3, A = 9 mm^2, E = 9e10 Pa, end tension 5 kN, 8
elements (beam3d); droppers tension-only, k = 2e5 N/m, c = 100 N s/m. Chosen here (the paper does
not give them): a 3 mm x 3 mm square section (I = 6.75e-12 m^4), the end tension entering as the
prestrain T / (EA) of the mesh, Kelvin-Voigt damping ``damping`` (s) of the strain rates, a beam3d
wire's torsion fixed at node 0, droppers hanging from fixed points 1.0 m above the wire with a free
length shortened by the stretch that carries 1/n of the wire's weight, so the unloaded wire hangs
straight. Used by ``models/seo2005_catenary.py`` and ``models/seo2005.py``.
"""
from __future__ import annotations

from ..model import Parameter
from ..scene import AncfBody, Material, Scene, Section, SpringDamper

G = 9.81
RHO, AREA, E_MOD, SIDE = 4200.0, 9e-6, 9e10, 3e-3
DROPPER_K, DROPPER_C, DROPPER_LENGTH = 2e5, 100.0, 1.0

_POS = dict(minimum=0.0, exclusive_minimum=True)

#: Model parameters of the seed catenary, by name (the keys :func:`add_seed_catenary_from`
#: reads from a model's parameter dict).
PARAMETERS = {q.name: q for q in (
    Parameter("element", "beam3d", "", "contact-wire element type", choices=("beam3d", "cable3d")),
    Parameter("n_elements", 8, "-", "contact-wire elements (droppers at the interior nodes)", minimum=2, maximum=400),
    Parameter("wire_length", 60.0, "m", "contact-wire length between the pinned ends", **_POS),
    Parameter("tension", 5000.0, "N", "contact-wire end tension", **_POS),
    Parameter("wire_damping", 1e-4, "s", "Kelvin-Voigt time constant of the wire strain rates", minimum=0.0),
)}


def add_seed_catenary(scene: Scene, element: str = "beam3d", n_elements: int = 8, length: float = 60.0,
                      tension: float = 5000.0, damping: float = 1e-4, z0: float = 0.0, name: str = "wire") -> Scene:
    """Add the seed contact wire ``name`` (from x = 0 to ``length`` along x at height ``z0``,
    y = 0, pinned ends) and its droppers ``dropper_1`` ... ``dropper_{n-1}`` to ``scene``."""
    ea = E_MOD * AREA
    section = Section.rectangle(SIDE, SIDE)
    wire = AncfBody.straight(name, element, [0, 0, z0], [length, 0, z0], n_elements, Material(E_MOD, RHO), section,
                             prestrain=tension / ea, damping_axial=damping, damping_bending=damping)
    wire.pin(0).pin(-1)
    if element == "beam3d":
        wire.fix(0, ["z_y", "y_z"])
    scene.add(wire)
    spacing = length / n_elements
    stretch = RHO * AREA * G * spacing / DROPPER_K
    for k in range(1, n_elements):
        x = k * spacing
        scene.add(SpringDamper(f"dropper_{k}", (name, k), "ground", at_i=(x, 0, z0), at_j=(x, 0, z0 + DROPPER_LENGTH),
                               stiffness=DROPPER_K, damping=DROPPER_C, free_length=DROPPER_LENGTH - stretch,
                               tension_only=True))
    return scene


def add_seed_catenary_from(scene: Scene, p: dict, z0: float = 0.0, name: str = "wire") -> Scene:
    """:func:`add_seed_catenary` with the model parameters ``p`` (keys of :data:`PARAMETERS`)."""
    return add_seed_catenary(scene, p["element"], p["n_elements"], p["wire_length"], p["tension"],
                             p["wire_damping"], z0, name)
