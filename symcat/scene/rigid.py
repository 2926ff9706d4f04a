"""Rigid bodies: mass, inertia and initial state; orientation by Euler parameters."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from .sections import require_positive


def euler_parameters(rotation: np.ndarray) -> np.ndarray:
    """Euler parameters ``[e0, e1, e2, e3]`` (e0 >= 0) of a rotation matrix."""
    a = np.asarray(rotation, dtype=float)
    tr = np.trace(a)
    if tr > 0:
        e0 = 0.5 * np.sqrt(1 + tr)
        e = np.array([a[2, 1] - a[1, 2], a[0, 2] - a[2, 0], a[1, 0] - a[0, 1]]) / (4 * e0)
        return np.r_[e0, e]
    k = int(np.argmax(np.diag(a)))
    i, j = (k + 1) % 3, (k + 2) % 3
    ek = 0.5 * np.sqrt(1 + 2 * a[k, k] - tr)
    out = np.zeros(4)
    out[1 + k] = ek
    out[0] = (a[j, i] - a[i, j]) / (4 * ek)
    out[1 + i] = (a[i, k] + a[k, i]) / (4 * ek)
    out[1 + j] = (a[j, k] + a[k, j]) / (4 * ek)
    return out if out[0] >= 0 else -out


def rotation_matrix(theta: np.ndarray) -> np.ndarray:
    e0, e = theta[0], np.asarray(theta[1:4])
    skew = np.array([[0, -e[2], e[1]], [e[2], 0, -e[0]], [-e[1], e[0], 0]])
    return (2 * e0**2 - 1) * np.eye(3) + 2 * (np.outer(e, e) + e0 * skew)


def g_bar(theta: np.ndarray) -> np.ndarray:
    e0, e1, e2, e3 = theta
    return np.array([[-e1, e0, e3, -e2], [-e2, -e3, e0, e1], [-e3, e2, -e1, e0]])


#: The coordinates a :class:`RigidBody` may hold (``held``).
HELD = ("x", "y", "z", "rotation")


@dataclass
class RigidBody:
    """A rigid body (reference coordinates: frame origin at the centre of mass, Euler parameters).

    Parameters
    ----------
    name : str
        Unique name in the scene.
    mass : float
        Mass (kg).
    inertia : sequence
        Inertia about the centre of mass in the body frame (kg m^2): 3 principal values or a
        3x3 matrix.
    position : sequence of 3 floats
        Initial centre of mass (m).
    rotation : 3x3 array, optional
        Initial orientation (body axes in global components, as columns).
    velocity, angular_velocity : sequence of 3 floats
        Initial velocity (m/s) and angular velocity in global components (rad/s).
    held : sequence of str
        Coordinates held at their initial values, any of ``"x"``, ``"y"``, ``"z"`` (the
        centre of mass) and ``"rotation"`` (the four Euler parameters): eliminated from the
        equations of motion like the pinned nodal coordinates of an ANCF body, instead of
        removed by joints to the ground and their multipliers. A body that only translates
        along one or two axes (a lumped pantograph's stages) costs one or two unknowns instead
        of seven coordinates and six constraint rows. Their initial velocities must be zero.
    """

    name: str
    mass: float
    inertia: object
    position: tuple = (0.0, 0.0, 0.0)
    rotation: np.ndarray | None = None
    velocity: tuple = (0.0, 0.0, 0.0)
    angular_velocity: tuple = (0.0, 0.0, 0.0)
    held: tuple = ()
    J: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        require_positive(f"{self.name}.mass", self.mass)
        j = np.asarray(self.inertia, dtype=float)
        j = np.diag(j) if j.shape == (3,) else j
        if j.shape != (3, 3) or not np.allclose(j, j.T) or np.any(np.linalg.eigvalsh(j) <= 0):
            raise ParameterError(f"{self.name}.inertia={self.inertia}: must be 3 positive values or a symmetric positive definite 3x3 matrix (kg m^2)")
        self.J = j
        rot = np.eye(3) if self.rotation is None else np.asarray(self.rotation, dtype=float)
        if rot.shape != (3, 3) or not np.allclose(rot.T @ rot, np.eye(3), atol=1e-9) or np.linalg.det(rot) < 0:
            raise ParameterError(f"{self.name}.rotation: must be a proper 3x3 rotation matrix")
        self.rotation = rot
        self.held = tuple(self.held)
        unknown = [h for h in self.held if h not in HELD]
        if unknown:
            raise ParameterError(f"{self.name}.held={self.held!r}: {', '.join(map(repr, unknown))} not a coordinate; "
                                 f"allowed: {', '.join(HELD)}")
        moving = [a for k, a in enumerate("xyz") if a in self.held and self.velocity[k] != 0]
        if moving or ("rotation" in self.held and np.any(np.asarray(self.angular_velocity, float) != 0)):
            raise ParameterError(f"{self.name}.held={self.held!r}: a held coordinate must start at rest (velocity "
                                 f"{tuple(self.velocity)} m/s, angular velocity {tuple(self.angular_velocity)} rad/s)")

    @property
    def held_mask(self) -> np.ndarray:
        """Which of the 7 coordinates ``[x, y, z, e0..e3]`` are held (:attr:`held`)."""
        mask = np.array([a in self.held for a in "xyz"] + ["rotation" in self.held] * 4)
        return mask

    @property
    def params(self) -> np.ndarray:
        """Kernel parameters ``[mass, Jxx, Jyy, Jzz, Jxy, Jxz, Jyz]``."""
        j = self.J
        return np.array([self.mass, j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2]])

    @property
    def q0(self) -> np.ndarray:
        return np.r_[np.asarray(self.position, float), euler_parameters(self.rotation)]

    @property
    def v0(self) -> np.ndarray:
        theta = euler_parameters(self.rotation)
        omega_bar = self.rotation.T @ np.asarray(self.angular_velocity, float)
        return np.r_[np.asarray(self.velocity, float), 0.5 * g_bar(theta).T @ omega_bar]

    def local(self, point) -> np.ndarray:
        """Body-frame coordinates of a global point of the initial configuration."""
        return self.rotation.T @ (np.asarray(point, float) - np.asarray(self.position, float))

    def local_vector(self, vector) -> np.ndarray:
        return self.rotation.T @ np.asarray(vector, float)
