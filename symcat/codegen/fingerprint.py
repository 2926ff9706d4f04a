"""An exact digest of plain data (a :class:`~symcat.scene.Scene`: numbers, strings, arrays,
sparse matrices, dataclasses of them), for caches keyed by what a model was built from
(:mod:`symcat.integrate.alpha_chunk_cache`). A :class:`~symcat.assembly.multibody.MultibodyModel`
keeps the digest of its scene as it was when the model was built (:attr:`scene_digest`), so
that a scene changed afterwards, which the built model does not follow, is not taken for it."""
from __future__ import annotations

import dataclasses
import hashlib
import struct

import numpy as np
import scipy.sparse as sps


class Undescribed(Exception):
    """A value :func:`_describe` does not know how to digest exactly."""


def _describe(value, out: list) -> None:
    """Append an exact, unambiguous description of ``value`` (type tags, lengths, bytes) to
    ``out``.

    Raises
    ------
    Undescribed
        For anything but None, bools, numbers, strings, bytes, sequences, dicts, NumPy arrays,
        SciPy sparse matrices and dataclass instances of them (a callable, a symbolic
        expression: their text need not say what they compute).
    """
    if value is None or isinstance(value, (bool, np.bool_)):
        out.append(repr(value).encode())
    elif isinstance(value, (int, np.integer)):
        out.append(b"i" + str(int(value)).encode())
    elif isinstance(value, (float, np.floating)):
        out.append(b"f" + struct.pack("<d", float(value)))
    elif isinstance(value, str):
        data = value.encode()
        out.append(b"s%d:" % len(data) + data)
    elif isinstance(value, bytes):
        out.append(b"b%d:" % len(value) + value)
    elif isinstance(value, np.ndarray):
        if value.dtype == object:
            out.append(b"o%d:" % value.size)
            for item in value.ravel():
                _describe(item, out)
        else:
            array = np.ascontiguousarray(value)
            out.append(f"a{array.dtype.str}{array.shape}:".encode() + array.tobytes())
    elif sps.issparse(value):
        m = sps.csr_matrix(value, copy=True)
        m.sum_duplicates()
        m.sort_indices()
        out.append(f"S{m.shape}".encode())
        for part in (m.indptr.astype(np.int64), m.indices.astype(np.int64), m.data.astype(float)):
            _describe(part, out)
    elif isinstance(value, (list, tuple)):
        out.append(b"%s%d:" % (b"l" if isinstance(value, list) else b"t", len(value)))
        for item in value:
            _describe(item, out)
    elif isinstance(value, dict):
        items = [(digest(k), v) for k, v in value.items()]
        out.append(b"d%d:" % len(items))
        for k, v in sorted(items, key=lambda kv: kv[0]):
            out.append(k)
            _describe(v, out)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        cls = type(value)
        out.append(f"D{cls.__module__}.{cls.__qualname__}:".encode())
        for f in dataclasses.fields(value):
            out.append(f.name.encode() + b"=")
            _describe(getattr(value, f.name), out)
    else:
        raise Undescribed(type(value).__name__)


def digest(value) -> bytes:
    """The SHA-256 digest of :func:`_describe`'s description of ``value``.

    Raises
    ------
    Undescribed
        See :func:`_describe`.
    """
    out: list = []
    _describe(value, out)
    return hashlib.sha256(b"|".join(out)).digest()


def scene_digest(scene) -> bytes | None:
    """:func:`digest` of ``scene``, or None if it holds a value without an exact description."""
    try:
        return digest(scene)
    except Undescribed:
        return None
