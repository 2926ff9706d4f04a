"""Where generated C and compiled libraries live, and what determines them (no SymPy)."""
from __future__ import annotations

import gzip
import hashlib
import json
import os
from functools import lru_cache
from importlib import metadata
from pathlib import Path

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
    """The shipped generated code: ``$SYMCAT_GENERATED``, else the package data of an installed
    symcat (``symcat/_generated``, see ``pyproject.toml``), else ``generated/`` of the source
    tree. Only ``make generate`` writes here; a run that meets stale code regenerates it into
    :func:`regenerated_dir` instead."""
    env = os.environ.get("SYMCAT_GENERATED")
    if env:
        return Path(env)
    installed = PACKAGE_DIR / "_generated"
    if installed.is_dir():
        return installed
    return PACKAGE_DIR.parent / "generated"


def regenerated_dir() -> Path:
    """Where a run writes the libraries it had to regenerate (stale or missing shipped code):
    a folder of the cache, never the source tree or the installed package."""
    return cache_dir() / "generated"


def cache_dir() -> Path:
    """Compiled-library cache (``$SYMCAT_CACHE`` or ``~/.cache/symcat``)."""
    env = os.environ.get("SYMCAT_CACHE")
    base = Path(env) if env else Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "symcat"
    return base


#: The tools whose versions shape the generated code; ``pyproject.toml`` pins them to the
#: versions recorded in the manifest (a test checks that they agree).
TOOLS = ("sympy", "casadi")


@lru_cache(maxsize=None)
def tool_versions() -> dict[str, str]:
    """Installed versions of :data:`TOOLS` (read from the package metadata: no import)."""
    return {tool: metadata.version(tool) for tool in TOOLS}


@lru_cache(maxsize=None)
def _sources_digest() -> bytes:
    h = hashlib.sha256()
    for path in SOURCE_FILES:
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.digest()


def source_hash(library: str) -> str:
    """Content hash of the symbolic sources that determine the generated code of ``library``.

    Tool versions are not part of it: the shipped C stays valid under any CasADi that loads
    it, so an install with other versions runs the shipped code instead of regenerating it.
    Reproducibility comes from the pins (``make check-generated`` compares them).
    """
    h = hashlib.sha256()
    h.update(library.encode())
    h.update(_sources_digest())
    return h.hexdigest()


def manifest_path(folder: Path | None = None) -> Path:
    return (folder or generated_dir()) / "manifest.json"


def read_manifest(folder: Path | None = None) -> dict:
    try:
        return json.loads(manifest_path(folder).read_text())
    except FileNotFoundError:
        return {"libraries": {}}


def sx_path(folder: Path, library: str) -> Path:
    """The serialized CasADi SX functions of ``library`` (gzip of one serialized function a
    line): what a whole-model DAE expands into, without SymPy."""
    return folder / f"{library}.sx.gz"


def read_sx_text(path: Path) -> str:
    return gzip.decompress(path.read_bytes()).decode()


def text_sha256(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def file_sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def atomic_write(path: Path, data: bytes) -> None:
    """Write ``path`` so that a reader never sees a partial file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def is_current(folder: Path, name: str, entry: dict | None = None) -> bool:
    """Whether ``folder`` holds the code of library ``name`` for today's symbolic sources,
    intact (C and serialized SX as the manifest recorded them)."""
    entry = entry if entry is not None else read_manifest(folder)["libraries"].get(name)
    c_path, sx = folder / f"{name}.c", sx_path(folder, name)
    return (
        entry is not None
        and entry.get("source_hash") == source_hash(name)
        and c_path.exists() and entry.get("c_sha256") == file_sha256(c_path)
        and sx.exists() and entry.get("sx_sha256") == text_sha256(read_sx_text(sx))
    )
