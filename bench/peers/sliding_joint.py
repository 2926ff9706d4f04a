"""Problem 1: a cuboid hanging from a 3D sliding joint on a damped ANCF wire (Exudyn's example
``ANCFslidingJoint.py``).

Wire along x, L = 2 m, r = 0.01 m, 7800 pi r^2 kg/m, EA = 2.5e4 N, EI = 1 N m^2, no prestrain,
48 elements; ends: positions and the y, z slopes fixed. Gravity -9.81 m/s^2 along y. Cuboid
0.05 x 0.36 x 0.10 m, 15600 kg/m^3, centre of mass at (0.2, -0.2, -0.05) m, attached at its
body point (0, 0.2, 0.05) m to the wire at s0 = 0.2 m by a frictionless sliding joint (three
position constraints, rotations free). From rest, 2 s, output every 0.01 s. Error: the largest
distance of the attachment point from the code's own reference over the outputs.

The damping laws differ. Exudyn: ``physicsAxialDamping = 0.02 EA`` and
``physicsBendingDamping = 0.02 EI``, the virtual work of the strain rates eps_dot and K_dot with
eps = |r'| - 1 and K = r' x r'' / |r'|^2. symcat: Kelvin-Voigt time constants of 0.02 s on
its axial and bending strain rates (``damping_axial``, ``damping_bending`` of
:meth:`~symcat.scene.AncfBody.straight`), whose axial force is about (1 + eps)^2 times
Exudyn's at the wire's 2-3 % strain; the physics-match row of the report gives the difference
of the two references.
"""
from __future__ import annotations

import numpy as np

from .common import exudyn_solve, symcat_solve

L, R, EA, EI, DAMPING = 2.0, 0.01, 2.5e4, 1.0, 0.02
MU = 7800 * np.pi * R**2
SIDES = (0.05, 0.36, 0.10)
DENSITY = 15600.0
CENTRE = (0.2, -0.2, -0.05)
ATTACH = np.array([0.0, 0.2, 0.05])
S0, T_END, N_OUT, N_ELEMENTS = 0.2, 2.0, 200, 48


def _mass_inertia():
    a, b, c = SIDES
    m = DENSITY * a * b * c
    return m, (m * (b**2 + c**2) / 12, m * (a**2 + c**2) / 12, m * (a**2 + b**2) / 12)


def symcat_model(n_elements=N_ELEMENTS, window=16):
    from symcat.assembly.multibody import MultibodyModel
    from symcat.scene import AncfBody, Material, RigidBody, Scene, Section, SlidingJoint

    modulus = 1e9
    section = Section.from_stiffness(EA, EI, modulus)
    wire = AncfBody.straight("wire", "cable3d", [0, 0, 0], [L, 0, 0], n_elements,
                             Material(E=modulus, rho=MU / section.A), section,
                             damping_axial=DAMPING, damping_bending=DAMPING)
    wire.pin(0).pin(-1).fix(0, ["y_x", "z_x"]).fix(-1, ["y_x", "z_x"])
    scene = Scene(gravity=(0.0, -9.81, 0.0))
    scene.add(wire)
    mass, inertia = _mass_inertia()
    scene.add(RigidBody("body", mass, inertia, CENTRE))
    scene.add(SlidingJoint("slider", "wire", "body", s0=S0, at=(S0, 0.0, 0.0), reference_direction=(0, 1, 0)))
    return MultibodyModel(scene, window=window)


def symcat_run(setting: dict, n_elements=N_ELEMENTS) -> np.ndarray:
    """Attachment-point positions (201 x 3) for ``{"rtol": ...}`` (IDAS) or ``{"dt": ...}``
    (generalized-alpha, spectral radius 0.9 as Exudyn's)."""
    from symcat.scene.rigid import rotation_matrix

    model = symcat_model(n_elements, setting.get("window", 16))
    q = symcat_solve(model, T_END, N_OUT, setting, 0.9)
    off = model.rigid_offset["body"]
    return np.array([row[off:off + 3] + rotation_matrix(row[off + 3:off + 7]) @ ATTACH for row in q])


def exudyn_run(setting: dict, n_elements=N_ELEMENTS) -> np.ndarray:
    """Attachment-point positions (201 x 3) for ``{"dt": ...}`` (generalized-alpha, index 3,
    spectral radius 0.9 (Exudyn's default), modified Newton, as the example)."""
    import exudyn as exu
    from exudyn.beams import GenerateStraightLineANCFCable
    from exudyn.utilities import (InertiaCuboid, MarkerBodyBeamShape, MarkerBodyRigid, NodeGenericData,
                                  ObjectANCFCable, ObjectJointSliding, SensorBody)

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    cable = ObjectANCFCable(physicsMassPerLength=MU, physicsBendingStiffness=EI, physicsBendingDamping=DAMPING * EI,
                            physicsAxialStiffness=EA, physicsAxialDamping=DAMPING * EA)
    ancf = GenerateStraightLineANCFCable(mbs=mbs, positionOfNode0=[0, 0, 0], positionOfNode1=[L, 0, 0],
                                         numberOfElements=n_elements, cableTemplate=cable,
                                         massProportionalLoad=[0, -9.81, 0],
                                         fixedConstraintsNode0=[1, 1, 1, 0, 1, 1],
                                         fixedConstraintsNode1=[1, 1, 1, 0, 1, 1])
    h = L / n_elements
    body = mbs.CreateRigidBody(referencePosition=list(CENTRE), inertia=InertiaCuboid(DENSITY, list(SIDES)),
                               gravity=[0, -9.81, 0])
    top = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body, localPosition=list(ATTACH)))
    markers = [mbs.AddMarker(MarkerBodyBeamShape(bodyNumber=e)) for e in ancf[1]]
    first = int(S0 / h)
    data = mbs.AddNode(NodeGenericData(initialCoordinates=[first, S0], numberOfDataCoordinates=2))
    mbs.AddObject(ObjectJointSliding(markerNumbers=[top, markers[first]], constrainRotations=[0, 0, 0],
                                     slidingMarkerNumbers=markers, slidingMarkerOffsets=[k * h for k in range(n_elements)],
                                     nodeNumber=data))
    sensor = mbs.AddSensor(SensorBody(bodyNumber=body, localPosition=list(ATTACH), storeInternal=True,
                                      writeToFile=False, outputVariableType=exu.OutputVariableType.Position))
    out = exudyn_solve(exu, mbs, sensor, T_END, N_OUT, setting, 0.9)
    grid = np.linspace(0.0, T_END, N_OUT + 1)
    return np.array([out[np.argmin(np.abs(out[:, 0] - t)), 1:4] for t in grid])


def error(out: np.ndarray, reference: np.ndarray) -> float:
    return float(np.linalg.norm(out - reference, axis=1).max())


SYMCAT_IDAS = [{"rtol": r} for r in (1e-2, 1e-3, 1e-4, 1e-5)]
SYMCAT_ALPHA = [{"dt": d, "tol": 1e-8} for d in (1e-2, 5e-3, 2.5e-3, 1e-3, 5e-4)]
EXUDYN = [{"dt": d} for d in (2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5)]
SYMCAT_REFERENCE = {"dt": 2.5e-5, "tol": 1e-12}
EXUDYN_REFERENCE = {"dt": 2.5e-5, "newton_rtol": 1e-10}
