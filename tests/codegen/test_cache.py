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
    assert entry["c_sha256"] == json.loads((generated_dir() / "manifest.json").read_text())["libraries"]["slope_moment"]["c_sha256"]
