"""Problem 3: static cantilever under a tip load, 64 cable elements, 2D and 3D (solve only).

L = 2 m, E = 2.07e11 Pa, square section 0.1 m, tip load P = 3 E I / L^2 in -y, clamped at x = 0.
Reference: the extensible elastica (tip u = 0.5085373043 m along -x, v = 1.2072398545 m along
-y). symcat: :func:`symcat.analysis.solve_static` (one load step); Exudyn: ``SolveStatic``,
one load step, Newton relative tolerance 1e-10. The wall is the solve alone (the model is built
and assembled before), median of interleaved repeats; symcat's first solve on a new system
(which compiles its Newton function) is reported separately.
"""
from __future__ import annotations

import numpy as np

from .common import Point, interleaved, timed

L, E, WIDTH, N_ELEMENTS = 2.0, 2.07e11, 0.1, 64
REFERENCE_TIP = np.array([L - 0.5085373043, -1.2072398545])


def _load():
    return 3.0 * E * WIDTH**4 / 12 / L**2


def symcat_case(dim: int):
    """``solve() -> tip (x, y)`` on a built symcat system, and the first-solve wall (s)."""
    from symcat.analysis import solve_static
    from symcat.assembly import assemble
    from symcat.scene import AncfBody, Material, NodalForce, Scene, Section

    section = Section.rectangle(WIDTH, WIDTH)
    end = np.zeros(dim)
    end[0] = L
    body = AncfBody.straight("beam", "cable2d" if dim == 2 else "cable3d", np.zeros(dim), end, N_ELEMENTS,
                             Material(E=E, rho=7850.0, nu=0.3), section)
    body.clamp(0)
    force = np.zeros(dim)
    force[1] = -_load()
    scene = Scene()
    scene.add(body)
    scene.add(NodalForce("beam", -1, tuple(force)))
    system = assemble(scene)
    tip = system.dofs.node_indices(body, -1)[:2]

    def solve():
        return solve_static(system, load_steps=1).q[tip]

    _, first = timed(solve)
    return solve, first


def exudyn_case(dim: int):
    """``solve() -> tip (x, y)`` on an assembled Exudyn system."""
    import exudyn as exu
    from exudyn.beams import GenerateStraightLineANCFCable, GenerateStraightLineANCFCable2D
    from exudyn.utilities import Cable2D, MarkerNodePosition, LoadForceVector, ObjectANCFCable

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    a, i = WIDTH**2, WIDTH**4 / 12
    props = dict(physicsMassPerLength=7850.0 * a, physicsBendingStiffness=E * i, physicsAxialStiffness=E * a)
    if dim == 2:
        nodes = GenerateStraightLineANCFCable2D(mbs, [0, 0, 0], [L, 0, 0], N_ELEMENTS, Cable2D(**props),
                                                fixedConstraintsNode0=[1, 1, 1, 1])[0]
    else:
        nodes = GenerateStraightLineANCFCable(mbs, [0, 0, 0], [L, 0, 0], N_ELEMENTS, ObjectANCFCable(**props),
                                              fixedConstraintsNode0=[1] * 6)[0]
    marker = mbs.AddMarker(MarkerNodePosition(nodeNumber=nodes[-1]))
    mbs.AddLoad(LoadForceVector(markerNumber=marker, loadVector=[0, -_load(), 0]))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.solutionSettings.writeSolutionToFile = False
    settings.solutionSettings.writeInitialValues = False
    settings.staticSolver.numberOfLoadSteps = 1
    settings.staticSolver.newton.relativeTolerance = 1e-10
    settings.staticSolver.verboseMode = 0
    settings.parallel.numberOfThreads = 1
    settings.linearSolverType = exu.LinearSolverType.EigenSparse

    def solve():
        mbs.systemData.SetODE2Coordinates(mbs.systemData.GetODE2Coordinates(exu.ConfigurationType.Initial),
                                          exu.ConfigurationType.Current)
        ok = mbs.SolveStatic(settings)
        if not ok:
            raise RuntimeError("Exudyn SolveStatic failed")
        return np.array(mbs.GetNodeOutput(nodes[-1], exu.OutputVariableType.Position))[:2]

    return solve


def run(repeats: int = 7) -> dict:
    """Both codes in 2D and 3D: points (error of the tip against the elastica) and notes."""
    results = {}
    for dim in (2, 3):
        sym, first = symcat_case(dim)
        exu_solve = exudyn_case(dim)
        out = interleaved({"symcat": sym, "Exudyn": exu_solve}, repeats)
        points = {}
        for code, (tip, walls) in out.items():
            points[code] = [Point(code, f"{dim}D", float(np.linalg.norm(tip - REFERENCE_TIP)), walls)]
        points["symcat"][0].info = f"first solve {first * 1e3:.1f} ms"
        results[f"{dim}D"] = points
    return results
