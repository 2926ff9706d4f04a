"""Force elements of a multibody scene (point loads, spring-dampers, rotational springs, penalty
wire contacts) as groups of compiled kernel instances."""
from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..scene.contact import PenaltyContact
from ..scene.forces import Bushing, PointLoad, RotationalSpring, SpringDamper
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
        values.update(phi0=force.angle0, k=force.stiffness, c=force.damping, rate=force.rate)
        model._add(f"rotspring_{a.kind}_{b.kind}", force.name, [a, b], values, model.force_groups)
        return
    if isinstance(force, Bushing):
        add_bushing(model, force)
        return
    raise ParameterError(f"unsupported force element {type(force).__name__}")


def add_bushing(model, force: Bushing) -> None:
    """Record a :class:`Bushing`: its point and axes in both bodies' frames and its law."""
    a, b = model.side(force.body_i, force.at), model.side(force.body_j, force.at)
    if a.kind != "rigid" or b.kind not in ("rigid", "ground"):
        raise ParameterError(f"bushing {force.name!r}: body_i must be a rigid body and body_j a rigid body or 'ground'")
    axes = np.eye(3) if force.axes is None else np.asarray(force.axes, float)
    if axes.shape != (3, 3) or not np.allclose(axes @ axes.T, np.eye(3), atol=1e-9) or np.linalg.det(axes) < 0:
        raise ParameterError(f"bushing {force.name!r}: axes={force.axes}: rows must be orthonormal and right-handed")
    values = {f"ui_{k}": a.local["u"][k] for k in range(3)}
    values.update({f"uj_{k}": b.local["u"][k] for k in range(3)})
    model._vectors(values, a, "i", x=axes[0], y=axes[1], z=axes[2])
    model._vectors(values, b, "j", x=axes[0], y=axes[1], z=axes[2])
    for attr, key in Bushing.LAW:
        vec = np.asarray(getattr(force, attr), float)
        if vec.shape != (3,) or not np.all(np.isfinite(vec)):
            raise ParameterError(f"bushing {force.name!r}: {attr}={getattr(force, attr)}: give 3 finite values")
        if attr != "preload" and np.any(vec < 0):
            raise ParameterError(f"bushing {force.name!r}: {attr}={tuple(vec.tolist())}: must be >= 0 "
                                 f"({dict(Bushing.UNITS)[attr]})")
        values.update({f"{key}_{k}": vec[k] for k in range(3)})
    model._add(f"bushing_{a.kind}_{b.kind}", force.name, [a, b], values, model.force_groups)
