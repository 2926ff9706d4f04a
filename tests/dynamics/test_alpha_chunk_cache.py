"""The compiled steps found from the model (:mod:`symcat.integrate.alpha_chunk_cache`): a run of
a model compiled before loads its library without building the Python step equations, gives
the same results as the run that built them, and a changed model is not taken for it."""
from __future__ import annotations

import numpy as np
import pytest

import symcat.integrate.alpha_chunk as alpha_chunk
import symcat.integrate.alpha_integrator as alpha_integrator
from symcat.assembly.multibody import MultibodyModel
from symcat.dae.formulation import Formulation
from symcat.integrate.alpha_chunk import _settings, step_sizes
from symcat.integrate.alpha_chunk_cache import model_key, read_record
from symcat.integrate.alpha_coefficients import AlphaCoefficients
from symcat.integrate.alpha_step import StepEquations
from symcat.integrate.generalized_alpha import generalized_alpha
from tests.dynamics.test_alpha_chunk import moving_load


def _key(model, variant="stabilized", rho_inf=1.0):
    return model_key(model, Formulation(model, "augmented", "1"), _settings(variant, AlphaCoefficients(rho_inf)))


def _run(model, **kwargs):
    return generalized_alpha(model, 0.1, 1e-3, rho_inf=1.0, n_out=10, progress=False, tol=1e-10,
                             multipliers="integrator", compiled=True, **kwargs)


@pytest.fixture
def builds(monkeypatch):
    """Counts the Python step equations built (from now on)."""
    count = {"n": 0}

    class Counted(StepEquations):
        def __init__(self, *args, **kwargs):
            count["n"] += 1
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(alpha_integrator, "StepEquations", Counted)
    return count


def test_a_model_compiled_before_runs_without_its_python_step_equations(monkeypatch, builds):
    """The first run (record ignored: the graph's path) builds the step equations and writes
    the record; a run of a new model of the same scene builds none and gives the same numbers."""
    with monkeypatch.context() as m:
        m.setattr(alpha_chunk, "read_record", lambda key: None)
        first = _run(moving_load())
    assert builds["n"] == 1
    again = _run(moving_load())
    assert builds["n"] == 1  # found from the model
    assert again.stats["compiled_steps"] == again.stats["steps"] == 100
    assert np.array_equal(again.q, first.q) and np.array_equal(again.s_m, first.s_m)
    assert again.stats["newton_iterations"] == first.stats["newton_iterations"]
    assert again.stats["factorizations"] == first.stats["factorizations"] >= 1


def test_a_changed_model_is_not_taken_for_the_recorded_one():
    """Another load, speed or initial state, form or spectral radius: another key; the same
    scene built twice: the same key; a scene changed after its model was built: none. A
    changed model's run builds its own equations and deflects by its own load."""
    base = _key(moving_load())
    assert base is not None and _key(moving_load()) == base
    assert _key(moving_load(speed=41.0)) != base
    assert _key(moving_load(), variant="index3") != base
    assert _key(moving_load(), rho_inf=0.9) != base
    moved = moving_load()
    moved.q0[5] += 1e-9
    assert _key(moved) != base
    changed = moving_load()  # a scene changed after its model was built: the model does not follow
    changed.scene.force_elements[0].force = (0.0, -200.0, 0.0)
    assert _key(changed) is None
    heavier = moving_load(force=200.0)
    assert _key(heavier) != base
    light, heavy = _run(moving_load()), _run(heavier)
    # each under its own record (written by this run or an earlier one), naming its own library
    assert read_record(_key(heavier))["library"] != read_record(base)["library"]
    wire = slice(0, heavier.ancf.n)  # (the body moves along x with its driving)
    sag = [np.abs(res.q[:, wire] - res.q[0, wire]).max() for res in (light, heavy)]
    assert sag[0] > 1e-5 and sag[1] == pytest.approx(2 * sag[0], rel=0.05)  # a taut wire: about linear


def test_models_the_key_cannot_describe_have_none():
    """A value of no exact description in the scene (a callable: on a built model, or in the
    scene a model is built from), or a model class that may hold more than its scene: no key
    (their runs take the graph's path)."""
    model = moving_load()
    model.scene.joints[-1].velocity = lambda t: 40.0
    assert _key(model) is None
    assert _key(MultibodyModel(model.scene)) is None

    class Special(MultibodyModel):
        pass

    assert _key(Special(moving_load().scene)) is None


@pytest.mark.parametrize("variant", ["stabilized", "index3"])
def test_step_sizes_are_the_step_equations(variant):
    """The sizes the recorded runs use without the step equations are theirs."""
    model = moving_load()
    form = Formulation(model, "augmented", "1")
    st = StepEquations(form, variant)
    assert step_sizes(form, variant) == (st.n_u, st.n_c, st.n_sc, st.n_y)


def test_a_run_digests_its_scene_once(monkeypatch):
    """Within a run (the compiled steps', the initial state's and the post-processing's keys)
    the scene is digested once; outside a run, at every key, so that a scene changed between
    two keys is still seen."""
    import symcat.integrate.alpha_chunk_cache as cache

    model = moving_load()
    _run(model)  # (compiled and recorded: the counted run below takes the same path)
    count = {"n": 0}
    digest = cache.scene_digest

    def counted(scene):
        count["n"] += 1
        return digest(scene)

    monkeypatch.setattr(cache, "scene_digest", counted)
    again = moving_load()
    _run(again)
    assert count["n"] == 1
    assert _key(again) is not None and count["n"] == 2
    again.scene.force_elements[0].force = (0.0, -200.0, 0.0)
    assert _key(again) is None and count["n"] == 3
