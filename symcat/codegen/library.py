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
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import casadi as ca
import numpy as np

from ..errors import CompilerError
from .paths import cache_dir, generated_dir, is_current, read_manifest, read_sx_text, regenerated_dir, sx_path

log = logging.getLogger(__name__)

#: -O1 keeps compile times short; -fno-tree-dominator-opts avoids minutes of compile time on
#: functions with thousands of outputs (measured).
CFLAGS = ("-O1", "-fno-tree-dominator-opts", "-fPIC", "-shared")

#: CasADi Function options that merge common subexpressions (as the kernels are built:
#: ``kernels.FUNCTION_OPTIONS``, ``multibody_kernels.OPTS``, whose jacobian companions repeat
#: :func:`merged`; they would call it at the next ``make generate``).
CSE_OPTIONS = {"cse": True}


def merged(fn: ca.Function) -> ca.Function:
    """The SX function ``fn`` rebuilt with :data:`CSE_OPTIONS` (``jacobian`` and ``expand``
    return functions without them)."""
    args = fn.sx_in()
    return ca.Function(fn.name(), args, fn.call(args), fn.name_in(), fn.name_out(), CSE_OPTIONS)


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


def cached_library(name: str, key_source: bytes, flags: tuple = CFLAGS) -> Path:
    """Where the library compiled from C identified by ``key_source`` lives in the cache
    (whether or not it is there yet): ``<cache>/<name>-<key>.so``."""
    compiler = find_compiler()
    key = hashlib.sha256(key_source + _compiler_identity(compiler).encode() + " ".join(flags).encode()).hexdigest()[:20]
    return cache_dir() / f"{name}-{key}.so"


def compile_c(c_path: Path, name: str, flags: tuple = CFLAGS, key_source: bytes | None = None) -> Path:
    """Compile ``c_path`` into the cache (if not there yet) and return the library path.
    ``key_source``: what identifies the C text, if not the text itself (the caller then
    writes ``c_path`` only when the returned library does not exist yet: see
    :func:`cached_library`)."""
    target = cached_library(name, c_path.read_bytes() if key_source is None else key_source, flags)
    if target.exists():
        return target
    from ..progress import notice

    notice(f"compiling the kernel library {name} with the C compiler (once per machine; cached in {target.parent})")
    build_library(find_compiler(), flags, c_path, target)
    return target


def build_library(compiler: str, flags: tuple, c_path: Path, target: Path) -> None:
    """Compile ``c_path`` with ``flags`` into ``target``, installed whole (:func:`os.replace`).

    Raises
    ------
    CompilerError
        If the compiler cannot run or fails (with its command and the end of its messages).
    """
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.{time.monotonic_ns()}.tmp")
    cmd = [compiler, *flags, str(c_path), "-o", str(tmp), "-lm"]
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


def fused(functions) -> ca.Function:
    """One Function of the same inputs giving the outputs of all ``functions`` in order (they
    share their inputs): one call from Python instead of several. A single one is returned as
    it is."""
    if len(functions) == 1:
        return functions[0]
    first = functions[0]
    args = [ca.MX.sym(first.name_in(i), first.sparsity_in(i)) for i in range(first.n_in())]
    outputs = [out for f in functions for out in f.call(args)]
    return ca.Function("_".join(f.name() for f in functions), args, outputs)


class BufferedFunction:
    """A CasADi Function evaluated in preallocated numpy arrays: a call of a small kernel from
    Python costs 0.2 us instead of about 30 us (no conversion of the inputs to ``DM`` and of
    the outputs back).

    Parameters
    ----------
    function : casadi.Function
        With dense inputs (outputs may be sparse: they are returned dense).
    """

    def __init__(self, function: ca.Function):
        for i in range(function.n_in()):
            if not function.sparsity_in(i).is_dense():
                raise ValueError(f"{function.name()}: input {i} is sparse; BufferedFunction needs dense inputs")
        self.function = function
        self._buffer, self._eval = function.buffer()
        self._inputs = [np.zeros(function.nnz_in(i)) for i in range(function.n_in())]
        self._outputs = [np.zeros(function.nnz_out(i)) for i in range(function.n_out())]
        # The buffer keeps raw pointers: the arrays above are only ever written in place.
        for i, a in enumerate(self._inputs):
            self._buffer.set_arg(i, memoryview(a))
        for i, a in enumerate(self._outputs):
            self._buffer.set_res(i, memoryview(a))
        self._patterns = None  # see __call__

    def sparse(self, *args) -> list:
        """The outputs as SciPy CSC matrices (patterns read once), at the inputs ``args``."""
        import scipy.sparse as sps

        if not hasattr(self, "_ccs"):
            self._ccs = []
            for i in range(self.function.n_out()):
                sp = self.function.sparsity_out(i)
                colind, row = sp.get_ccs()
                self._ccs.append((np.array(row, int), np.array(colind, int), sp.shape))
        self._evaluate(args)
        return [sps.csc_matrix((nz.copy(), row, colind), shape=shape)
                for nz, (row, colind, shape) in zip(self._outputs, self._ccs)]

    def nonzeros(self, *args) -> list[np.ndarray]:
        """The outputs' nonzeros in CasADi's (column-major) order, as new arrays: for a sparse
        output to be built from its pattern (``function.sparsity_out(i).get_ccs()``).

        Raises
        ------
        RuntimeError
            If the function reports a failed evaluation (as a regular call does).
        """
        self._evaluate(args)
        return [nz.copy() for nz in self._outputs]

    def bind(self, inputs: dict | None = None, outputs: dict | None = None) -> None:
        """Evaluate input ``i`` from, and write output ``i`` into, the caller's own array
        (``{i: array}``: contiguous float64 of the right size, kept alive by the caller and
        only written in place): a large argument passed from one call to the next (a
        factorization carried by compiled steps) then stays in the caller's memory instead of
        being copied in and out. An input passed as its bound array itself is not copied: the
        compiled code reads it where it is, and code that writes into an input (see
        :func:`~symcat.codegen.band_c.store_function`) writes into the caller's array."""
        for i, a in (inputs or {}).items():
            if a is not self._inputs[i]:
                self._check_bound(a, self._inputs[i].size)
                self._inputs[i] = a
                self._buffer.set_arg(i, memoryview(a))
        for i, a in (outputs or {}).items():
            if a is not self._outputs[i]:
                self._check_bound(a, self._outputs[i].size)
                self._outputs[i] = a
                self._buffer.set_res(i, memoryview(a))

    @staticmethod
    def _check_bound(a, size: int) -> None:
        if not (isinstance(a, np.ndarray) and a.dtype == np.float64 and a.flags.c_contiguous and a.size == size):
            raise ValueError(f"bind: a contiguous float64 array of {size} entries is needed")

    def outputs(self, *args) -> list[np.ndarray]:
        """The outputs' nonzeros at the inputs ``args`` in the function's own arrays (and the
        caller's bound ones, :meth:`bind`), not copied: valid until the next call."""
        self._evaluate(args)
        return self._outputs

    def _evaluate(self, args) -> None:
        for a, v in zip(self._inputs, args):
            if a is not v:
                a[:] = v
        self._eval()
        if self._buffer.ret():
            self.function(*args)  # raises CasADi's own error
            raise RuntimeError(f"{self.function.name()}: evaluation failed")

    def __call__(self, *args) -> list[np.ndarray]:
        """Dense outputs (new arrays, shaped as the Function's) at the inputs ``args``.

        Raises
        ------
        RuntimeError
            If the function reports a failed evaluation (as a regular call does).
        """
        if self._patterns is None:
            # Per output: its shape and the row-major positions of its nonzeros (CasADi's are
            # column-major): one 1-D scatter per call. Built at the first call: a caller of
            # nonzeros() never needs them, and on large outputs they take milliseconds.
            self._patterns = []
            for i in range(self.function.n_out()):
                sp = self.function.sparsity_out(i)
                flat = np.array(sp.row(), int) * sp.shape[1] + np.array(sp.get_col(), int)
                self._patterns.append((sp.shape, sp.shape[0] * sp.shape[1], flat))
        self._evaluate(args)
        out = []
        for nz, (shape, size, flat) in zip(self._outputs, self._patterns):
            dense = np.zeros(size)
            dense[flat] = nz
            out.append(dense.reshape(shape))
        return out


_LOADED: dict[str, KernelLibrary] = {}


_FOLDERS: dict[str, Path] = {}


def generated_folder(name: str) -> Path:
    """The folder whose code of library ``name`` is current: the shipped ``generated/`` or, if
    that is stale or missing there, :func:`~.paths.regenerated_dir` in the cache, where it is
    regenerated on first need (imports SymPy; the source tree is never written by a run)."""
    folder = _FOLDERS.get(name)
    if folder is not None:
        return folder
    for folder in (generated_dir(), regenerated_dir()):
        if is_current(folder, name):
            _FOLDERS[name] = folder
            return folder
    folder = regenerated_dir()
    log.warning("kernel library %s is missing or stale in %s: regenerating it into %s (once; "
                "`make generate` updates the shipped code)", name, generated_dir(), folder)
    from .generate import generate  # deferred: imports SymPy

    generate([name], out_dir=folder, verbose=False)
    _FOLDERS[name] = folder
    return folder


def ensure_generated(name: str) -> Path:
    """Path of current generated C for ``name`` (see :func:`generated_folder`)."""
    return generated_folder(name) / f"{name}.c"


class SymbolicKernelLibrary(KernelLibrary):
    """A kernel library as CasADi SX functions, deserialized from the generated code (no
    SymPy): a graph built from them expands into one SX function (see :func:`symbolic_kernels`).
    The ``jac_`` companions are not shipped in this form (the expanded graph is differentiated
    as a whole); asking for one derives the library in SymPy."""

    def __getitem__(self, function: str) -> ca.Function:
        if not self.functions:
            text = read_sx_text(sx_path(generated_folder(self.name), self.name))
            self.functions.update((f.name(), f) for f in map(ca.Function.deserialize, text.splitlines()))
        if function not in self.functions:
            from .kernels import library_functions  # deferred: imports SymPy

            self.functions.update((f.name(), f) for f in library_functions(self.name))
        return self.functions[function]


_SYMBOLIC: dict[str, SymbolicKernelLibrary] = {}
_SYMBOLIC_DEPTH = [0]


@contextmanager
def symbolic_kernels():
    """Within this context :func:`kernel_library` gives the kernels as SX functions instead of
    compiled externals, so that a model graph built there can be expanded to SX, differentiated
    and compiled as a whole (:mod:`symcat.codegen.model_dae`)."""
    _SYMBOLIC_DEPTH[0] += 1
    try:
        yield
    finally:
        _SYMBOLIC_DEPTH[0] -= 1


def in_symbolic_kernels() -> bool:
    """Whether :func:`kernel_library` gives SX forms now (inside :func:`symbolic_kernels`):
    functions cached over compiled kernels must then be built afresh."""
    return bool(_SYMBOLIC_DEPTH[0])


def kernel_library(name: str) -> KernelLibrary:
    """Load (compiling on first use) the kernel library ``name``; inside
    :func:`symbolic_kernels`, its SX form."""
    if _SYMBOLIC_DEPTH[0]:
        return _SYMBOLIC.setdefault(name, SymbolicKernelLibrary(name, generated_dir() / f"{name}.c"))
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
        info = _INTERFACES[name] = read_manifest(generated_folder(name))["libraries"][name]["interface"]
    return info


def write_functions_c(functions, name: str, folder: Path) -> Path:
    """Generate the C of the SX ``functions`` into ``folder/<name>.c`` (its path)."""
    cwd = os.getcwd()
    os.chdir(folder)  # CasADi writes relative to the working directory
    try:
        gen = ca.CodeGenerator(f"{name}.c", {"with_header": False, "verbose": False})
        for fn in functions:
            gen.add(fn)
        gen.generate()
    finally:
        os.chdir(cwd)
    return folder / f"{name}.c"
