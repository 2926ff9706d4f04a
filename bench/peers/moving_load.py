"""Problem 2: a force moving along a taut wire at half the wave speed.

L = 60 m, T = 20 kN, mass 1.35 kg/m, EI = 195 N m^2, EA = 1.8e7 N, pinned ends, planar, no
gravity, no damping. A 100 N force in -y enters at x = 0 at t = 0 and moves at v = 0.5 c
(c = sqrt(T / mu)) until it leaves at t = L / v. Output: the mid-span deflection at 201 equally
spaced times. Error: its largest difference from the code's own reference.

How each code states the load:

- Exudyn: ``ObjectANCFCable2D`` with ``physicsReferenceAxialStrain = -T / EA``, the load as
  consistent nodal forces (the element's Hermite shape functions at the load's arc length
  ``v t``) through load user functions on the nodes' y and y' coordinates.
- symcat has no moving nodal load: a point body of :data:`BODY_MASS` (rotation held) hangs on
  the wire by a :class:`~symcat.scene.SlidingJoint`, is driven along x at v
  (:class:`~symcat.scene.Driving`) and carries the force (:class:`~symcat.scene.PointLoad`); the
  wire is ``cable3d`` (the sliding joint needs it), prestrained by T / EA, and stays in its
  plane. The load then acts where the deformed wire's x is ``v t`` (Exudyn: at the material
  point ``s = v t``) and the body adds its inertia; the physics-match row says by how much
  the two references differ.
"""
from __future__ import annotations

import numpy as np

from .common import exudyn_solve, symcat_solve

L, T, MU, EI, EA, FORCE = 60.0, 20e3, 1.35, 195.0, 1.8e7, 100.0
SPEED = 0.5 * np.sqrt(T / MU)
T_END = L / SPEED
N_OUT = 200
N_ELEMENTS = 60
BODY_MASS = 1e-3


def symcat_model(n_elements=N_ELEMENTS):
    from symcat.assembly.multibody import MultibodyModel
    from symcat.scene import AncfBody, Driving, Material, PointLoad, RigidBody, Scene, Section, SlidingJoint

    modulus = 1e11
    section = Section.from_stiffness(EA, EI, modulus)
    prestrain = T / EA
    wire = AncfBody.straight("wire", "cable3d", [0, 0, 0], [L, 0, 0], n_elements,
                             Material(E=modulus, rho=MU * (1 + prestrain) / section.A), section, prestrain=prestrain)
    wire.pin(0).pin(-1)
    scene = Scene(gravity=(0.0, 0.0, 0.0))
    scene.add(wire)
    j = 1e-3 * BODY_MASS
    scene.add(RigidBody("load", BODY_MASS, (j, j, j), (0.0, 0.0, 0.0), held=("rotation",)))
    scene.add(SlidingJoint("slider", "wire", "load", s0=0.0, at=(0.0, 0.0, 0.0), reference_direction=(0, 0, 1)))
    scene.add(Driving("drive", "load", direction=(1.0, 0.0, 0.0), velocity=SPEED))
    scene.add(PointLoad("force", "load", force=(0.0, -FORCE, 0.0)))
    model = MultibodyModel(scene)
    mid = model.ancf.dofs.node_indices(wire, n_elements // 2)[1]
    return model, mid


def symcat_run(setting: dict, n_elements=N_ELEMENTS) -> np.ndarray:
    """Mid-span deflections (201) for ``{"rtol": ...}`` (IDAS) or ``{"dt": ..., "rho": ...}``."""
    model, mid = symcat_model(n_elements)
    q = symcat_solve(model, T_END, N_OUT, setting, 1.0)
    return q[:, mid]


def exudyn_run(setting: dict, n_elements=N_ELEMENTS) -> np.ndarray:
    """Mid-span deflections (201) for ``{"dt": ...}`` (generalized-alpha, spectral radius 1)."""
    import exudyn as exu
    from exudyn.beams import GenerateStraightLineANCFCable2D
    from exudyn.utilities import Cable2D, LoadCoordinate, MarkerNodeCoordinate, SensorNode

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    cable = Cable2D(physicsMassPerLength=MU, physicsBendingStiffness=EI, physicsAxialStiffness=EA,
                    physicsReferenceAxialStrain=-T / EA)
    nodes = GenerateStraightLineANCFCable2D(mbs, [0, 0, 0], [L, 0, 0], n_elements, cable,
                                            fixedConstraintsNode0=[1, 1, 0, 0], fixedConstraintsNode1=[1, 1, 0, 0])[0]
    h = L / n_elements

    def shape(t, node, kind):
        """Consistent nodal force (N) or moment-like slope load (N m) of node ``node``."""
        s = SPEED * t
        if s >= L:
            return 0.0
        e = min(int(s / h), n_elements - 1)
        if node not in (e, e + 1):
            return 0.0
        xi = s / h - e
        if node == e:
            n = 1 - 3 * xi**2 + 2 * xi**3 if kind == 0 else h * (xi - 2 * xi**2 + xi**3)
        else:
            n = 3 * xi**2 - 2 * xi**3 if kind == 0 else h * (-(xi**2) + xi**3)
        return -FORCE * n

    for k, node in enumerate(nodes):
        for kind, coordinate in ((0, 1), (1, 3)):
            marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=coordinate))
            mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=0.0,
                                       loadUserFunction=lambda mbs_, t, load, k=k, kind=kind: shape(t, k, kind)))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=nodes[n_elements // 2], storeInternal=True, writeToFile=False,
                                      outputVariableType=exu.OutputVariableType.Position))
    data = exudyn_solve(exu, mbs, sensor, T_END, N_OUT, setting, 1.0, modified_newton=False)
    grid = np.linspace(0.0, T_END, N_OUT + 1)
    return np.array([data[np.argmin(np.abs(data[:, 0] - t)), 2] for t in grid])


def error(out: np.ndarray, reference: np.ndarray) -> float:
    return float(np.abs(out - reference).max())


def _steps(k):
    return T_END / (200 * k)


SYMCAT_IDAS = [{"rtol": r} for r in (1e-4, 1e-5, 1e-6)]
SYMCAT_ALPHA = [{"dt": _steps(k), "tol": 1e-8} for k in (1, 2, 4, 8, 16, 32)]
EXUDYN = [{"dt": _steps(k)} for k in (1, 2, 4, 8, 16, 32)]
SYMCAT_REFERENCE = {"dt": _steps(64), "tol": 1e-12}
EXUDYN_REFERENCE = {"dt": _steps(64), "newton_rtol": 1e-10}
