"""Reference catenaries: the 2015 benchmark and the EN 50318:2002 reference model.

Every value carries its source in the design's ``sources``; values the public data leave open
are marked "choice" with the reason (see ``symcat/reference_data/*.md``).
"""
from __future__ import annotations

import math
from importlib import resources

import numpy as np

from .design import CatenaryDesign, Wire

BENCHMARK_2015_SOURCE = ("Bruni et al., 'The results of the pantograph-catenary interaction benchmark', "
                         "Vehicle System Dynamics 53(3):412-435, 2015")
EN50318_SOURCE = "EN 50318:2002 reference model as reproduced in public papers (unconfirmed against the standard)"


def parabolic_presag(positions, span_length: float, max_sag: float, first: float, last: float) -> tuple:
    """Presag (m) at ``positions``: a parabola through 0 at the first and last dropper with
    ``max_sag`` at mid-span between them."""
    mid = 0.5 * (first + last)
    half = 0.5 * (last - first)
    return tuple(max_sag * (1.0 - ((x - mid) / half) ** 2) for x in positions)


def rayleigh_from_ratio(zeta: float, f1_hz: float, f2_hz: float) -> tuple[float, float]:
    """Rayleigh coefficients (alpha 1/s, beta s) giving damping ratio ``zeta`` at two frequencies."""
    w1, w2 = 2 * math.pi * f1_hz, 2 * math.pi * f2_hz
    return 2 * zeta * w1 * w2 / (w1 + w2), 2 * zeta / (w1 + w2)


def benchmark2015(n_spans: int = 10, steady_arm: str = "held", dropper_statics: str = "wires") -> CatenaryDesign:
    """The pantograph-catenary interaction benchmark catenary (Bruni et al. 2015).

    Parameters
    ----------
    n_spans : int
        Spans of the tension section.
    steady_arm, dropper_statics : str
        Static conventions (:class:`~symcat.catenary.design.CatenaryDesign`). The benchmark's
        published dropper lengths (:func:`benchmark2015_dropper_lengths`) follow
        ``steady_arm="free", dropper_statics="strings"``: the model ``benchmark2015`` uses
        those. The defaults here keep the convention other models built on this catenary use
        (``seo2005_line``): steady arms holding the wire at its design height, droppers
        form-found with the model's wires (13 to 15 mm longer than the published ones at 60
        elements per span).
    """
    positions = (4.5, 10.25, 16.0, 21.75, 27.5, 33.25, 39.0, 44.75, 50.5)
    return CatenaryDesign(
        n_spans=n_spans,
        span_length=55.0,
        encumbrance=1.2,
        dropper_positions=positions,
        presag=(0.0, 0.024, 0.041, 0.052, 0.055, 0.052, 0.041, 0.024, 0.0),
        contact_wire=Wire(tension=22000.0, mass_per_length=1.35, EA=100e9 * 150e-6, EI=195.0),
        messenger_wire=Wire(tension=16000.0, mass_per_length=1.08, EA=97e9 * 120e-6, EI=131.7),
        dropper_EA=2.0e5,
        dropper_mass_per_length=0.117,
        clamp_mass_contact=0.165,
        clamp_mass_messenger=0.195,
        steady_arm_stiffness=2673.58,
        messenger_support_stiffness=5.0e5,
        stagger=0.2,
        rayleigh_alpha=0.0125,
        rayleigh_beta=1.0e-4,
        steady_arm=steady_arm,
        dropper_statics=dropper_statics,
        sources={
            "all values": BENCHMARK_2015_SOURCE + " (public parameter set, symcat/reference_data/catenary-benchmark-2015.md)",
            "steady_arm, dropper_statics": "free, strings reproduce the benchmark's nominal dropper lengths within 1.4 mm "
                                           "(symcat/reference_data/benchmark2015_dropper_lengths.csv); held, wires: "
                                           "symcat's earlier convention",
            "steady_arm_stiffness, messenger_support_stiffness, rayleigh": "single secondary source (?), an assumption",
            "stagger": "choice: +/-0.2 m, a usual high-speed value; the public set does not state it",
            "contact_wire_height": "choice: 5.3 m; only relative heights matter",
        },
    )


def benchmark2015_dropper_lengths() -> dict[str, np.ndarray]:
    """The benchmark's published dropper lengths of one span, with their positions and presag.

    Read from ``symcat/reference_data/benchmark2015_dropper_lengths.csv`` (its header gives the
    source). Returns arrays ``position_m``, ``presag_m`` and ``length_m`` (m, dropper 1 nearest
    the span's first support).
    """
    text = resources.files("symcat.reference_data").joinpath("benchmark2015_dropper_lengths.csv").read_text()
    rows = [line for line in text.splitlines() if line and not line.startswith("#")]
    header = rows[0].split(",")
    table = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    return {name: table[:, header.index(name)] for name in ("position_m", "presag_m", "length_m")}


def en50318(n_spans: int = 10, presag_max: float = 0.055) -> CatenaryDesign:
    """The EN 50318:2002 reference catenary as reproduced in public papers.

    Choices where the public data are silent (stated in ``sources``): the encumbrance (1.2 m),
    wire EA (the benchmark's wires), the presag parabola between the end droppers, dropper and
    clamp masses (none given: taken as zero), Rayleigh damping fitted to 0.5 % at 1 and 20 Hz,
    and no stagger. ``presag_max`` (m) is the presag at mid-span: the public data give 55 mm
    as a maximum, and the statistics depend on it more than on any other open value (the
    sensitivity study in ``models/en50318.py``). The standard's own presag and dropper layout
    (Annex A) are not in the public record (issue 30), so the presag stays an assumption.
    """
    positions = (5.0, 10.5, 17.0, 23.5, 30.0, 36.5, 43.0, 49.5, 55.0)
    alpha, beta = rayleigh_from_ratio(0.005, 1.0, 20.0)
    return CatenaryDesign(
        n_spans=n_spans,
        span_length=60.0,
        encumbrance=1.2,
        dropper_positions=positions,
        presag=parabolic_presag(positions, 60.0, presag_max, positions[0], positions[-1]),
        contact_wire=Wire(tension=20000.0, mass_per_length=1.35, EA=100e9 * 150e-6, EI=195.0),
        messenger_wire=Wire(tension=16000.0, mass_per_length=1.07, EA=97e9 * 120e-6, EI=131.7),
        dropper_EA=1.0e5,
        dropper_stiffness=1.0e5,
        steady_arm_stiffness=300.0,
        messenger_support_stiffness=5.0e4,
        stagger=0.0,
        rayleigh_alpha=alpha,
        rayleigh_beta=beta,
        sources={
            "spans, wires, droppers, supports, damping ratio": EN50318_SOURCE,
            "encumbrance": "choice: 1.2 m (not in the public data)",
            "EA of the wires": "choice: the 2015 benchmark's wires (E A = 15.0 MN and 11.64 MN)",
            "presag": f"choice: parabola, 0 at the end droppers, {1e3 * presag_max:g} mm at mid-span (55 mm is the "
                      "public maximum; the standard's Annex A presag is not in the public record)",
            "dropper and clamp masses": "choice: none (not in the public data)",
            "rayleigh": f"choice: alpha={alpha:.4g} 1/s, beta={beta:.4g} s give 0.5 % at 1 Hz and 20 Hz",
            "stagger": "choice: none",
        },
    )
