"""The optimized tier of the model DAE libraries (symcat.codegen.optimized): compiled in the
background after the -O0 library, loaded by later runs, equal in value; compiled at once in
mode ``now``; never in mode ``off``; a dead compiler's job restarted, a failed one reported."""
import os
import subprocess
import sys

import casadi as ca
import numpy as np
import pytest

import symcat.codegen.model_dae as model_dae
from symcat.codegen import optimized
from symcat.codegen.library import cached_library
from symcat.dae.formulation import Formulation
from symcat.dae.initial import consistent_state
from symcat.errors import ParameterError

from .test_model_dae import _wheelset


@pytest.fixture
def form():
    return Formulation(_wheelset("conical", "linear"), "augmented", "ggl", 10.0, False)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """Model libraries in a folder of their own (the kernels stay in the shared cache)."""
    monkeypatch.setattr(model_dae, "cached_library",
                        lambda name, key, flags: tmp_path / cached_library(name, key, flags).name)
    return tmp_path


def _libraries(folder):
    return sorted(p.name for p in folder.iterdir() if p.suffix == ".so")


def _values(library, form, seed):
    """Residual and Jacobian of the compiled DAE at perturbed consistent states."""
    fn = ca.external(form.dae_function().name(), str(library))
    jac = fn.jacobian()
    x, z = consistent_state(form, 0.0)
    rng, out = np.random.default_rng(seed), []
    for k in range(2):
        args = [0.01, x + 1e-4 * rng.standard_normal(len(x)) * k, z, np.zeros(fn.size1_in(3)), ca.DM(0, 1)]
        out += [np.asarray(ca.densify(v)) for v in fn(*args)[:2]]
        out += [np.asarray(ca.densify(v)) for v in jac(*args, *[ca.DM.zeros(fn.sparsity_out(i)) for i in range(4)])]
    return [v for v in out if v.size]


def test_background_compile_is_loaded_by_the_next_run_and_equals_the_plain_library(form, cache):
    first = model_dae.model_library(form.dae_function, form.dae_function(), "background")
    assert first.suffix == ".so" and first.exists()
    # The C waits in the cache for the compiler started in the background.
    waiting = sorted(cache.glob("*.c"))
    assert len(waiting) == 1
    assert optimized.wait_for_background(300.0)
    assert not list(cache.glob("*.c")) and not list(cache.glob("*.lock")) and not list(cache.glob("*.failed"))
    libs = _libraries(cache)
    assert len(libs) == 2 and first.name in libs
    optimized_lib = cache / next(n for n in libs if n != first.name)
    assert optimized_lib == waiting[0].with_suffix(".so")
    before = model_dae.COMPILED["n"]
    second = model_dae.model_library(form.dae_function, form.dae_function(), "background")
    assert second == optimized_lib and model_dae.COMPILED["n"] == before
    # Same arithmetic, in registers instead of on the stack: equal to rounding.
    for a, b in zip(_values(first, form, 7), _values(second, form, 7)):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12 * (1 + np.abs(a).max()))
    # Mode off keeps to the plain library even where the optimized one exists.
    assert model_dae.model_library(form.dae_function, form.dae_function(), "off") == first


def test_mode_now_compiles_the_optimized_library_at_once_and_off_never_does(form, cache):
    now = model_dae.model_library(form.dae_function, form.dae_function(), "now")
    assert _libraries(cache) == [now.name] and not list(cache.glob("*.c"))
    for p in cache.iterdir():
        p.unlink()
    off = model_dae.model_library(form.dae_function, form.dae_function(), "off")
    assert off != now and _libraries(cache) == [off.name]
    assert not list(cache.glob("*.c")) and not list(cache.glob("*.lock"))
    assert optimized.wait_for_background(0.0)


def test_a_dead_compilers_job_is_started_again_and_a_live_one_is_not(form, cache):
    plain = model_dae.model_library(form.dae_function, form.dae_function(), "off")
    # The C left by a run whose background compiler died (its lock names a dead process).
    target = model_dae.cached_library(f"model_{form.dae_function().name()}",
                                      form.dae_function().serialize().encode() + model_dae.LAYOUT,
                                      optimized.OPTIMIZED_FLAGS)
    with model_dae.tempfile.TemporaryDirectory() as tmp:
        c_path = model_dae.write_dae_c(form.dae_function, form.dae_function().name(), model_dae.Path(tmp))
        optimized.source_path(target).write_bytes(c_path.read_bytes())
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    target.with_suffix(".lock").write_text(str(dead.pid))
    assert model_dae.model_library(form.dae_function, form.dae_function(), "background") == plain
    assert target.with_suffix(".lock").read_text() != str(dead.pid)  # a new job holds it
    assert not optimized.start_background(target)  # while it runs, no second one
    assert optimized.wait_for_background(300.0)
    assert target.exists() and not optimized.source_path(target).exists()


def test_a_failed_compile_is_reported_in_a_file_and_not_retried(tmp_path):
    target = tmp_path / "model_broken-0123.so"
    optimized.source_path(target).write_text("this is not C;\n")
    assert optimized.start_background(target)
    assert optimized.wait_for_background(120.0)
    failed = target.with_suffix(".failed")
    assert failed.exists() and "CompilerError" in failed.read_text()
    assert not target.exists() and not optimized.source_path(target).exists()
    assert not target.with_suffix(".lock").exists()


def test_an_unknown_mode_is_refused_with_its_name(monkeypatch):
    monkeypatch.setenv("SYMCAT_OPTIMIZE", "fast")
    with pytest.raises(ParameterError, match="SYMCAT_OPTIMIZE='fast'.*background, now, off"):
        optimized.optimize_mode()
    monkeypatch.setenv("SYMCAT_OPTIMIZE", " Now ")
    assert optimized.optimize_mode() == "now"


def test_a_library_with_its_own_optimized_flags_is_compiled_with_them(cache):
    """The compiled generalized-alpha steps take -O2 where the DAEs take -Og: the background
    job compiles with the caller's flags, into the library those flags name."""
    from symcat.codegen.library import write_functions_c

    x = ca.SX.sym("x")
    tiny = ca.Function("tiny", [x], [x * x + 1])
    flags = ("-O2", "-fPIC", "-shared")

    def write(folder):
        return write_functions_c([tiny], "tiny", folder)

    plain = model_dae.compiled_library("tiny", b"tiny", write, "background", optimized_flags=flags)
    assert optimized.wait_for_background(120.0)
    expected = cache / cached_library("tiny", b"tiny", flags).name
    assert expected.exists() and expected != plain
    assert expected.name != cached_library("tiny", b"tiny", optimized.OPTIMIZED_FLAGS).name
    assert model_dae.compiled_library("tiny", b"tiny", write, "background", optimized_flags=flags) == expected
    assert float(ca.external("tiny", str(expected))(3.0)) == 10.0


def test_a_short_runs_step_is_compiled_in_the_background_for_the_next_run(cache, monkeypatch):
    """A generalized-alpha run too short to wait for the compiler (``compiled=None``) evaluates
    the rest of its step expanded and leaves its graph to a background job; the model's next run
    loads the library the job wrote and compiled, with the same values."""
    from symcat.integrate.alpha_coefficients import AlphaCoefficients
    from symcat.integrate.alpha_step import StepEquations

    monkeypatch.setenv(optimized.OPTIMIZE_ENV, "background")
    form = Formulation(_wheelset("conical", "linear"), "augmented", "1")
    first = StepEquations(form, "stabilized", compiled=None)
    assert first._rest.function.class_name() != "External"
    assert optimized.wait_for_background(600.0)
    for leftover in ("*.casadi", "*.c", "*.lock", "*.failed"):
        assert not list(cache.glob(leftover)), leftover
    assert len([n for n in _libraries(cache) if n.startswith("alpha_rest-")]) == 1
    second = StepEquations(form, "stabilized", compiled=None)
    assert second._rest.function.class_name() == "External"
    model, c, h = form.model, AlphaCoefficients(0.9), 1e-3
    u0 = np.r_[model.q0[model.free], model.s0]
    rng = np.random.default_rng(3)
    p = np.r_[u0, rng.normal(0, 1e-3, 2 * u0.size), 0.01, c.beta * h * h, c.gamma * h, (1 - c.alpha_m) / (1 - c.alpha_f)]
    y = np.zeros(first.n_y)
    y[: u0.size] = u0 + rng.normal(0, 1e-6, u0.size)
    np.testing.assert_allclose(second.residual(y, p), first.residual(y, p), rtol=1e-10, atol=1e-9)
    a, b = first.jacobian(y, p).toarray(), second.jacobian(y, p).toarray()
    np.testing.assert_allclose(b, a, rtol=1e-10, atol=1e-10 * np.abs(a).max())


def test_mode_off_leaves_no_background_job_for_a_short_run(cache, monkeypatch):
    from symcat.integrate.alpha_step import StepEquations

    monkeypatch.setenv(optimized.OPTIMIZE_ENV, "off")
    StepEquations(Formulation(_wheelset("conical", "linear"), "augmented", "1"), "stabilized", compiled=None)
    assert not list(cache.iterdir())


def test_a_short_run_starts_no_second_compiler_while_one_runs(cache, monkeypatch):
    """Short runs of several models (a study) start one background compiler at a time."""
    from symcat.integrate import alpha_rest

    monkeypatch.setenv(optimized.OPTIMIZE_ENV, "background")
    busy = cache / "other.lock"
    busy.write_text(str(os.getpid()))  # a live process compiling something else
    y = ca.MX.sym("y", 2)
    rest = ca.Function("alpha_rest", [y], [2 * y])
    assert not alpha_rest.compile_later(rest, b"key")
    assert not list(cache.glob("*.casadi"))
