"""The seed paper's complete scene: the wheels carry the vehicle, the pantograph and the wire's
push; the pantograph starts from the catenary-only equilibrium."""
from __future__ import annotations

import numpy as np

from symcat.model import load_model
from symcat.vehicle import wheel_forces

G = 9.81


def test_complete_scene_starts_in_equilibrium_and_the_wheels_carry_everything():
    model = load_model("seo2005")
    p = model.resolve({"t_end": 0.05, "n_out": 200})
    p["progress"] = False
    out = model.run(p)
    s, res, layout = out.summary, out.arrays["result"], out.arrays["layout"]
    # The pan-head starts where the catenary-only model's equilibrium puts it.
    cat = load_model("seo2005_catenary")
    static = cat.run(cat.resolve({"t_end": 0.0})).summary
    # The summary is the catenary-only model's plus the wheels'.
    moving = cat.run(cat.resolve({"t_end": 0.01, "n_out": 100})).summary
    assert set(moving) <= set(s), sorted(set(moving) - set(s))
    assert {"wheel_normal_force_static_N", "wheel_normal_force_min_N", "wheel_normal_force_max_N"} <= set(s)
    np.testing.assert_allclose(s["static_contact_force_N"], static["static_contact_force_N"], rtol=1e-8)
    # (at 17 m/s the sliding point follows the sagging wire: m v^2 kappa ~ 0.1 N more than at rest)
    np.testing.assert_allclose(-res.reactions_N["contact"][0, 2], static["static_contact_force_N"], rtol=3e-3)
    assert s["contact_loss_percent"] == 0.0
    # The 8-element wire lies within one element window, which never moves: the driver groups
    # the 10 output intervals into one integrator call (one per interval when windows move).
    assert res.stats["contact_calls"] <= 2
    # Vertical wheel forces = vehicle weight + pantograph weight + the wire pushing the pan-head down.
    forces = wheel_forces(res, layout)
    q_sum = sum(forces[n]["Q_N"] for n in layout.contact_names)
    pantograph_kg = 8.0 + 8.0 + 4.0 + 2.0
    wire_push = -res.reactions_N["contact"][:, 2]         # force of the wire on the pan-head, downward
    expected = (layout.parameters.total_mass_kg + pantograph_kg) * G + wire_push
    np.testing.assert_allclose(q_sum[0], expected[0], rtol=1e-6)   # the preloads include the pantograph
    np.testing.assert_allclose(q_sum, expected, rtol=1e-4)
    assert max(s["wheelset_lateral_displacement_max_m"]) < 1e-6
    assert min(s["wheel_normal_force_min_N"]) > 0.95 * min(s["wheel_normal_force_static_N"])


def test_complete_scene_bad_input_names_the_item():
    from symcat.errors import ParameterError
    import pytest

    with pytest.raises(ParameterError, match=r"start=70 m: the pantograph must start on the wire"):
        load_model("seo2005").run({**load_model("seo2005").resolve({"start": 70.0}), "progress": False})
    with pytest.raises(ParameterError, match="lateral_offset_m"):
        load_model("seo2005").resolve({"lateral_offset_m": 0.02})
