"""The solution of a wheel/rail contact-point problem (:class:`ContactPoint`), described on demand,
and the small linear solve of its Newton steps (:func:`solve_small`)."""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from scipy.linalg.lapack import dgesv as _dgesv


def _described(name: str, doc: str) -> property:
    """A :class:`ContactPoint` attribute taken from its description (computed on first access)."""
    return property(lambda self: self._description[name], doc=doc)


@dataclass
class ContactPoint:
    """Solution of the contact-point problem for a given wheelset position.

    The geometric description (radius, angle, lateral positions, point, normal) is computed on
    first access: the searches for local minima (:mod:`.gap_minima`) solve many points and use
    only their parameters and gaps.

    Attributes
    ----------
    s : ndarray (4,)
        Surface parameters ``[s1w, s2w, s1r, s2r]``.
    gap_m : float
        Normal gap along the rail's outward normal [m] (positive: separated, negative:
        penetration); the fifth constraint's value.
    residual : float
        Largest absolute value of the four conditions solved.
    iterations : int
        Newton iterations.
    contact : symcat.wheelrail.constraint_contact.WheelRailContact
        The contact solved (it describes the point).
    kernels : ContactKernels or None
        The contact's kernels at ``s`` (with ``clip``), as the solve's last evaluation left them.
    rolling_radius_m : float
        Wheel radius at the contact point [m].
    contact_angle_rad : float
        Inclination of the common tangent to the track plane [rad], positive when the wheel's
        contact normal points toward the track centre (convention of :mod:`.geometry`).
    wheel_y_m, rail_y_m : float
        Lateral coordinates of the contact point on the wheel and rail profiles [m].
    point_m : ndarray (3,)
        Contact point on the rail, global [m].
    normal : ndarray (3,)
        Unit outward normal of the rail, global.
    """

    s: np.ndarray
    gap_m: float
    residual: float
    iterations: int
    contact: object = field(repr=False, compare=False)
    kernels: object = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        self._solved_s = np.array(self.s, float)  # described as solved, whatever becomes of s

    @cached_property
    def _description(self) -> dict:
        return self.contact._describe(self._solved_s)

    rolling_radius_m = _described("rolling_radius_m", "Wheel radius at the contact point [m].")
    contact_angle_rad = _described("contact_angle_rad", "Inclination of the common tangent to the track plane [rad].")
    wheel_y_m = _described("wheel_y_m", "Lateral coordinate of the contact point on the wheel profile [m].")
    rail_y_m = _described("rail_y_m", "Lateral coordinate of the contact point on the rail profile [m].")
    point_m = _described("point_m", "Contact point on the rail, global [m].")
    normal = _described("normal", "Unit outward normal of the rail, global.")


def solve_small(a, b) -> np.ndarray:
    """``np.linalg.solve(a, b)`` of a small system without its overhead (LAPACK's ``dgesv``
    directly, 1 us instead of 5: the same result bit for bit).

    Raises
    ------
    numpy.linalg.LinAlgError
        If ``a`` is singular.
    """
    _, _, x, info = _dgesv(a, b)
    if info > 0:
        raise np.linalg.LinAlgError("Singular matrix")
    return x
