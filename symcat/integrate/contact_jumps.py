"""Contact-point jumps of wheel/rail constraint contacts between integrator calls.

A constraint contact follows one stationary point of the wheel/rail gap continuously. On worn or
nearly conformal profiles (S1002 on UIC60, EN 15302 wheel A on rail A) the lowest point jumps:
another point of the profiles comes into contact while the followed one lifts off. Between two
integrator calls the driver asks :meth:`WheelRailContact.solve` for the lowest point of each
wheel from scratch; where it lies elsewhere on the profiles and lower (penetrating) than the
followed one, the surface parameters move there and the state is projected back onto the
constraints (positions, then velocities: the minimum-norm change, an impact-like velocity jump)
before IDAS restarts. The rest of the run is the constraint formulation unchanged.

On curved track the search is the same (:meth:`WheelRailContact.solve` projects the wheel onto
the layout's cross-sections); a contact whose point has left the layout's defined length ends
the run with a :class:`SolverError` naming it (the kernels would extrapolate the end piece).
"""
from __future__ import annotations

import math

import numpy as np

from ..dae.initial import consistent_state
from ..errors import ParameterError, SolverError
from .failure import split_state

#: A lowest point this much below the followed one (m) triggers a jump.
JUMP_TOLERANCE_M = 1e-7
#: Points closer than this along the wheel profile (m) are the same contact.
SAME_POINT_M = 1e-4


def jump_contacts(form, x, z, t: float):
    """``(x, z, names)``: the state after moving every wheel/rail contact whose lowest point is
    elsewhere (``names`` lists them; unchanged state and an empty list if none)."""
    model = form.model
    if not model.wheelrail:
        return x, z, []
    parts = split_state(form, x, z)
    q_full = model.q0.copy()
    q_full[model.free] = form.to_physical(parts["q"])
    s = parts["s"].copy()
    jumped = []
    for e in model.wheelrail:
        q_body = q_full[e.rows]
        i = e.s_index
        current = s[i : i + 4]
        try:
            e.contact.frames.check(current[2])
        except ParameterError as err:
            raise SolverError(f"wheel/rail contact {e.joint.name!r} at t = {t:.6g} s: {err}") from None
        try:
            lowest = e.contact.solve(q_body)
        except SolverError:
            continue
        if lowest.gap_m < e.contact.gap(q_body, current) - JUMP_TOLERANCE_M and abs(lowest.s[0] - current[0]) > SAME_POINT_M:
            new = lowest.s.copy()
            # Keep the wheel angle continuous (it counts revolutions).
            new[1] = current[1] + math.remainder(new[1] - current[1], 2 * math.pi)
            s[i : i + 4] = new
            jumped.append(e.joint.name)
    if not jumped:
        return x, z, []
    start = {"q": parts["q"], "v": parts["v"], "s": s, "w": parts.get("w", np.zeros(form.n_s)),
             "sc": parts.get("sc", np.zeros(form.n_sc))}
    x_new, z_new = consistent_state(form, t, start=start)
    return x_new, z_new, jumped
