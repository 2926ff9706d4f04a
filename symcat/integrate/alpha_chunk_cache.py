"""The compiled steps' cache keyed by the model (:mod:`.alpha_chunk`): a run of a model whose
steps were compiled before finds their library without building the step's equations.

Why: the compiled library is identified by the graph of the step's residual
(:func:`.alpha_chunk._compiled`), and that graph is built from the Python step equations
(:class:`~.alpha_step.StepEquations`, a :class:`~.alpha_chunk_residual.ChunkResidual`, a
serialization): on a small model (a wire under a moving load, a cable pendulum) that set-up
costs as much as the compiled steps of a coarse run. What the graph follows from is the
scene the model was built from (plain data), the assembled model's initial state and fixed
coordinates, the run's settings, symcat's source, the shipped kernels and the tools'
versions; their digest (:func:`model_key`) names a small record (:func:`read_record`) that a
run with the graph writes: the digest of the graph's key (which names the library) and the
multipliers' tolerance scale. A run that finds the record loads the library and builds the
Python step equations only if a step falls back to them.

A model the digest cannot describe exactly has no key, and its runs take the graph's path as
before: a scene holding something other than numbers, strings, arrays, sparse matrices and
dataclasses of them (:mod:`symcat.codegen.fingerprint`), a scene changed since the model was
built from it (the model does not follow it: its digest then differs from the one the model
kept), or a subclass of :class:`~symcat.assembly.multibody.MultibodyModel`, which may hold
more. What the key cannot see is a change made to the assembled model's own internals (its
kernel groups' values, its index maps) after it was built.

A library once loaded is kept for the process's next runs (:func:`loaded`).
"""
from __future__ import annotations

import hashlib
import json
from collections import OrderedDict
from functools import lru_cache, wraps
from pathlib import Path

import casadi as ca
import numpy as np

from ..codegen.fingerprint import Undescribed, digest, scene_digest
from ..codegen.library import BufferedFunction
from ..codegen.paths import PACKAGE_DIR, atomic_write, cache_dir, generated_dir, manifest_path, regenerated_dir, \
    tool_versions

#: Version of the record's content (a change makes older records unreadable, not wrong).
RECORD_VERSION = 2
#: Functions :func:`model_memo` keeps in a process, two or three per model (least recently used
#: first out; a small model's are tens to hundreds of kilobytes, a line's megabytes: a process
#: that runs many lines, a study's worker, keeps a few models' worth).
MEMO_SIZE = 12
_MEMO: OrderedDict = OrderedDict()


@lru_cache(maxsize=None)
def _code_digest() -> bytes:
    """What every compiled step follows from besides the model: symcat's Python source, the
    shipped and regenerated kernels' manifests (their code's hashes) and the tools' versions.
    Read once per process."""
    h = hashlib.sha256()
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        h.update(str(path.relative_to(PACKAGE_DIR)).encode() + b"\0" + path.read_bytes())
    for folder in (generated_dir(), regenerated_dir()):
        manifest = manifest_path(folder)
        h.update(manifest.read_bytes() if manifest.is_file() else b"-")
    h.update(json.dumps(tool_versions(), sort_keys=True).encode())
    return h.digest()


def model_key(model, form, settings) -> str | None:
    """The hex digest naming the compiled steps of ``model`` (its :class:`Formulation` ``form``)
    under ``settings`` (the run's settings that shape the code, e.g. variant and spectral
    radius), or None when the model cannot be described exactly (see the module's notes)."""
    from ..assembly.multibody import MultibodyModel

    if type(model) is not MultibodyModel:
        return None
    built = getattr(model, "scene_digest", None)
    if built is None or not _scene_unchanged(model, built):
        return None
    try:
        parts = [model.window_size, model.q0, model.v0, model.free, model.s0, model.sc0,
                 np.asarray(form.q_fixed, float), form.formulation, form.index, form.cholesky, settings]
        return hashlib.sha256(_code_digest() + built + digest(parts)).hexdigest()
    except Undescribed:
        return None


def _scene_unchanged(model, built: bytes) -> bool:
    """Whether ``model``'s scene still digests to ``built`` (it was not changed after the model
    was built from it); within a run (:func:`one_run`), digested once."""
    checked = model.__dict__.get("_scene_checked")  # (None: not in a run; "run": not yet in this run)
    if isinstance(checked, bool):
        return checked
    same = scene_digest(model.scene) == built
    if checked == "run":
        model._scene_checked = same
    return same


def one_run(run):
    """Decorate ``run(model, ...)``, a run of a model (its time integration and the result's
    post-processing): the scene cannot change meanwhile, so :func:`model_key` digests it once
    instead of at each of the run's keys (the compiled steps', the initial state's terms', the
    post-processing's: a line's scene takes 0.02 s to digest)."""
    @wraps(run)
    def wrapper(model, *args, **kwargs):
        outer = model.__dict__.get("_scene_checked")
        model._scene_checked = "run"
        try:
            return run(model, *args, **kwargs)
        finally:
            model._scene_checked = outer
    return wrapper


def _record_path(key: str) -> Path:
    return cache_dir() / f"alpha_chunk-model-{key[:40]}.json"


def read_record(key: str | None) -> dict | None:
    """The record of the compiled steps named ``key`` (:func:`write_record`), or None."""
    if key is None:
        return None
    try:
        record = json.loads(_record_path(key).read_text())
    except (OSError, ValueError):
        return None
    if record.get("version") != RECORD_VERSION or record.get("key") != key:
        return None
    return record


def write_record(key: str | None, library_key: str, mass_scale: float) -> None:
    """Record that the model named ``key`` has the compiled steps whose library key digests to
    ``library_key``, with the multipliers' tolerance scale ``mass_scale`` (kg) its runs start
    from."""
    if key is None:
        return
    record = {"version": RECORD_VERSION, "key": key, "library": library_key, "mass_scale": float(mass_scale)}
    atomic_write(_record_path(key), json.dumps(record).encode())


def model_memo(model, form, tag: tuple, build):
    """``build()`` once per process for all models of one digest (:func:`model_key` of ``model``
    and ``form`` with ``tag``, which names what is built and what else it follows from, e.g. the
    element windows); every call when the model has no key.

    Why: a run builds its model anew, and the functions a run needs besides the compiled steps
    (the consistent initial state's terms, the results' post-processing terms and their maps
    over the outputs) are built from it as CasADi graphs; on a small model that costs as much
    as the compiled steps of a coarse run, although the digest says the graph would be the same
    as the last run's. The values are kept, not copied: what ``build`` returns must not change
    with use in a way that depends on the model (a cache of evaluations by size is fine)."""
    key = model_key(model, form, ("memo",) + tuple(tag))
    if key is None:
        return build()
    found = _MEMO.get(key)
    if found is None:
        found = _MEMO[key] = build()
        while len(_MEMO) > MEMO_SIZE:
            _MEMO.popitem(last=False)
    else:
        _MEMO.move_to_end(key)
    return found


#: Libraries whose loaded functions a process keeps for the next runs (least recently used
#: first out): a function's evaluation buffers are allocated when it is loaded, and on a line
#: its work vector takes tens of megabytes (the factorization's graph), whose allocation and
#: first touch cost as much as a short run's steps; kept for two models, not more.
LOADED_LIBRARIES = 2
_LOADED: dict = {}


def loaded(path: Path) -> "_Lengths":
    """The functions of the library at ``path``, loaded once per process (see
    :data:`LOADED_LIBRARIES`; the callers bind their own arrays before each call)."""
    fns = _LOADED.pop(path, None)
    if fns is None:  # (not `or`: a library none of whose functions is loaded yet is empty)
        fns = _Lengths(path)
    _LOADED[path] = fns  # (the most recent last)
    while len(_LOADED) > LOADED_LIBRARIES:
        _LOADED.pop(next(iter(_LOADED)))
    return fns


class _Lengths(dict):
    """The library's functions by length (and ``"renew"``), loaded at first use."""

    def __init__(self, path: Path):
        super().__init__()
        self.path = path

    def __missing__(self, length) -> BufferedFunction:
        fn = self[length] = BufferedFunction(ca.external(f"alpha_chunk_{length}", str(self.path)))
        return fn
