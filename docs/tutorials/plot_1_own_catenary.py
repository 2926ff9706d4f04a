"""
Build your own catenary
=======================

A catenary is a :class:`~symcat.catenary.CatenaryDesign`: spans, dropper positions, the presag
the contact wire should have at each dropper, the two wires (tension, mass, EA, EI), droppers,
clamps, supports, stagger and Rayleigh damping. :func:`~symcat.catenary.find_form` meshes it into
ANCF cables and finds the dropper lengths that hold the contact wire at its presag target; a
:func:`~symcat.interaction.scene_passage.run_scene_passage` then runs a lumped pantograph under
it at speed (as scene bodies on the shared multibody path) and returns the EN 50318 statistics of
the contact force.

This tutorial designs a line with 50 m spans, seven droppers and a lighter contact-wire tension
than the 2015 benchmark (whose values it starts from, :func:`symcat.catenary.benchmark2015`).
"""

import os

import matplotlib.pyplot as plt
import numpy as np

from symcat.catenary import CatenaryDesign, Wire, find_form
from symcat.catenary.reference import parabolic_presag

FULL = os.environ.get("SYMCAT_DOCS_FULL") == "1"
ELEMENTS_PER_SPAN = 60 if FULL else 20  # the models' default is 60 (statistics to about 0.5 %)

# %%
# The design
# ----------
# Every length is in metres, every force in newtons. The presag is a parabola through the end
# droppers with 40 mm at mid-span (:func:`~symcat.catenary.reference.parabolic_presag`).

span = 50.0
droppers = (5.0, 11.0, 18.0, 25.0, 32.0, 39.0, 45.0)
design = CatenaryDesign(
    n_spans=6,
    span_length=span,
    encumbrance=1.2,                  # messenger above the contact wire at the supports
    dropper_positions=droppers,
    presag=parabolic_presag(droppers, span, 0.040, droppers[0], droppers[-1]),
    contact_wire=Wire(tension=20000.0, mass_per_length=1.35, EA=100e9 * 150e-6, EI=195.0),
    messenger_wire=Wire(tension=16000.0, mass_per_length=1.08, EA=97e9 * 120e-6, EI=131.7),
    dropper_EA=2.0e5,
    dropper_mass_per_length=0.117,
    clamp_mass_contact=0.165,
    clamp_mass_messenger=0.195,
    steady_arm_stiffness=2673.58,
    messenger_support_stiffness=5.0e5,
    stagger=0.2,                      # +/- 0.2 m, alternating at the supports
    rayleigh_alpha=0.0125,
    rayleigh_beta=1.0e-4,
)
print(f"line length {design.line_length:.0f} m, contact-wire wave speed {design.wave_speed * 3.6:.0f} km/h")

# %%
# Form finding
# ------------
# The droppers' unstretched lengths are found so that the static contact wire meets the presag
# target; ``height_error_m`` is what is left of the difference in the coupled static state.

form = find_form(design, ELEMENTS_PER_SPAN, progress=False)
print(f"height error {form.height_error_m * 1e3:.3f} mm after {form.iterations} iterations")
print("dropper lengths of the first span [m]:", np.round(form.dropper_length_m[: len(droppers)], 3))

st = form.structure
z = st.contact_wire_z(form.q)
x = form.q[st.cw_xyz[:, 0]]
fig, ax = plt.subplots(figsize=(8, 3))
ax.plot(x, (z - design.contact_wire_height) * 1e3)
ax.plot(design.dropper_x(), -np.tile(design.presag, design.n_spans) * 1e3, "k.", label="presag target")
ax.set(xlabel="x [m]", ylabel="contact wire height [mm]", title="static contact wire (form-found)")
ax.legend()
fig.tight_layout()

# %%
# A passage
# ---------
# The 2015 benchmark's three-mass pantograph (:func:`~symcat.pantograph.benchmark2015_pantograph`,
# its uplift the EN 50367 mean force at the speed) runs over the line at 250 km/h, as scene bodies
# (:func:`~symcat.interaction.scene_passage.lumped_fragment`) pressing with its static force. The
# statistics are those of the 20 Hz low-pass filtered contact force over the central
# ``analysis_spans``.

from symcat.interaction.scene_passage import lumped_fragment, run_scene_passage
from symcat.interaction.statistics import lowpass
from symcat.pantograph import benchmark2015_pantograph

speed_kmh = 250.0
panto = benchmark2015_pantograph(speed_kmh)
result = run_scene_passage(design, lumped_fragment(panto, form=form), speed_kmh / 3.6,
                           float(panto.static_force(speed_kmh / 3.6).sum()), elements_per_span=ELEMENTS_PER_SPAN,
                           form=form, progress=False)
for key, value in result.statistics[0].items():
    print(f"{key:26s} {value:10.4g}")

rec = result.record
force = rec.contact_force_N[:, 0]
fig, ax = plt.subplots(figsize=(8, 3))
ax.plot(rec.x_contact_m[:, 0], force, lw=0.6, label="raw")
ax.plot(rec.x_contact_m[:, 0], lowpass(rec.t_s, force), label="20 Hz low-pass")
for a in result.section_m:
    ax.axvline(a, color="k", ls=":")
ax.set(xlabel="pan-head position [m]", ylabel="contact force [N]",
       title=f"own catenary, {speed_kmh:.0f} km/h, {ELEMENTS_PER_SPAN} elements/span")
ax.legend()
fig.tight_layout()

# %%
# The same passage runs from the command line on the shipped catenaries (``symcat run
# benchmark2015``, ``symcat run en50318``); their parameters (``contact_wire_tension_N``,
# ``dropper_positions_m``, ``presag_scale``, ...) change the design the same way. With
# ``--out`` they also write the plots, an ``.npz`` of every history and a ParaView series.
