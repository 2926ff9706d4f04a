"""The 2015 pantograph-catenary interaction benchmark (Bruni et al., Vehicle System Dynamics 53(3), 2015).

A ten-span (by default) simple catenary with 55 m spans, nine droppers per span and the
benchmark's three-mass pantograph, at 320 km/h by default; one or two pantographs 200 m apart.
The dropper lengths come from static form finding with the benchmark's presag target; every run
starts from the static equilibrium with the pantographs pressing on the wire. The summary holds
the EN 50318 statistics of the 20 Hz filtered contact force over the central spans.

Assumptions (the public parameter set marks them "(?)"): steady-arm and messenger-support
stiffness, Rayleigh damping, pantograph dampers (0 unless set), uplift = EN 50367 mean force on
the lower frame; stagger +/-0.2 m; contact-wire height 5.3 m; pantograph gravity balanced.

``pantograph=seo2005`` runs the seed paper's four-body pantograph instead (scene bodies on the
multibody path, :mod:`symcat.interaction.scene_passage`; penalty contact, as the wire is
staggered; one pantograph, one tension section): its plunger uplift is trimmed so that the static
contact force is the lumped pantograph's (``uplift_N`` or the EN 50367 target, plus the
aerodynamic ``c v^2`` on the pan-head), and the summary reports that uplift (``uplift_N``).
"""
from __future__ import annotations

from symcat.catenary import benchmark2015
from symcat.errors import ParameterError
from symcat.interaction.model_support import (
    NUMERICAL_PARAMETERS,
    PANTOGRAPH_PARAMETER,
    check_scene_pantograph,
    numerical_options,
    passage_output,
    run_scene_pantograph,
)
from symcat.interaction.passage import run_passage, spans_needed
from symcat.model import Model, Parameter, comma_numbers, numbers_check
from symcat.pantograph import LumpedPantograph, benchmark2015_pantograph

PARAMETERS = [
    Parameter("speed_kmh", 320.0, "km/h", "train speed (below the contact-wire wave speed, 459.6 km/h)",
              minimum=0.0, exclusive_minimum=True),
    Parameter("n_pantographs", 1, "-", "pantographs on the train (1 or 2)", minimum=1, maximum=2),
    Parameter("spacing_m", 200.0, "m", "distance between the two pantographs", minimum=0.0, exclusive_minimum=True),
    Parameter("n_spans", 0, "-", "spans of the line (of each tension section when tension_sections > 1); 0: 10 for "
              "one pantograph, enough for two", minimum=0, maximum=200),
    Parameter("tension_sections", 1, "-", "tension sections, each overlapping the next by three spans (the overlap "
              "of two 10-span sections is the central 3 of 17 spans: set analysis_spans=3)", minimum=1, maximum=20),
    Parameter("overlap_raise_m", 0.15, "m", "height of a wire going out of running at the overlap's middle support",
              minimum=0.0, exclusive_minimum=True),
    Parameter("uplift_N", -1.0, "N", "static uplift; -1: EN 50367 target 0.00097 v^2 + 70 N", minimum=-1.0),
    Parameter("aero_coefficient_N_s2_m2", 0.0, "N s^2/m^2", "aerodynamic uplift on the pan-head, c v^2 (v in m/s)",
              minimum=0.0),
    Parameter("pantograph_damping_N_s_m", "0,0,0", "N s/m", "dampers of the three stages from the roof up, "
              "comma-separated (the public set gives none)", text="three comma-separated numbers >= 0",
              check=numbers_check(3, 0.0)),
    Parameter("presag_scale", 1.0, "-", "factor on the benchmark presag target (55 mm at mid-span)", minimum=0.0),
    Parameter("contact_wire_tension_N", 22000.0, "N", "contact-wire tension", minimum=0.0, exclusive_minimum=True),
    Parameter("messenger_tension_N", 16000.0, "N", "messenger-wire tension", minimum=0.0, exclusive_minimum=True),
    Parameter("dropper_positions_m", "", "m", "dropper positions from the start of a span, comma-separated; "
              "empty: the benchmark's nine", text="comma-separated numbers inside the span, or nothing",
              check=numbers_check(minimum=0.0, empty=True)),
    PANTOGRAPH_PARAMETER,
] + NUMERICAL_PARAMETERS


def design_from(p: dict):
    """The benchmark catenary with the model's overrides."""
    from dataclasses import replace

    from symcat.catenary.reference import parabolic_presag

    n_spans = p["n_spans"] or (10 if p["n_pantographs"] == 1 or p["tension_sections"] > 1 else
                               spans_needed(55.0, 2, p["spacing_m"], p["analysis_spans"]))
    d = benchmark2015(n_spans)
    changes = dict(presag=tuple(p["presag_scale"] * s for s in d.presag), n_sections=p["tension_sections"],
                   overlap_raise=p["overlap_raise_m"])
    changes["contact_wire"] = replace(d.contact_wire, tension=p["contact_wire_tension_N"])
    changes["messenger_wire"] = replace(d.messenger_wire, tension=p["messenger_tension_N"])
    if p["dropper_positions_m"].strip():
        pos = comma_numbers(p["dropper_positions_m"], "dropper_positions_m")
        for x in pos:
            if not 0 < x < d.span_length:
                raise ParameterError(f"dropper_positions_m: {x:g} m is outside the span (0..{d.span_length:g} m)")
        changes["dropper_positions"] = pos
        changes["presag"] = parabolic_presag(pos, d.span_length, 0.055 * p["presag_scale"], pos[0], pos[-1])
    return d.with_(**changes)


def run(p: dict):
    design = design_from(p)
    speed = p["speed_kmh"] / 3.6
    if not speed < design.wave_speed:
        raise ParameterError(f"speed_kmh={p['speed_kmh']:g} km/h: must be below the contact-wire wave speed "
                             f"{design.wave_speed * 3.6:.1f} km/h")
    base = benchmark2015_pantograph(p["speed_kmh"])
    damping = comma_numbers(p["pantograph_damping_N_s_m"], "pantograph_damping_N_s_m", 3)
    uplift = base.uplift if p["uplift_N"] < 0 else p["uplift_N"]
    panto = LumpedPantograph(base.masses, base.stiffness, damping, uplift, base.uplift_stage,
                             aero_coefficient=p["aero_coefficient_N_s2_m2"], name=base.name, sources=base.sources)
    if p["pantograph"] != "lumped":  # a multibody pantograph with the lumped one's static contact force
        check_scene_pantograph(p, design.stagger, p["n_pantographs"], design.n_sections,
                               {} if p["pantograph"] == "lumped_scene" else
                               {"pantograph_damping_N_s_m": (p["pantograph_damping_N_s_m"], "0,0,0")})
        extra = {"speed_kmh": p["speed_kmh"], "n_spans": design.line_spans, "tension_sections": design.n_sections,
                 "wave_speed_kmh": design.wave_speed * 3.6}
        return run_scene_pantograph(design, p, speed, float(panto.static_force(speed).sum()), "benchmark2015", extra,
                                    aero_force=float(panto.aero_coefficient * speed**2), lumped=panto)
    result = run_passage(design, [panto] * p["n_pantographs"], speed, spacing=p["spacing_m"], **numerical_options(p))
    extra = {"speed_kmh": p["speed_kmh"], "uplift_N": uplift, "n_spans": design.line_spans,
             "tension_sections": design.n_sections,
             "wave_speed_kmh": design.wave_speed * 3.6}
    return passage_output(result, p, "benchmark2015", extra)


MODEL = Model("benchmark2015", "the 2015 pantograph-catenary benchmark: EN 50318 statistics of the contact force",
              PARAMETERS, run)
