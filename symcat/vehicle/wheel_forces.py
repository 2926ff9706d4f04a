"""Wheel forces of a simulated vehicle: the contact force on each wheel, its lateral and
vertical components and the derailment quotient Y/Q."""
from __future__ import annotations

import numpy as np


def wheel_forces(result, layout) -> dict:
    """Contact force components of every wheel over time.

    The force the rail exerts on the wheel is the constraint force of the contact (its normal
    force, from the multipliers: ``result.reactions_N``) plus the creep forces along the contact
    frame ``t1 = x`` (rolling direction of tangent track) and ``t2 = n x t1``.

    Returns
    -------
    dict
        ``{contact name: {"Y_N", "Q_N", "Y_over_Q", "normal_N"}}`` (arrays over the outputs):
        ``Q_N`` the vertical force on the wheel (N), ``Y_N`` the lateral force on the wheel,
        positive toward the track centre (the direction a flange contact pushes the wheel;
        Nadal's criterion bounds ``Y / Q``), and the normal force.
    """
    out = {}
    t1 = np.array([1.0, 0.0, 0.0])
    for wheelset in layout.wheelsets:
        for side, name in layout.contacts[wheelset].items():
            reaction = np.asarray(result.reactions_N[name], float)
            rec = result.wheelrail[name]
            n = reaction / np.maximum(np.linalg.norm(reaction, axis=1, keepdims=True), 1e-300)
            t2 = np.cross(n, t1)
            force = reaction + rec["fx_N"][:, None] * t1 + rec["fy_N"][:, None] * t2
            inward = -1.0 if side == "left" else 1.0   # the left rail is at +y
            y_n, q_n = inward * force[:, 1], force[:, 2]
            out[name] = {"Y_N": y_n, "Q_N": q_n, "Y_over_Q": y_n / np.where(np.abs(q_n) > 0, q_n, np.nan),
                         "normal_N": np.asarray(rec["normal_force_N"], float)}
    return out
