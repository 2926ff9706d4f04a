"""Compiled generalized-alpha steps on a catenary line (:mod:`symcat.integrate.alpha_chunk_wires`,
:mod:`symcat.integrate.alpha_chunk_later`): the wires' rows and Jacobian built as loops are the
Python steps' bulk, the compiled steps give the Python steps' contact force to the Newton
tolerance, the generated code does not grow with the wires' elements, and a line without an
optimized library steps in Python while the library is built for its next run.

A short benchmark2015 line (2 spans, a few elements per span) with the lumped pantograph as
scene bodies and a penalty contact; its wires are built as loops by lowering
:data:`~symcat.integrate.alpha_chunk_wires.LOOPED_ELEMENTS` (a real line has hundreds of
elements)."""
from __future__ import annotations

import os
import re

import casadi as ca
import numpy as np
import pytest

import symcat.integrate.alpha_chunk as alpha_chunk
import symcat.integrate.alpha_chunk_wires as alpha_chunk_wires
from symcat.analysis.equilibrium import solve_equilibrium
from symcat.assembly.multibody import MultibodyModel
from symcat.catenary import benchmark2015, find_form
from symcat.catenary.scene import catenary_scene
from symcat.codegen.library import symbolic_kernels
from symcat.dae.formulation import Formulation
from symcat.dae.initial import consistent_state
from symcat.integrate.alpha_chunk_later import _build_library
from symcat.integrate.alpha_coefficients import AlphaCoefficients
from symcat.integrate.alpha_integrator import Integrator
from symcat.integrate.generalized_alpha import generalized_alpha
from symcat.pantograph import benchmark2015_pantograph
from symcat.pantograph.lumped_scene import add_lumped_pantograph, loaded_wire_height

SPEED_KMH, X0 = 200.0, 55.0
_FORMS = {}


def line(elements=4, wires="nonlinear"):
    """A 2-span line under the lumped pantograph at its static equilibrium, and the contact's name."""
    if elements not in _FORMS:
        _FORMS[elements] = find_form(benchmark2015(2), elements, progress=False)
    form = _FORMS[elements]
    form.structure.linearize_wires(None)
    panto = benchmark2015_pantograph(SPEED_KMH)
    scene = catenary_scene(form, wires=wires)
    z = loaded_wire_height(form, X0, float(panto.static_force(SPEED_KMH / 3.6).sum()))
    info = add_lumped_pantograph(scene, panto, "contact", X0, SPEED_KMH / 3.6, contact="penalty", head_z=z)
    model = MultibodyModel(scene)
    solve_equilibrium(model).apply(model)
    return model, info["contact"]


@pytest.fixture
def loops(monkeypatch):
    """Every model's wires built as loops."""
    monkeypatch.setattr(alpha_chunk_wires, "LOOPED_ELEMENTS", 0)


def _stepper(model):
    model.center_windows()
    form = Formulation(model, "augmented", "1")
    stats = dict(steps=0, nsteps=0, newton_iterations=0, factorizations=0, rebuilds=0, halvings=0, build_s=0.0)
    integ = Integrator(model, form, AlphaCoefficients(0.8), "stabilized", 1e-6, 20, 4, False, stats)
    integ.stepper.scale_multipliers(integ.start(*consistent_state(form, 0.0), 1e-3).u)
    return integ


@pytest.mark.parametrize("wires", ["nonlinear", "linear"])
def test_looped_wires_are_the_bulks_rows_and_jacobian(wires):
    """Away from the static state, with moving predictors (the droppers' damping) and a shift:
    the loops' rows and Jacobian are the Python steps' bulk to round-off."""
    model, _ = line(4, wires)
    integ = _stepper(model)
    st, n_u = integ.stepper, integ.stepper.n_u
    n_b = st.bulk.n_b
    with symbolic_kernels():
        rows, jacobian = alpha_chunk_wires.LoopedWires(st).functions()
    rng = np.random.default_rng(1)
    p = np.r_[rng.normal(size=3 * n_u) * 1e-2, 0.1, 0.3e-6, 0.6e-3, 0.9]
    y_b = model.q0[model.free[:n_b]] - np.asarray(st.form.q_fixed).ravel()[model.free[:n_b]] + 1e-3 * rng.normal(size=n_b)
    shift = 1e-8 * rng.normal(size=n_b)
    r_python = st.bulk.residual(y_b, p, shift)
    j_python = st.bulk.jacobian.matrix(y_b, p, shift).toarray()
    r = np.array(rows(y_b, p, shift)).ravel()
    j = np.array(ca.DM(jacobian(y_b, p, shift)).full())
    assert np.abs(r_python).max() > 1.0 and np.abs(j_python).max() > 1.0
    assert np.abs(r - r_python).max() <= 1e-12 * np.abs(r_python).max()
    assert np.abs(j - j_python).max() <= 1e-12 * np.abs(j_python).max()


@pytest.mark.parametrize("wires", ["nonlinear", "linear"])
def test_compiled_steps_on_a_line_are_the_python_steps(loops, wires, record_property):
    """Every step compiled, the contact force the Python steps' to the Newton tolerance (a
    penalty of 5e4 N/m: 1e-6 m of gap is 0.05 N)."""
    model, contact = line(4, wires)
    runs = [generalized_alpha(model, 0.1, 1e-3, 0.8, n_out=10, progress=False, tol=1e-6, multipliers="integrator",
                              compiled=compiled) for compiled in (False, True)]
    assert "compiled_steps" not in runs[0].stats
    assert runs[1].stats["compiled_steps"] == runs[1].stats["steps"] == 100
    python, compiled = (np.asarray(r.contacts[contact]["force_N"]) for r in runs)
    apart = np.abs(compiled - python).max()
    record_property("apart_N", apart)
    assert python.std() > 1.0  # a passage, not a static state
    assert apart < 0.1


def _code(elements: int) -> str:
    """The compiled steps' C of the line, its constant arrays (indices, sparsity patterns,
    constant matrices) left out and its numbers replaced by a placeholder."""
    integ = _stepper(line(elements)[0])
    with symbolic_kernels():
        functions = alpha_chunk.chunk_functions(integ.stepper, integ.coef)
    gen = ca.CodeGenerator("alpha_chunk.c", {"with_header": False})
    for fn in functions:
        gen.add(fn)
    text = re.sub(r"static const [^;{]*=\s*\{[^}]*\};", "", gen.dump())
    return re.sub(r"\d+", "0", text)


def test_the_code_does_not_grow_with_the_elements(loops):
    """Twice the elements per span: the same code but for its constant arrays (loops over the
    wires' elements, one proxy element per contact point)."""
    small, large = _code(4), _code(8)
    assert len(large) == len(small)
    assert large == small


def test_a_line_steps_in_python_while_its_library_is_built_for_the_next_run(loops, monkeypatch):
    """Under ``SYMCAT_OPTIMIZE=background`` a line without its optimized library takes the
    Python steps and leaves the library to a background job (run here at once: built by the
    end of the first output interval, the run goes on with it); the next run finds it from the
    model's record (written by the first run, without the library key's digest of the step's
    graph), compiled from its start, and gives the same contact force to the Newton tolerance."""
    import symcat.codegen.optimized as optimized

    monkeypatch.setenv("SYMCAT_OPTIMIZE", "background")
    # a tier of its own, compiled quickly
    monkeypatch.setattr(alpha_chunk, "OPTIMIZED_FLAGS", ("-O0", "-g0", "-fPIC", "-shared"))
    started = []

    def start_background(library, flags, module):
        started.append(library)
        return _build_library(library, flags) == 0

    monkeypatch.setattr(optimized, "start_background", start_background)
    monkeypatch.setattr(optimized, "jobs_running", lambda folder: False)
    monkeypatch.setattr(os, "nice", lambda increment: 0)  # (the job's, run in this process)
    model, contact = line(4)
    library = _library(model)
    for path in (library, optimized.failed_path(library)):
        path.unlink(missing_ok=True)
    keys = []
    library_key = alpha_chunk.library_key
    monkeypatch.setattr(alpha_chunk, "library_key", lambda *args: keys.append(1) or library_key(*args))
    try:
        runs = []
        for _ in range(2):
            keys.clear()
            runs.append(generalized_alpha(line(4)[0], 0.05, 1e-3, 0.8, n_out=5, progress=False, tol=1e-6,
                                          multipliers="integrator", compiled=True))
        assert keys == []  # the second run: found from its record
        assert started == [library] and library.exists()
        assert runs[0].stats["compiled_steps"] == 40 and runs[0].stats["steps"] == 50  # picked up after 10
        assert runs[1].stats["compiled_steps"] == runs[1].stats["steps"] == 50
        python, compiled = (np.asarray(r.contacts[contact]["force_N"]) for r in runs)
        assert np.abs(compiled - python).max() < 0.1
    finally:
        library.unlink(missing_ok=True)


def _library(model):
    """Where the optimized library of ``model``'s compiled steps is cached."""
    from symcat.codegen.model_dae import cached_library

    integ = _stepper(model)
    key = alpha_chunk.library_key(integ.stepper, integ.coef)
    return cached_library("alpha_chunk", key.encode(), alpha_chunk.OPTIMIZED_FLAGS)


def test_a_long_run_of_a_line_steps_in_python_without_optimization(loops, monkeypatch):
    """Under ``SYMCAT_OPTIMIZE=off`` a line's long run does not build its steps at -O0 (slower
    than its Python steps; only ``compiled=True`` asks for them)."""
    import importlib

    ga = importlib.import_module("symcat.integrate.generalized_alpha")
    monkeypatch.setenv("SYMCAT_OPTIMIZE", "off")
    monkeypatch.setattr(ga, "CHUNK_COMPILE_STEPS", 10)
    built = []
    monkeypatch.setattr(alpha_chunk, "chunk_functions", lambda *a: built.append(a) or [])
    # a library of this model cached by an earlier test or run would be used: none here
    monkeypatch.setattr(alpha_chunk, "read_record", lambda key: None)
    monkeypatch.setattr(alpha_chunk, "library_key", lambda st, coef: f"never-cached-{os.getpid()}-{id(st)}")
    model, _ = line(4)
    run = generalized_alpha(model, 0.02, 1e-3, 0.8, n_out=2, progress=False, tol=1e-6)
    assert run.stats["steps"] == 20 and not run.stats.get("compiled_steps") and not built
