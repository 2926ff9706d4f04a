"""Force elements of a multibody scene (point loads, spring-dampers, rotational springs, penalty
wire contacts) as groups of compiled kernel instances."""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..scene.contact import PenaltyContact
from ..scene.forces import PointLoad, RotationalSpring, SpringDamper
from ..scene.joints import perpendiculars, unit


def add_force(model, force):
    """Record one force element of the scene in ``model`` (a MultibodyModel under construction)."""
    if isinstance(force, PenaltyContact):
        from .contact import add_contact

        model.contacts.append(add_contact(model, force))
        return
    if isinstance(force, PointLoad):
        body = model.scene.find(force.body)
        side = model.side(force.body, body.position if force.at is None else force.at)
        values = {f"ui_{k}": side.local["u"][k] for k in range(3)}
        for key, vec in (("F0", force.force), ("F1", force.force_amplitude), ("T0", force.torque), ("T1", force.torque_amplitude)):
            values.update({f"{key}_{k}": float(vec[k]) for k in range(3)})
        values.update(omega=2 * np.pi * force.frequency, phase=force.phase)
        model._add("pointload_rigid", force.name, [side], values, model.force_groups)
        return
    if isinstance(force, SpringDamper):
        a, b = model.side(force.body_i, force.at_i), model.side(force.body_j, force.at_j)
        order = {"node": 0, "rigid": 1, "ground": 2}  # libraries exist in this order of kinds
        if order[a.kind] > order[b.kind]:
            a, b = b, a
        library = f"springdamper_{a.kind}_{b.kind}"
        if a.kind == "ground":
            raise ParameterError(f"spring-damper {force.name!r}: both ends on the ground")
        length0 = float(np.linalg.norm(np.asarray(force.at_j, float) - np.asarray(force.at_i, float)))
        values = {f"ui_{k}": a.local["u"][k] for k in range(3)}
        values.update({f"uj_{k}": b.local["u"][k] for k in range(3)})
        values.update(l0=length0 if force.free_length is None else force.free_length, k=force.stiffness,
                      k3=force.cubic_stiffness, c=force.damping, tension_only=float(force.tension_only))
        model._add(library, force.name, [a, b], values, model.force_groups)
        return
    if isinstance(force, RotationalSpring):
        a = model.side(force.body_i, model.scene.find(force.body_i).position)
        b = model.side(force.body_j, a.body.position)
        x, _ = perpendiculars(force.axis)
        values = {}
        model._vectors(values, a, "i", z=unit(force.axis), x=x)
        model._vectors(values, b, "j", x=x)
        values.update(phi0=force.angle0, k=force.stiffness, c=force.damping)
        model._add(f"rotspring_{a.kind}_{b.kind}", force.name, [a, b], values, model.force_groups)
        return
    raise ParameterError(f"unsupported force element {type(force).__name__}")
