"""The per-model functions kept across runs (:func:`symcat.integrate.alpha_chunk_cache.model_memo`):
a run of a new model of the same scene reuses the consistent state's and the results' terms
functions, gives the same numbers, and a changed model gets its own."""
from __future__ import annotations

import numpy as np

import symcat.integrate.alpha_chunk_cache as cache
import symcat.integrate.post_terms as results
from symcat.dae.formulation import Formulation
from symcat.dae.initial import _terms_function, consistent_state
from symcat.integrate.generalized_alpha import generalized_alpha
from tests.dynamics.test_alpha_chunk import moving_load


def _run(model):
    return generalized_alpha(model, 0.05, 1e-3, rho_inf=1.0, n_out=5, progress=False, tol=1e-10,
                             multipliers="integrator", compiled=False)


def test_models_of_one_scene_share_their_terms_functions_and_changed_ones_do_not(monkeypatch):
    monkeypatch.setattr(cache, "_MEMO", type(cache._MEMO)())
    built = {"n": 0}
    original = results._terms_function

    def counted(*args, **kwargs):
        built["n"] += 1
        return original(*args, **kwargs)

    monkeypatch.setattr(results, "_terms_function", counted)
    a, b = moving_load(), moving_load()
    fa = _terms_function(Formulation(a, "augmented", "1"))
    assert _terms_function(Formulation(b, "augmented", "1")) is fa
    assert _terms_function(Formulation(b, "augmented", "ggl")) is not fa  # another form
    moved = moving_load()
    moved.q0[5] += 1e-3  # another initial state: its own function
    assert _terms_function(Formulation(moved, "augmented", "1")) is not fa
    first = _run(a)
    assert built["n"] == 1
    again = _run(b)
    assert built["n"] == 1  # the results' terms kept
    assert np.array_equal(again.q, first.q) and np.array_equal(again.energy_J["total"], first.energy_J["total"])
    heavier = moving_load(force=200.0)
    other = _run(heavier)
    assert built["n"] == 2
    assert not np.allclose(other.q, first.q)  # its own load, not the kept function's
    # the consistent state of a kept function is the one a fresh model's builds
    kept = consistent_state(Formulation(moving_load(), "augmented", "1"))
    monkeypatch.setattr(cache, "_MEMO", type(cache._MEMO)())
    fresh = consistent_state(Formulation(moving_load(), "augmented", "1"))
    assert all(np.array_equal(k, f) for k, f in zip(kept, fresh))


def test_the_memo_is_bounded_and_a_model_without_a_key_builds_every_time(monkeypatch):
    monkeypatch.setattr(cache, "_MEMO", type(cache._MEMO)())
    monkeypatch.setattr(cache, "MEMO_SIZE", 2)
    model = moving_load()
    form = Formulation(model, "augmented", "1")
    for tag in range(3):
        cache.model_memo(model, form, (tag,), object)
    assert len(cache._MEMO) == 2
    changed = moving_load()
    changed.scene.force_elements[0].force = (0.0, -200.0, 0.0)  # no key: the scene changed after the build
    calls = []
    cache.model_memo(changed, form, ("x",), lambda: calls.append(1))
    cache.model_memo(changed, form, ("x",), lambda: calls.append(1))
    assert calls == [1, 1]


def test_compiled_post_terms_give_the_virtual_machines_results(monkeypatch):
    """A run whose steps are compiled has its result's terms compiled (post_terms): the same
    energies, drifts and reactions as the terms in CasADi's virtual machine."""
    monkeypatch.setattr(cache, "_MEMO", type(cache._MEMO)())
    calls = []
    original = results._compiled_terms

    def counted(*args):
        fn = original(*args)
        calls.append(fn)
        return fn

    monkeypatch.setattr(results, "_compiled_terms", counted)
    compiled = generalized_alpha(moving_load(), 0.05, 1e-3, rho_inf=1.0, n_out=5, progress=False, tol=1e-10,
                                 multipliers="integrator", compiled=True)
    assert compiled.stats["compiled_steps"] > 0 and len(calls) == 1 and calls[0] is not None
    plain = _run(moving_load())  # Python steps: the terms in the virtual machine
    assert len(calls) == 1
    assert np.allclose(compiled.q, plain.q, atol=1e-8)
    # the result's terms of the same states, both ways
    monkeypatch.setattr(cache, "_MEMO", type(cache._MEMO)())
    form = Formulation(moving_load(), "augmented", "1")
    fn, _, vm = results.mapped_terms(form, True, True, compiled=False)
    _, _, cc = results.mapped_terms(form, True, True, compiled=True)
    assert cc.fn is not vm.fn and cc.fn.name() == "post_terms"
    rng = np.random.default_rng(1)
    args = [rng.normal(scale=1e-3, size=(7, fn.nnz_in(i))) for i in range(fn.n_in())]
    args[0] = args[0] + np.asarray(form.to_internal(form.model.q0[form.model.free]))
    for a, b in zip(vm(*args), cc(*args)):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-9 * (1 + np.abs(a).max(initial=0)))
