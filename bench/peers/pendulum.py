"""Problem 4: 3D spinning cable pendulum, 2 s.

L = 1 m along x, mass 8e-3 kg/m, EA = 40 N, EI = 7.9577e-5 N m^2; node 0 pinned (slopes free),
gravity along -y, no damping; initial nodal velocities v_z = -4 x (slopes at rest); tip position
every 0.01 s. Error: the largest distance of the tip from the code's own reference over the 201
outputs. Exudyn: generalized-alpha, spectral radius 0.8, modified Newton, relative tolerance
1e-8. symcat: IDAS (rtol sweep) and generalized-alpha (spectral radius 0.8, step sweep). Both
codes on the same mesh (:data:`N_ELEMENTS`).

symcat's scene has no initial velocities of ANCF nodes: the bench writes them into the
model's initial velocity vector ``MultibodyModel.v0`` before integrating.
"""
from __future__ import annotations

import numpy as np

from .common import exudyn_solve, symcat_solve

L, MU, EA, EI, T_END, N_OUT = 1.0, 8e-3, 40.0, 7.9577e-5, 2.0, 200
N_ELEMENTS = 16


def symcat_model(n_elements=N_ELEMENTS):
    from symcat.assembly.multibody import MultibodyModel
    from symcat.scene import AncfBody, Material, Scene, Section

    modulus = 1e9
    section = Section.from_stiffness(EA, EI, modulus)
    wire = AncfBody.straight("cable", "cable3d", [0, 0, 0], [L, 0, 0], n_elements,
                             Material(E=modulus, rho=MU / section.A), section)
    wire.pin(0)
    scene = Scene(gravity=(0.0, -9.81, 0.0))
    scene.add(wire)
    model = MultibodyModel(scene)
    dofs = model.ancf.dofs
    for k in range(wire.n_nodes):
        idx = dofs.node_indices(wire, k)
        model.v0[idx[2]] = -4.0 * wire.q0[k, 0]
    tip = dofs.node_indices(wire, -1)[:3]
    return model, tip


def symcat_run(setting: dict, n_elements=N_ELEMENTS) -> np.ndarray:
    """Tip positions (201 x 3) for ``{"rtol": ...}`` (IDAS) or ``{"dt": ...}`` (generalized-alpha)."""
    model, tip = symcat_model(n_elements)
    q = symcat_solve(model, T_END, N_OUT, setting, 0.8)
    return q[:, tip]


def exudyn_run(setting: dict, n_elements=N_ELEMENTS) -> np.ndarray:
    """Tip positions (201 x 3) for ``{"dt": ...}``."""
    import exudyn as exu
    from exudyn.beams import GenerateStraightLineANCFCable
    from exudyn.utilities import ObjectANCFCable, SensorNode

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    cable = ObjectANCFCable(physicsMassPerLength=MU, physicsBendingStiffness=EI, physicsAxialStiffness=EA)
    nodes = GenerateStraightLineANCFCable(mbs, [0, 0, 0], [L, 0, 0], n_elements, cable,
                                          massProportionalLoad=[0, -9.81, 0],
                                          fixedConstraintsNode0=[1, 1, 1, 0, 0, 0])[0]
    for k, node in enumerate(nodes):
        x = L * k / n_elements
        mbs.SetNodeParameter(node, "initialVelocities", [0, 0, -4.0 * x, 0, 0, 0])
    sensor = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True, writeToFile=False,
                                      outputVariableType=exu.OutputVariableType.Position))
    data = exudyn_solve(exu, mbs, sensor, T_END, N_OUT, setting, 0.8)
    return _on_grid(data)


def _on_grid(data: np.ndarray) -> np.ndarray:
    """Sensor rows ``[t, x, y, z]`` at the output times (the sensor may add the initial row)."""
    grid = np.linspace(0.0, T_END, N_OUT + 1)
    rows = [data[np.argmin(np.abs(data[:, 0] - t))] for t in grid]
    return np.array([r[1:4] for r in rows])


def error(out: np.ndarray, reference: np.ndarray) -> float:
    return float(np.linalg.norm(out - reference, axis=1).max())


SYMCAT_IDAS = [{"rtol": r} for r in (1e-4, 1e-5, 1e-6, 1e-7)]
SYMCAT_ALPHA = [{"dt": d, "tol": 1e-8} for d in (5e-3, 2.5e-3, 1e-3, 5e-4, 2.5e-4)]
EXUDYN = [{"dt": d} for d in (5e-3, 2.5e-3, 1e-3, 5e-4, 2.5e-4)]
SYMCAT_REFERENCE = {"dt": 2.5e-5, "tol": 1e-12}
EXUDYN_REFERENCE = {"dt": 2.5e-5, "newton_rtol": 1e-10}
