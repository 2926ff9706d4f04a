"""
Your own multibody pantograph under the catenary
================================================

A multibody pantograph is a *scene fragment*: a function that adds its rigid bodies, joints and
force elements to the catenary's :class:`~symcat.scene.Scene` under the contact wire and returns
the name of its pan-head/wire contact (the contract is in
:mod:`symcat.interaction.scene_passage`). :func:`~symcat.interaction.scene_passage.run_scene_passage`
form-finds the catenary, adds the fragment at the start of the analysis section, trims its
uplift so that the static contact force is ``target_force``, starts from the joint static
equilibrium and integrates by generalized-alpha, with the same EN 50318 statistics as the lumped
passages. The seed paper's four-body pantograph (``pantograph=seo2005`` of the catenary models)
plugs in the same way (:func:`symcat.interaction.scene_pantographs.seo2005_fragment`).

This one is the smallest pantograph that works: a roof body driven along the line on a
prismatic joint, a pan-head on a vertical prismatic guide, a spring-damper between them, the
uplift as a point load, and a penalty contact (loss of contact allowed; the benchmark's wire is
staggered).
"""

import os

import matplotlib.pyplot as plt

from symcat.catenary import benchmark2015
from symcat.interaction.scene_passage import ScenePantograph, run_scene_passage
from symcat.pantograph.lumped_scene import wire_height
from symcat.scene import Driving, PenaltyContact, PointLoad, Prismatic, RigidBody, SpringDamper

FULL = os.environ.get("SYMCAT_DOCS_FULL") == "1"
N_SPANS, ELEMENTS_PER_SPAN = (10, 60) if FULL else (5, 10)


def my_pantograph(scene, wire, x0, speed, uplift):
    """Add the pantograph under ``wire`` at ``x0`` (m), moving at ``speed`` (m/s), pushed up by
    ``uplift`` (N); return the name of its contact."""
    z, s0, _ = wire_height(scene, wire, x0)  # the wire's height and arc length at x0
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


# %%
# The passage
# -----------
# ``uplift=160`` is the first guess of the trim; the result's ``uplift_N`` is the uplift that
# gives a static contact force of 90 N.

speed_kmh = 200.0
result = run_scene_passage(benchmark2015(N_SPANS), ScenePantograph(my_pantograph, uplift=160.0, name="mine"),
                           speed_kmh / 3.6, target_force=90.0, elements_per_span=ELEMENTS_PER_SPAN,
                           progress=False)
print(f"trimmed uplift {result.uplift_N:.1f} N")
for key, value in result.statistics[0].items():
    print(f"{key:26s} {value:10.4g}")

# %%
# The histories are named with their SI units (:class:`~symcat.interaction.scene_passage.SceneRecord`),
# and ``symcat.interaction.output`` writes the models' plots and ParaView series from them. The mesh
# here is coarse so that the documentation builds quickly: at 10 elements per span the raw force
# carries a ripple of the elements (5.5 m long), and on the 2015 benchmark at 320 km/h such a mesh
# overstates the standard deviation by about 30 % (:doc:`../performance/pantograph`); the
# models' default is 60 elements per span (``SYMCAT_DOCS_FULL=1`` runs this page with it).

from symcat.interaction.statistics import lowpass

rec = result.record
fig, axes = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
axes[0].plot(rec.x_contact_m[:, 0], rec.contact_force_N[:, 0], lw=0.5, color="0.6", label="raw")
axes[0].plot(rec.x_contact_m[:, 0], lowpass(rec.t_s, rec.contact_force_N[:, 0]), label="20 Hz low-pass")
axes[0].legend(loc="upper right")
axes[0].set(ylabel="contact force [N]", title=f"own pantograph, {speed_kmh:.0f} km/h, "
            f"{N_SPANS} spans x {ELEMENTS_PER_SPAN} elements")
axes[1].plot(rec.x_contact_m[:, 0], (rec.panhead_z_m[:, 0] - rec.panhead_z_m[0, 0]) * 1e3, lw=0.7)
axes[1].set(xlabel="pan-head position [m]", ylabel="pan-head height\nfrom its start [mm]")
for ax in axes:
    for a in result.section_m:
        ax.axvline(a, color="k", ls=":")
fig.tight_layout()

# %%
# To run the seed paper's pantograph instead: ``symcat run benchmark2015 --set pantograph=seo2005``,
# or in Python ``run_scene_passage(design, seo2005_fragment(), ...)`` with
# :func:`~symcat.interaction.scene_pantographs.seo2005_fragment`.
