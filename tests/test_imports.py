"""Start-up: a model imports only what its scene uses.

Each check runs in a fresh interpreter (``sys.modules`` of the test process holds whatever the
other tests imported) and reads back the names of the modules it loaded. A cable or beam statics
model loads no multibody or wheel/rail code, no SymPy and no matplotlib unless it plots, and no
SciPy optimizer unless its analytic reference solves for a root (the cantilever's elastica and
the hanging cable's catenary do).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

MULTIBODY = ["symcat.wheelrail", "symcat.assembly.multibody", "symcat.analysis.equilibrium", "symcat.dae",
             "symcat.integrate"]
#: Never loaded by a statics run without --out.
ALWAYS_FORBIDDEN = [*MULTIBODY, "sympy", "matplotlib", "symcat.codegen.generate", "symcat.symbolic"]
#: Model, parameters (small meshes: only the imports matter), modules it must not load.
STATIC_RUNS = {
    "taut_wire": ({"n_elements": 8, "n_modes": 3}, [*ALWAYS_FORBIDDEN, "scipy.optimize", "scipy.integrate"]),
    "cantilever": ({"n_elements": 2}, ALWAYS_FORBIDDEN),
    "rollup": ({"n_elements": 4}, [*ALWAYS_FORBIDDEN, "scipy.optimize", "scipy.integrate"]),
    "hanging_cable": ({"n_elements": 3}, [*ALWAYS_FORBIDDEN, "scipy.integrate"]),
}
#: ``import symcat`` alone: the package's top level loads none of the numerical stack.
TOP_LEVEL_FORBIDDEN = ["numpy", "scipy", "casadi", "sympy", "matplotlib", "meshio", "symcat.analysis",
                       "symcat.assembly", "symcat.scene", "symcat.wheelrail", "symcat.codegen"]


def _modules_after(code: str) -> set[str]:
    """Names in ``sys.modules`` after running ``code`` in a fresh interpreter."""
    script = f"{code}\nimport json, sys\nprint('\\nMODULES=' + json.dumps(sorted(sys.modules)))\n"
    env = {**os.environ, "SYMCAT_OPTIMIZE": "off"}
    proc = subprocess.run([sys.executable, "-c", script], check=False, cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    line = next(line for line in proc.stdout.splitlines() if line.startswith("MODULES="))
    return set(json.loads(line.removeprefix("MODULES=")))


def _loaded(modules: set[str], forbidden: list[str]) -> list[str]:
    """The forbidden packages (or any of their submodules) among ``modules``."""
    return sorted(f for f in forbidden if f in modules or any(m.startswith(f + ".") for m in modules))


def _warm(model: str, params: dict) -> None:
    """Run once in this process, so that a missing kernel library is generated here (with SymPy)
    and the fresh interpreter finds it compiled."""
    from symcat.model import run_model

    run_model(model, params)


@pytest.mark.parametrize("model", ["taut_wire", "cantilever"])
def test_static_run_via_run_model_loads_only_its_scene(model):
    params, forbidden = STATIC_RUNS[model]
    _warm(model, params)
    modules = _modules_after(f"from symcat.model import run_model\nrun_model({model!r}, {params!r})")
    assert "symcat.analysis.statics" in modules  # the run did happen
    assert _loaded(modules, forbidden) == []


@pytest.mark.parametrize("model", sorted(STATIC_RUNS))
def test_static_run_via_cli_loads_only_its_scene(model):
    params, forbidden = STATIC_RUNS[model]
    _warm(model, params)
    sets = [a for name, value in params.items() for a in ("--set", f"{name}={value}")]
    argv = ["run", model, *sets, "--quiet"]
    modules = _modules_after(f"from symcat.cli import main\nassert main({argv!r}) == 0")
    assert "symcat.analysis.statics" in modules
    assert _loaded(modules, forbidden) == []


def test_plotting_loads_matplotlib_when_it_plots(tmp_path):
    params, _ = STATIC_RUNS["taut_wire"]
    _warm("taut_wire", params)
    out = tmp_path / "out"
    modules = _modules_after(f"from symcat.model import run_model\nrun_model('taut_wire', {params!r}, out={str(out)!r})")
    assert "matplotlib" in modules
    assert (out / "frequencies.png").is_file()
    assert _loaded(modules, MULTIBODY) == []


def test_top_level_import_is_light():
    modules = _modules_after("import symcat")
    assert _loaded(modules, TOP_LEVEL_FORBIDDEN) == []


def test_analysis_package_leaves_the_multibody_stack_unloaded():
    """``symcat.analysis`` loads :mod:`.equilibrium` (multibody, DAE, wheel/rail) on first use of
    one of its names; ``symcat.analytic`` loads SciPy's optimizer and integrators on first use."""
    modules = _modules_after("from symcat.analysis import modes, solve_static\nfrom symcat.analytic import "
                             "taut_wire_frequencies\nimport symcat.analysis, symcat.analytic, symcat.results, "
                             "symcat.scene, symcat.assembly")
    assert _loaded(modules, [*MULTIBODY, "scipy.optimize", "scipy.integrate", "sympy", "matplotlib"]) == []


def test_lazy_names_keep_their_import_paths():
    modules = _modules_after(
        "import symcat.analysis as a, symcat.analytic as r\n"
        "from symcat.analysis import EquilibriumResult, ModalResult, StaticResult, modes, solve_equilibrium, "
        "solve_static\n"
        "from symcat.analysis.equilibrium import solve_equilibrium as se\n"
        "from symcat.analysis.modes import modes as m\n"
        "assert solve_equilibrium is se and a.solve_equilibrium is se and modes is m and a.modes is m\n"
        "assert set(a.__all__) <= set(dir(a)) and set(r.__all__) <= set(dir(r))\n"
        "from symcat.analytic import *\n"
        "from symcat.analytic.catenary import elastic_catenary as ec\n"
        "assert elastic_catenary is ec and callable(cantilever_tip_load) and callable(taut_wire_frequencies)\n"
        "for bad in ('a.no_such_name', 'r.no_such_name'):\n"
        "    try:\n"
        "        eval(bad)\n"
        "    except AttributeError:\n"
        "        pass\n"
        "    else:\n"
        "        raise AssertionError(bad)\n"
    )
    assert "symcat.assembly.multibody" in modules  # solve_equilibrium resolved through it
