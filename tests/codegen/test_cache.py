"""The generated-code manifest and the compiled-library cache."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from symcat.codegen import library as lib_mod
from symcat.codegen.paths import generated_dir
from symcat.errors import CompilerError

ROOT = Path(__file__).resolve().parents[2]


def test_warm_run_neither_imports_sympy_nor_compiles():
    """...and loads only the kernel libraries its scene uses."""
    lib_mod.kernel_library("cable2d")  # make sure the cache is warm
    code = (
        "import sys\n"
        "from symcat.model import run_model\n"
        "from symcat.codegen import library\n"
        "r = run_model('cantilever', {'element': 'cable2d', 'n_elements': 2, 'alpha': 0.5})\n"
        "print(int('sympy' in sys.modules), library.COMPILE_COUNT['n'], ','.join(sorted(library._LOADED)))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.split() == ["0", "0", "cable2d"], out.stderr


def test_failed_compile_leaves_nothing(tmp_path, monkeypatch):
    monkeypatch.setenv("SYMCAT_CACHE", str(tmp_path / "cache"))
    bad = tmp_path / "broken.c"
    bad.write_text("int f( {\n")
    with pytest.raises(CompilerError, match="broken.c"):
        lib_mod.compile_c(bad, "broken")
    assert not any((tmp_path / "cache").glob("*")), list((tmp_path / "cache").iterdir())


def test_missing_compiler_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    with pytest.raises(CompilerError, match="no C compiler found"):
        lib_mod.find_compiler()


def test_compile_is_cached_by_content(tmp_path, monkeypatch):
    monkeypatch.setenv("SYMCAT_CACHE", str(tmp_path / "cache"))
    src = tmp_path / "tiny.c"
    src.write_text("double tiny(double x) { return 2 * x; }\n")
    before = lib_mod.COMPILE_COUNT["n"]
    first = lib_mod.compile_c(src, "tiny")
    again = lib_mod.compile_c(src, "tiny")
    assert first == again and lib_mod.COMPILE_COUNT["n"] == before + 1
    src.write_text("double tiny(double x) { return 3 * x; }\n")
    assert lib_mod.compile_c(src, "tiny") != first


def test_concurrent_compiles_install_one_intact_library(tmp_path):
    src = tmp_path / "conc.c"
    src.write_text("double conc(double x) { return x; }\n" * 1)
    env = {**os.environ, "SYMCAT_CACHE": str(tmp_path / "cache")}
    code = "import sys; from pathlib import Path; from symcat.codegen.library import compile_c; print(compile_c(Path(sys.argv[1]), 'conc'))"
    procs = [subprocess.Popen([sys.executable, "-c", code, str(src)], env=env, cwd=ROOT, stdout=subprocess.PIPE, text=True) for _ in range(4)]
    outs = {p.communicate()[0].strip() for p in procs}
    assert all(p.returncode == 0 for p in procs)
    assert len(outs) == 1
    files = list((tmp_path / "cache").iterdir())
    assert [f.name for f in files] == [Path(outs.pop()).name]


def test_check_generated_detects_a_stale_file(tmp_path):
    copy = tmp_path / "generated"
    shutil.copytree(generated_dir(), copy)
    env = {**os.environ, "SYMCAT_GENERATED": str(copy)}
    check = [sys.executable, "-m", "symcat.codegen", "check"]
    assert subprocess.run(check, env=env, cwd=ROOT, capture_output=True).returncode == 0
    path = copy / "cable2d.c"
    path.write_text(path.read_text().replace("casadi_real", "casadi_real ", 1))
    res = subprocess.run(check, env=env, cwd=ROOT, capture_output=True, text=True)
    assert res.returncode == 1 and "cable2d" in res.stderr
    # A changed symbolic source makes every library stale: simulate by editing the hash.
    manifest = json.loads((copy / "manifest.json").read_text())
    manifest["libraries"]["cable3d"]["source_hash"] = "0" * 64
    (copy / "manifest.json").write_text(json.dumps(manifest))
    res = subprocess.run(check, env=env, cwd=ROOT, capture_output=True, text=True)
    assert "cable3d" in res.stderr


def test_generation_is_reproducible(tmp_path):
    """Regenerating a library reproduces the committed C byte for byte."""
    from symcat.codegen.generate import generate_library

    entry = generate_library("slope_moment", tmp_path)
    assert (tmp_path / "slope_moment.c").read_bytes() == (generated_dir() / "slope_moment.c").read_bytes()
    shipped = json.loads((generated_dir() / "manifest.json").read_text())["libraries"]["slope_moment"]
    assert entry["c_sha256"] == shipped["c_sha256"] and entry["sx_sha256"] == shipped["sx_sha256"]


def test_compiled_model_dae_on_a_cold_model_cache_does_not_import_sympy(tmp_path):
    """The whole-model DAE expands the kernels' shipped SX (generated/*.sx.gz), not SymPy."""
    for name in ("rigid", "driving_rigid_ground", "pointload_rigid", "wheelrail_railframe_rigid_ground"):
        lib_mod.kernel_library(name)  # warm kernels in the shared cache
    cache = tmp_path / "cache"
    cache.mkdir()
    for so in lib_mod.cache_dir().glob("*.so"):
        if not so.name.startswith("model_"):
            (cache / so.name).symlink_to(so)  # kernels warm, model libraries cold
    code = (
        "import sys\n"
        "from tests.codegen.test_model_dae import _wheelset\n"
        "from symcat.simulation import simulate\n"
        "from symcat.codegen.model_dae import COMPILED\n"
        "res = simulate(_wheelset(), 0.002, 'augmented', 'ggl', rtol=1e-6, n_out=2, compiled=True)\n"
        "print(int('sympy' in sys.modules), COMPILED['n'], len(res.t_s))\n"
    )
    env = {**os.environ, "SYMCAT_CACHE": str(cache), "SYMCAT_OPTIMIZE": "off"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["0", "1", "3"], out.stderr


def test_pinned_tool_versions_are_those_the_generated_code_was_made_with():
    """pyproject.toml pins SymPy and CasADi to the manifest's versions: an install on any later
    day regenerates the shipped code byte for byte and reads it as current."""
    import re

    from symcat.codegen.paths import TOOLS, read_manifest

    text = (ROOT / "pyproject.toml").read_text()
    pins = {tool: re.search(rf'"{tool}==([^"]+)"', text) for tool in TOOLS}
    assert all(pins.values()), f"pyproject.toml must pin {', '.join(TOOLS)} with =="
    recorded = {(tool, entry[tool]) for entry in read_manifest()["libraries"].values() for tool in TOOLS}
    assert recorded == {(tool, pin.group(1)) for tool, pin in pins.items()}


def test_stale_shipped_code_is_regenerated_into_the_cache_not_the_source_tree(tmp_path):
    """A run that meets stale shipped code regenerates it into the cache and leaves the
    shipped folder (the source tree, or an installed package) as it was."""
    shipped = tmp_path / "generated"
    shipped.mkdir()
    for name in ("manifest.json", "slope_moment.c", "slope_moment.sx.gz"):
        shutil.copy(generated_dir() / name, shipped / name)
    manifest = json.loads((shipped / "manifest.json").read_text())
    manifest["libraries"]["slope_moment"]["source_hash"] = "0" * 64
    (shipped / "manifest.json").write_text(json.dumps(manifest))
    before = {p.name: p.read_bytes() for p in shipped.iterdir()}
    env = {**os.environ, "SYMCAT_GENERATED": str(shipped), "SYMCAT_CACHE": str(tmp_path / "cache")}
    code = "from symcat.codegen.library import kernel_library; print(kernel_library('slope_moment').path)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env)
    assert out.returncode == 0, out.stderr
    assert "regenerating it into" in out.stderr
    assert {p.name: p.read_bytes() for p in shipped.iterdir()} == before
    regenerated = tmp_path / "cache" / "generated"
    assert (regenerated / "slope_moment.c").read_bytes() == (generated_dir() / "slope_moment.c").read_bytes()
    # A second run finds the regenerated code current and derives nothing.
    again = subprocess.run([sys.executable, "-c", code + "; import sys; print(int('sympy' in sys.modules))"],
                           capture_output=True, text=True, cwd=ROOT, env=env)
    assert again.returncode == 0 and again.stdout.split()[-1] == "0" and "regenerating" not in again.stderr


def test_processes_needing_the_same_model_library_at_once_compile_it_once(tmp_path):
    """Two processes (as parallel test workers) ask for the same uncached model library at the
    same moment: one compiles it while the other waits for it, and both load it."""
    code = (
        "import sys, time\n"
        "from pathlib import Path\n"
        "import casadi as ca\n"
        "from symcat.codegen import model_dae\n"
        "from symcat.codegen.library import write_functions_c\n"
        "x = ca.SX.sym('x')\n"
        "tiny = ca.Function('tiny', [x], [x * x + 1])\n"
        "def write(folder):\n"
        "    time.sleep(1.0)  # a slow generation: the other process arrives meanwhile\n"
        "    return write_functions_c([tiny], 'tiny', folder)\n"
        "go = Path(sys.argv[1])\n"
        "print('ready', flush=True)\n"
        "while not go.exists():\n"
        "    time.sleep(0.01)\n"
        "path = model_dae.compiled_library('tiny', b'tiny', write, 'off')\n"
        "print(model_dae.COMPILED['n'], float(ca.external('tiny', str(path))(3.0)), path)\n"
    )
    go = tmp_path / "go"
    env = {**os.environ, "SYMCAT_CACHE": str(tmp_path / "cache")}
    procs = [subprocess.Popen([sys.executable, "-c", code, str(go)], env=env, cwd=ROOT, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    for p in procs:
        assert p.stdout.readline().strip() == "ready", p.stderr.read()
    go.touch()
    outs = [p.communicate()[0].split() for p in procs]
    assert all(p.returncode == 0 for p in procs), [p.stderr for p in procs]
    assert sorted(int(out[0]) for out in outs) == [0, 1]  # compiled once
    assert [out[1] for out in outs] == ["10.0", "10.0"] and outs[0][2] == outs[1][2]
    assert [p.name for p in (tmp_path / "cache").glob("*.so")] == [Path(outs[0][2]).name]
