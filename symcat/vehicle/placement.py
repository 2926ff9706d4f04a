"""Place a wheelset on the track: both wheels touching their rails (the initial state of a
multibody run with :class:`symcat.scene.WheelRailJoint` contacts), on tangent track or at a
chainage of a curved track layout.

Here, with the scene builders, and not in :mod:`symcat.wheelrail`: the placement is a scene's
initial state (the rigid body's coordinates, :func:`symcat.scene.rigid.euler_parameters`), and
the wheel/rail geometry stays below the scene (``tests/test_layers.py``)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SolverError
from ..scene.rigid import euler_parameters
from ..wheelrail.constraint_contact import ContactPoint, WheelRailContact
from ..wheelrail.geometry import TrackCrossSection, WheelsetDimensions, contact_geometry
from ..wheelrail.identity_memo import IdentityMemo
from ..wheelrail.track import TrackLayout
from ..wheelrail.track_pieces import cross_section_of


@dataclass
class WheelsetPlacement:
    """A wheelset resting on both rails.

    Attributes
    ----------
    position_m : ndarray (3,)
        Axle centre, global (m).
    rotation : ndarray (3, 3)
        Wheelset axes in global components (columns; the axle is the second).
    roll_rad, yaw_rad : float
        Roll (left wheel up) and yaw angles (rad).
    contacts : dict
        ``{"left": ContactPoint, "right": ContactPoint}`` of the 3D constraint contact.
    """

    position_m: np.ndarray
    rotation: np.ndarray
    roll_rad: float
    yaw_rad: float
    contacts: dict


#: The 2D rest geometry (:func:`contact_geometry`) per profile pair, shift, cross-section and
#: wheelset: a vehicle's four wheelsets start from the same (20 ms each).
_REST_2D = IdentityMemo(8)


def _rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def _rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def wheelset_on_track(wheel, rail, lateral_shift_m: float = 0.0, *, x_m: float = 0.0, yaw_rad: float = 0.0,
                      wheelset: WheelsetDimensions | None = None, track=None, cant_rad: float = 0.0,
                      tol_m: float = 1e-12, track_piece_length_m: float = 1.0) -> WheelsetPlacement:
    """The height and roll angle at which both wheels of a wheelset touch their rails.

    The 2D contact geometry (:func:`symcat.wheelrail.contact_geometry` with roll) gives the
    start; Newton's method on the two normal gaps of the 3D constraint contact
    (:class:`WheelRailContact`) in height and roll finishes, so the result is consistent with
    the kernels to ``tol_m``. The wheelset is placed in the (canted) track frame at ``x_m``: its
    axle centre at ``lateral_shift_m`` and the height found, its axes those of the track frame
    turned by the roll found and by ``yaw_rad`` (so on a curve it stands radially for zero yaw).

    Parameters
    ----------
    wheel, rail : Profile
    lateral_shift_m : float
        Lateral displacement of the axle centre toward the left rail, in the track frame (m).
    x_m : float
        Position along the track (m): global ``x`` on tangent track, the chainage on a layout.
    yaw_rad : float
        Yaw angle relative to the track tangent (rad), ``|yaw| < 0.1``.
    wheelset, track, cant_rad, track_piece_length_m
        As for :class:`~symcat.wheelrail.constraint_contact.WheelRailContact` (``track`` a
        :class:`~symcat.wheelrail.TrackCrossSection`, ``None`` or a
        :class:`~symcat.wheelrail.track.TrackLayout`).
    tol_m : float
        Largest gap left (m).

    Raises
    ------
    ParameterError
        If the wheelset does not fit on the rails at that shift (names the shift), or ``x_m``
        lies off the layout.
    """
    if not (isinstance(yaw_rad, (int, float)) and abs(yaw_rad) < 0.1):
        raise ParameterError(f"yaw_rad={yaw_rad!r}: must be a number with |yaw_rad| < 0.1 rad")
    if not (isinstance(lateral_shift_m, (int, float)) and abs(lateral_shift_m) < 0.05):
        raise ParameterError(f"lateral_shift_m={lateral_shift_m!r}: must be a number with |shift| < 0.05 m")
    wheelset = wheelset or WheelsetDimensions()
    if isinstance(track, TrackLayout):
        if not (isinstance(x_m, (int, float)) and 0.0 <= x_m <= track.length_m):
            raise ParameterError(f"x_m={x_m!r}: must lie on the track layout, 0 <= x_m <= {track.length_m:g} m")
        frame = track.track_frame(x_m)
        centre, axes = frame.R[0], frame.A[0]
        cross = cross_section_of(track, rail)
    else:
        cross = track or TrackCrossSection()
        centre, axes = np.array([float(x_m), 0.0, 0.0]), _rot_x(cant_rad)
    geo = _REST_2D.get((wheel, rail), (float(lateral_shift_m), cross, wheelset),
                       lambda: contact_geometry(wheel, rail, [lateral_shift_m], track=cross, wheelset=wheelset,
                                                roll=True))
    contacts = {side: WheelRailContact(wheel, rail, side, wheelset=wheelset, track=track, cant_rad=cant_rad,
                                       track_piece_length_m=track_piece_length_m)
                for side in ("left", "right")}
    x = np.array([float(geo.axle_height_m[0]), float(geo.roll_angle_rad[0])])
    guesses = {}

    def state(x):
        rot = axes @ _rot_x(x[1]) @ _rot_z(yaw_rad)
        return centre + axes @ np.array([0.0, lateral_shift_m, x[0]]), rot

    def gaps(x):
        pos, rot = state(x)
        q = np.r_[pos, euler_parameters(rot)]
        points = {}
        for side, c in contacts.items():
            points[side] = c.solve(q, guesses.get(side))
            guesses[side] = points[side].s
        return np.array([points["left"].gap_m, points["right"].gap_m]), points

    try:
        g, points = gaps(x)
        for _ in range(30):
            if np.abs(g).max() <= tol_m:
                break
            jac = np.empty((2, 2))
            for j, h in enumerate((1e-7, 1e-7)):
                dx = np.zeros(2)
                dx[j] = h
                jac[:, j] = (gaps(x + dx)[0] - g) / h
            x = x - np.linalg.solve(jac, g)
            g, points = gaps(x)
        else:
            raise SolverError(f"gaps {g} m after 30 Newton steps")
    except (SolverError, np.linalg.LinAlgError) as err:
        raise ParameterError(f"lateral_shift_m={lateral_shift_m:g}: the wheelset cannot rest on both rails ({err})") from None
    pos, rot = state(x)
    return WheelsetPlacement(pos, rot, float(x[1]), float(yaw_rad), points)


__all__ = ["ContactPoint", "WheelsetPlacement", "wheelset_on_track"]
