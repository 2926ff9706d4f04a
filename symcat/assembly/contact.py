"""Assembly of penalty wire contacts (:class:`symcat.scene.PenaltyContact`).

Each contact has an arc length ``s_c`` located, like a sliding joint's, by a global arc-length
map with an element window (see :mod:`symcat.assembly.multibody`). ``s_c`` is not a
generalized coordinate and carries no multiplier: the tangency condition ``T(q, s_c) = 0`` is an
algebraic equation of its own, and the normal penalty force enters the applied forces.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..codegen.library import kernel_library, library_interface
from ..scene.contact import PenaltyContact
from ..scene.joints import unit


def add_contact(model, contact: PenaltyContact):
    """Record of one contact for ``model`` (a :class:`MultibodyModel` under construction)."""
    from .wire_attachment import Sliding, wire_attachment

    wire, body, starts = wire_attachment(model.scene, "contact", contact.name, contact.wire, contact.body, contact.s0)
    library = f"contact_{wire.element.name}_rigid"
    info = library_interface(library)
    u = body.local(body.position if contact.at is None else contact.at)
    d_ref = unit(contact.reference_direction, f"{contact.name}.reference_direction")
    values = {"L": 0.0, **{f"d_ref_{k}": d_ref[k] for k in range(3)}, **{f"uj_{k}": u[k] for k in range(3)},
              "k": contact.stiffness, "c": contact.damping, "delta": contact.smoothing}
    params = np.array([values[p] for p in info["params"]])
    return Sliding(contact, wire, body, library, len(model.contacts), starts,
                   model.ancf.dofs.element_indices(wire), params)


def contact_terms(model, q: ca.MX, v: ca.MX, s_c: ca.MX) -> dict:
    """Generalized contact forces ``Q`` (n_q), tangency residuals ``T``, gaps (m) and normal
    forces (N) of every contact (MX). Off its wire (past an end) a contact's gap is measured to
    the wire's straight continuation and its force is zero."""
    q_total = ca.MX(model.n_q, 1)
    t_parts, gaps, forces = [], [], []
    for k, ct in enumerate(model.contacts):
        lib = kernel_library(ct.library)
        y, y_dot, length, sel = model._sliding_local(ct, q, v, s_c[k], ca.MX(0))
        p = ca.vertcat(length, ca.DM(ct.params[1:]))
        t_parts.append(lib[f"{ct.library}_tangency"](y, p))
        q_loc, gap, force = lib[f"{ct.library}_force"](y, y_dot[:-1], p)
        # Past the wire's ends the point follows its straight continuation (the tangency stays
        # solvable, see ElementWindows._selection) but touches nothing: the wire has ended.
        on_wire = ca.logic_and(s_c[k] >= ct.element_start[0], s_c[k] <= ct.element_start[-1])
        q_loc, force = q_loc * on_wire, force * on_wire
        n_loc = ct.element_indices.shape[1]
        rows = model._rigid_indices(ct.body.name)
        q_total += ca.mtimes(sel.T, q_loc[:n_loc])
        q_total += ca.mtimes(_placement(rows, model.n_q).T, q_loc[n_loc:])
        gaps.append(gap)
        forces.append(force)
    cat = lambda xs: ca.vertcat(*xs) if xs else ca.MX(0, 1)
    return {"Q": q_total, "T": cat(t_parts), "gap": cat(gaps), "force": cat(forces)}


def _placement(cols, n: int) -> ca.DM:
    cols = list(cols)
    return ca.DM(ca.Sparsity.triplet(len(cols), n, list(range(len(cols))), cols), 1.0)
