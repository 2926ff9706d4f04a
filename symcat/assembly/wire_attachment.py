"""A rigid body attached to an ANCF wire at an arc length (a sliding joint or a penalty
contact of :class:`~symcat.assembly.multibody.MultibodyModel`): the checks of the attachment
and the record the model keeps of it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..scene.ancf import AncfBody
from ..scene.joints import SlidingJoint
from ..scene.rigid import RigidBody


@dataclass
class Sliding:
    """A body on a wire as the model keeps it: the joint or contact, the wire and the body,
    the kernel library, the arc length's index, the wire's element starts and coordinate
    indices, the kernels' parameters and the current element window."""

    joint: SlidingJoint
    wire: AncfBody
    body: RigidBody
    library: str
    s_index: int
    element_start: np.ndarray      # arc length at the start of each element (m)
    element_indices: np.ndarray    # (n_el, n_loc) global coordinate indices
    params: np.ndarray
    window: tuple[int, int] = (0, 0)


def wire_attachment(scene, kind: str, name: str, wire_name: str, body_name: str, s0: float):
    """Check a rigid body attached to an ANCF wire at arc length ``s0`` (sliding joint or
    contact); returns the wire, the body and the arc length at each element start (m)."""
    wire = scene.find(wire_name)
    body = scene.find(body_name)
    if not isinstance(body, RigidBody):
        raise ParameterError(f"{kind} {name!r}: body={body_name!r} must be a rigid body")
    if wire.element.name not in ("cable3d", "beam3d"):
        raise ParameterError(f"{kind} {name!r}: wire {wire.name!r} is {wire.element.name}; a {kind} needs cable3d or beam3d")
    starts = np.concatenate([[0.0], np.cumsum(wire.params[:, 0])])
    if kind == "contact":  # a contact may start on the wire's straight continuation past an end
        if not np.isfinite(s0):
            raise ParameterError(f"{kind} {name!r}: s0={s0!r} m must be a finite arc length")
    elif not 0 <= s0 <= starts[-1]:
        raise ParameterError(f"{kind} {name!r}: s0={s0:g} m must lie on the wire, in [0, {starts[-1]:g}] m")
    return wire, body, starts
