"""Where generated C and compiled libraries live, and what determines them (no SymPy)."""
from __future__ import annotations

import hashlib
import json
import os
from functools import lru_cache
from importlib import metadata
from pathlib import Path

import casadi

PACKAGE_DIR = Path(__file__).resolve().parents[1]
#: Files whose text determines the generated code of every library.
SOURCE_FILES = sorted(
    [*(PACKAGE_DIR / "symbolic").glob("*.py"),
     PACKAGE_DIR / "catalog.py",
     PACKAGE_DIR / "codegen" / "kernels.py",
     PACKAGE_DIR / "codegen" / "multibody_kernels.py",
     PACKAGE_DIR / "codegen" / "sympy_to_casadi.py",
     PACKAGE_DIR / "codegen" / "generate.py"]
)


def generated_dir() -> Path:
    """``generated/`` of the source tree, or a folder of the cache for an installed package."""
    env = os.environ.get("SYMCAT_GENERATED")
    if env:
        return Path(env)
    repo = PACKAGE_DIR.parent / "generated"
    if repo.is_dir():
        return repo
    return cache_dir() / "generated"


def cache_dir() -> Path:
    """Compiled-library cache (``$SYMCAT_CACHE`` or ``~/.cache/symcat``)."""
    env = os.environ.get("SYMCAT_CACHE")
    base = Path(env) if env else Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "symcat"
    return base


@lru_cache(maxsize=None)
def tool_versions() -> dict[str, str]:
    """Versions of the tools that shape the generated C (SymPy read without importing it)."""
    return {"sympy": metadata.version("sympy"), "casadi": casadi.__version__}


def source_hash(library: str) -> str:
    """Content hash of everything that determines the generated C of ``library``."""
    h = hashlib.sha256()
    h.update(library.encode())
    h.update(json.dumps(tool_versions(), sort_keys=True).encode())
    for path in SOURCE_FILES:
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def manifest_path() -> Path:
    return generated_dir() / "manifest.json"


def read_manifest() -> dict:
    try:
        return json.loads(manifest_path().read_text())
    except FileNotFoundError:
        return {"libraries": {}}


def file_sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def atomic_write(path: Path, data: bytes) -> None:
    """Write ``path`` so that a reader never sees a partial file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)
