"""IDAS's tuning as one checked object (:class:`symcat.integrate.IdasSettings`), the old keywords
of :func:`symcat.integrate.simulate` as its compatibility path, and the event handlers a run
takes (``handlers=``): a wheel/rail model without them is refused, not run without its contact
jumps."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from symcat.assembly.multibody import MultibodyModel
from symcat.errors import ParameterError
from symcat.integrate import EventHandler, IdasSettings, simulate
from symcat.integrate.settings import FIELDS, settings_from
from symcat.scene import Prismatic, RigidBody, Scene, SpringDamper
from symcat.wheelrail_events import ContactEvents, default_handlers


def _oscillator():
    scene = Scene(gravity=(0, 0, -9.81))
    scene.add(RigidBody("cart", 2.0, (0.1, 0.2, 0.3), (0.1, 0, 0), velocity=(0.5, 0, 0)))
    scene.add(Prismatic("rail", "cart", "ground", at=(0.1, 0, 0), axis=(1, 0, 0)))
    scene.add(SpringDamper("spring", "cart", "ground", at_i=(0.1, 0, 0), at_j=(-1.0, 0, 0), stiffness=50.0,
                           free_length=1.1))
    return MultibodyModel(scene)


@pytest.mark.parametrize("field, value", [
    ("rtol", 0.0), ("rtol", 1.5), ("rtol", "1e-6"), ("atol", -1e-8), ("atol", np.array([1e-8, 0.0])),
    ("velocity_atol", 0.0), ("algebraic_atol", 0.0), ("baumgarte", -1.0), ("cholesky", 1), ("progress", "yes"),
    ("compiled", "auto"), ("linear_solver", "no_such_solver"), ("max_step", -1e-3), ("max_steps", 0),
    ("max_steps", 10.5), ("n_out", 0), ("chunks", -1),
])
def test_a_bad_setting_is_refused_in_one_line_naming_field_and_value(field, value):
    with pytest.raises(ParameterError) as err:
        IdasSettings(**{field: value})
    message = str(err.value)
    assert message.startswith(f"{field}=") and "must be" in message and "\n" not in message


def test_defaults_and_good_values_pass_and_the_object_is_frozen():
    s = IdasSettings(rtol=1e-8, atol=np.full(3, 1e-9), velocity_atol=1e-7, linear_solver="qr", compiled=False,
                     max_step=1e-3, max_steps=np.int64(100), n_out=10, chunks=2)
    assert s.max_steps == 100 and IdasSettings().n_out == 200
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.rtol = 1e-3


def test_old_keywords_build_the_settings_and_an_unknown_one_is_named_with_the_allowed():
    base = IdasSettings(rtol=1e-8, n_out=10)
    assert settings_from(base, n_out=20) == dataclasses.replace(base, n_out=20)
    assert settings_from(None, rtol=1e-7) == IdasSettings(rtol=1e-7)
    with pytest.raises(ParameterError, match=r"^reltol: not an IDAS setting \(allowed: rtol, atol, .*progress\)$"):
        settings_from(base, reltol=1e-6)
    assert set(FIELDS) == {f.name for f in dataclasses.fields(IdasSettings)}
    with pytest.raises(ParameterError, match="reltol"):
        simulate(_oscillator(), 0.1, reltol=1e-6)


def test_keywords_and_settings_give_the_same_run_bit_for_bit():
    settings = IdasSettings(rtol=1e-9, atol=1e-11, n_out=20, progress=False)
    by_object = simulate(_oscillator(), 0.5, settings=settings)
    by_keywords = simulate(_oscillator(), 0.5, rtol=1e-9, atol=1e-11, n_out=20, progress=False)
    overridden = simulate(_oscillator(), 0.5, "augmented", "1", dataclasses.replace(settings, n_out=5), n_out=20)
    np.testing.assert_array_equal(by_object.q, by_keywords.q)
    np.testing.assert_array_equal(by_object.q, overridden.q)
    assert by_object.stats["nsteps"] == by_keywords.stats["nsteps"]


def test_a_wheel_rail_model_without_handlers_is_refused_naming_the_function_that_attaches_them():
    from tests.codegen.test_model_dae import _wheelset

    model = _wheelset()
    with pytest.raises(ParameterError, match=r"^the model has wheel/rail contacts \(wr_left, wr_right\).*"
                                             r"symcat\.simulation\.simulate") as err:
        simulate(model, 0.01, progress=False)
    assert "\n" not in str(err.value)
    handlers = default_handlers(model)
    assert len(handlers) == 1 and isinstance(handlers[0], ContactEvents) and isinstance(handlers[0], EventHandler)
    assert default_handlers(_oscillator()) == []


def test_handlers_must_be_event_handlers_and_one_for_now():
    with pytest.raises(ParameterError, match="not an EventHandler"):
        simulate(_oscillator(), 0.1, handlers=[object()], progress=False)
    with pytest.raises(ParameterError, match="one event handler per run"):
        simulate(_oscillator(), 0.1, handlers=[ContactEvents(), ContactEvents()], progress=False)
