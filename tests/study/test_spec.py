"""A study's inputs: grids, random parameters and their samples, checked before any work."""
from __future__ import annotations

import pytest

from symcat.errors import ParameterError
from symcat.model import load_model
from symcat.study.sampling import study_runs
from symcat.study.spec import make_spec, parse_grid, parse_random

from .conftest import TOY


@pytest.fixture(scope="module")
def toy():
    return load_model(TOY)


def test_grid_ranges_include_both_ends_and_lists_are_parsed(toy):
    assert parse_grid(toy, "x=0.1:0.5:0.1") == ("x", [0.1, 0.2, 0.3, 0.4, 0.5])
    assert parse_grid(toy, "x=1:2:0.3") == ("x", [1.0, 1.3, 1.6, 1.9])
    assert parse_grid(toy, "n=1:3:1") == ("n", [1, 2, 3])
    assert all(type(v) is int for v in parse_grid(toy, "n=1:3:1")[1])
    assert parse_grid(toy, "shape=square,cube") == ("shape", ["square", "cube"])
    assert parse_grid(toy, "x=2:2:1") == ("x", [2.0])


@pytest.mark.parametrize("item, message", [
    ("y=1,2", r"--grid y=1,2: y: not a parameter of model 'toy' \(parameters: x, n, "),
    ("x=3:1:1", r"--grid x=3:1:1: empty range \(START=3 > STOP=1\)"),
    ("x=1:3:0", r"--grid x=1:3:0: STEP=0 must be > 0"),
    ("x=1:3", r"--grid x=1:3: a range is START:STOP:STEP \(three numbers\), got '1:3'"),
    ("x=1:b:1", r"--grid x=1:b:1: STOP 'b' is not a finite number"),
    ("x=1,,2", r"--grid x=1,,2: an empty value in the list"),
    ("x=", r"--grid 'x=': expected NAME=START:STOP:STEP"),
    ("n=0.5,1", r"--grid n=0.5,1: n=0.5: must be an integer >= 0"),
    ("shape=1:2:1", r"--grid shape=1:2:1: shape is not numeric \(one of square, cube\)"),
    ("shape=round", r"--grid shape=round: shape=round: must be one of square, cube"),
    ("x=1,1", r"--grid x=1,1: a value is given twice"),
])
def test_bad_grids_are_named_with_what_is_allowed(toy, item, message):
    with pytest.raises(ParameterError, match=message):
        parse_grid(toy, item)


@pytest.mark.parametrize("item, message", [
    ("x=gamma:1:2", r"--random x=gamma:1:2: unknown distribution 'gamma'; use NAME=normal:MEAN:SD or NAME=uniform"),
    ("y=normal:1:2", r"--random y=normal:1:2: y: not a parameter of model 'toy'"),
    ("n=normal:1:2", r"--random n=normal:1:2: n must be a real-valued parameter"),
    ("x=normal:1", r"--random x=normal:1: normal takes two numbers, normal:MEAN:SD"),
    ("x=normal:1:-1", r"SD=-1 must be > 0"),
    ("x=uniform:2:1", r"LOW=2 must be below HIGH=1"),
    ("x=uniform:a:1", r"LOW 'a' is not a finite number"),
])
def test_bad_random_parameters_are_named_with_what_is_allowed(toy, item, message):
    with pytest.raises(ParameterError, match=message):
        parse_random(toy, item)


def test_a_parameter_given_twice_or_samples_of_nothing_random_are_refused(toy):
    with pytest.raises(ParameterError, match=r"--grid x=1,2: x is given twice"):
        make_spec(toy, TOY, {"x": 1.0}, ["x=1,2"])
    with pytest.raises(ParameterError, match=r"--random x=normal:1:1: x is given twice"):
        make_spec(toy, TOY, None, ["x=1,2"], ["x=normal:1:1"])
    with pytest.raises(ParameterError, match=r"--samples 3: model 'toy' has nothing random to sample"):
        make_spec(toy, TOY, samples=3)
    with pytest.raises(ParameterError, match=r"--samples 0: must be an integer >= 1"):
        make_spec(toy, TOY, samples=0)


def test_runs_are_the_factorial_times_the_samples_with_common_random_numbers(toy):
    spec = make_spec(toy, TOY, {"n": 2}, {"shape": ["square", "cube"], "x": "1:2:1"}, {"fail_above": "normal:5:1"},
                     samples=3, seed=11)
    runs = study_runs(spec)
    assert len(runs) == 2 * 2 * 3
    assert [(r.grid_point, r.sample) for r in runs[:4]] == [(0, 0), (0, 1), (0, 2), (1, 0)]
    assert runs[0].params == {"n": 2, "shape": "square", "x": 1.0, "fail_above": runs[0].params["fail_above"]}
    # sample k draws the same value at every grid point; the samples differ
    draws = [[r.params["fail_above"] for r in runs if r.sample == k] for k in range(3)]
    assert all(len(set(d)) == 1 for d in draws) and len({d[0] for d in draws}) == 3
    assert len({r.run_id for r in runs}) == len(runs)
    again = study_runs(make_spec(toy, TOY, {"n": 2}, {"shape": ["square", "cube"], "x": "1:2:1"},
                                 {"fail_above": "normal:5:1"}, samples=3, seed=11))
    assert [r.params for r in again] == [r.params for r in runs]
    other = study_runs(make_spec(toy, TOY, {"n": 2}, {"shape": ["square", "cube"], "x": "1:2:1"},
                                 {"fail_above": "normal:5:1"}, samples=3, seed=12))
    assert [r.params for r in other] != [r.params for r in runs]


def test_each_sample_of_a_catenary_model_gets_its_own_deviation_seed():
    model = load_model("benchmark2015")
    spec = make_spec(model, "benchmark2015", {"dropper_length_sd_m": "0.005"}, samples=4, seed=7)
    seeds = [r.params["deviation_seed"] for r in study_runs(spec)]
    assert len(set(seeds)) == 4 and all(0 <= s < 2**31 for s in seeds)
    assert seeds == [r.params["deviation_seed"] for r in study_runs(make_spec(
        model, "benchmark2015", {"dropper_length_sd_m": "0.005"}, samples=4, seed=7))]
    # a deviation seed the user gives is kept
    given = make_spec(model, "benchmark2015", {"deviation_seed": 5}, {"speed_kmh": "250,300"})
    assert [r.params["deviation_seed"] for r in study_runs(given)] == [5, 5]
