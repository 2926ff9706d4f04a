"""Compile generated C into a content-addressed cache and load kernels (never imports SymPy
when the generated code is current).

A compiled library is stored as ``<cache>/<name>-<key>.so`` where ``key`` hashes the C text,
the compiler (resolved path, size and modification time: identified without running it) and
the flags. It is built under a temporary name and installed with :func:`os.replace`, so
concurrent runs never see, or leave, a half-written library.
"""
from __future__ import annotations

import hashlib
import logging
import os
import shutil
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

import casadi as ca

from ..errors import CompilerError
from .paths import cache_dir, file_sha256, generated_dir, read_manifest, source_hash

log = logging.getLogger(__name__)

#: -O1 keeps compile times short; -fno-tree-dominator-opts avoids minutes of compile time on
#: functions with thousands of outputs (measured).
CFLAGS = ("-O1", "-fno-tree-dominator-opts", "-fPIC", "-shared")

#: Counts compiler invocations of this process (the tests check that a warm run makes none).
COMPILE_COUNT = {"n": 0}


def find_compiler() -> str:
    """Resolve the C compiler: ``$CC``, then ``gcc``, then ``cc``."""
    candidates = [os.environ["CC"]] if os.environ.get("CC") else ["gcc", "cc"]
    for cand in candidates:
        path = shutil.which(cand)
        if path:
            return os.path.realpath(path)
    raise CompilerError(
        f"no C compiler found (looked for {', '.join(candidates)}); symcat compiles its kernels "
        "with one: install gcc (e.g. `apt-get install gcc`) or set CC to a compiler"
    )


def _compiler_identity(path: str) -> str:
    st = os.stat(path)
    return f"{path}:{st.st_size}:{int(st.st_mtime)}"


def compile_c(c_path: Path, name: str) -> Path:
    """Compile ``c_path`` into the cache (if not there yet) and return the library path."""
    compiler = find_compiler()
    key = hashlib.sha256(
        c_path.read_bytes() + _compiler_identity(compiler).encode() + " ".join(CFLAGS).encode()
    ).hexdigest()[:20]
    target = cache_dir() / f"{name}-{key}.so"
    if target.exists():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.{time.monotonic_ns()}.tmp")
    cmd = [compiler, *CFLAGS, str(c_path), "-o", str(tmp), "-lm"]
    log.info("compiling %s", c_path.name)
    COMPILE_COUNT["n"] += 1
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise CompilerError(f"could not run the C compiler {compiler}: {exc}") from exc
    if proc.returncode != 0:
        tmp.unlink(missing_ok=True)
        tail = "\n".join(proc.stderr.strip().splitlines()[-15:])
        raise CompilerError(f"compiling {c_path} failed (exit {proc.returncode}): {' '.join(cmd)}\n{tail}")
    os.replace(tmp, target)
    return target


@dataclass
class KernelLibrary:
    """A loaded kernel library: CasADi externals by function name."""

    name: str
    path: Path
    functions: dict[str, ca.Function] = field(default_factory=dict)

    def __getitem__(self, function: str) -> ca.Function:
        f = self.functions.get(function)
        if f is None:
            f = ca.external(function, str(self.path))
            self.functions[function] = f
        return f


_LOADED: dict[str, KernelLibrary] = {}


def ensure_generated(name: str) -> Path:
    """Path of current generated C for ``name``, regenerating it if stale (imports SymPy)."""
    entry = read_manifest()["libraries"].get(name)
    path = generated_dir() / f"{name}.c"
    if entry is not None and path.exists() and entry["source_hash"] == source_hash(name):
        if entry["c_sha256"] == file_sha256(path):
            return path
    log.warning("kernel library %s is missing or stale: regenerating it (run `make generate`)", name)
    from .generate import generate  # deferred: imports SymPy

    generate([name], verbose=False)
    return path


def kernel_library(name: str) -> KernelLibrary:
    """Load (compiling on first use) the kernel library ``name``."""
    lib = _LOADED.get(name)
    if lib is None:
        so = compile_c(ensure_generated(name), name)
        lib = KernelLibrary(name, so)
        _LOADED[name] = lib
    return lib


_INTERFACES: dict[str, dict] = {}


def library_interface(name: str) -> dict:
    """Sizes and parameter names of a multibody library, from the manifest (no SymPy).

    Cached per process: scenes ask once per joint or force instance, and each uncached look-up
    re-hashes the symbolic sources and re-reads the manifest.
    """
    info = _INTERFACES.get(name)
    if info is None:
        ensure_generated(name)
        info = _INTERFACES[name] = read_manifest()["libraries"][name]["interface"]
    return info
