"""One compiled C library per model: its whole DAE residual and the residual's Jacobian.

IDAS spends most of a wheel/rail model's time in the Jacobian of the residual. Built as a
CasADi MX graph over the compiled kernels (externals), that Jacobian is thousands of small
sparse products run by CasADi's virtual machine: 4 to 8 ms for the seed vehicle (467 unknowns,
7745 nonzeros). The same DAE built over the kernels' SX expressions (:func:`symbolic_kernels`),
expanded to one SX function, differentiated in SX and compiled costs 0.3 ms, and its residual
0.1 ms instead of 0.2 to 0.4 (``python -m bench.model_dae`` measures both). The library is
cached under a key of the expanded function, so a model is compiled once per machine: processes
that need the same library at the same time (parallel test workers, runs of a study) compile it
once, the others wait for it (:func:`_compiling`).
"""
from __future__ import annotations

import logging
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Callable

import casadi as ca

from .library import build_library, cached_library, find_compiler, merged, symbolic_kernels, write_functions_c
from .optimized import OPTIMIZED_FLAGS, optimize_mode, source_path, start_background
from ..progress import notice
from .paths import atomic_write

log = logging.getLogger(__name__)

#: The code is straight-line arithmetic, compiled at -O0 first (11 s for the seed vehicle's 5 MB),
#: then optimized in the background (:mod:`.optimized`: twice as fast, 27 s to compile).
FLAGS = ("-O0", "-fPIC", "-shared")

#: What the library's code is, beyond the graph, in its cache key (merged subexpressions).
LAYOUT = b"|cse"

#: Models generated and compiled by this process (the tests check that a second run makes none;
#: the seconds exclude the background compilers).
COMPILED = {"n": 0, "seconds": 0.0}


def compiled_dae(build: Callable[[], ca.Function]) -> ca.Function:
    """The DAE function that ``build`` returns (an MX function over the kernels), as a compiled
    external with its Jacobian companion ``jac_<name>``: same inputs, outputs and values. The
    library is the optimized one (:mod:`.optimized`) once there, else the -O0 one.

    ``build`` is called once as is (its serialization is the cache key) and, if the library is
    not in the cache yet, once inside :func:`symbolic_kernels`: it must obtain every kernel
    through :func:`symcat.codegen.library.kernel_library` while it runs.

    Raises
    ------
    RuntimeError
        If the graph cannot be expanded to SX (a kernel captured as an external outside
        ``build``); the caller then keeps the MX function.
    ParameterError
        If ``$SYMCAT_OPTIMIZE`` is not one of :data:`.optimized.MODES`.
    """
    fn = build()
    return ca.external(fn.name(), str(model_library(build, fn)))


def model_library(build: Callable[[], ca.Function], fn: ca.Function, mode: str | None = None) -> Path:
    """Path of the compiled library of the DAE ``fn = build()`` (see :func:`compiled_dae`),
    compiling what ``mode`` (default: ``$SYMCAT_OPTIMIZE``, :mod:`.optimized`) asks for."""
    name = fn.name()
    # The graph over the externals names each kernel library by its content-addressed path:
    # its serialization identifies the model without deriving anything.
    return compiled_library(f"model_{name}", fn.serialize().encode() + LAYOUT,
                            lambda folder: write_dae_c(build, name, folder), mode)


def compiled_library(name: str, key: bytes, write_c: Callable[[Path], Path], mode: str | None = None,
                     build: bool = True, optimized_flags: tuple = OPTIMIZED_FLAGS) -> Path | None:
    """Path of the cached library ``name`` identified by ``key``, compiled from the C that
    ``write_c(folder)`` writes (returning its path) when the library is not cached yet: -O0
    first and optimized (``optimized_flags``) in the background, or optimized now, or -O0 only
    (``mode``, default ``$SYMCAT_OPTIMIZE``, :mod:`.optimized`). ``build=False``: only a
    library already cached (``None`` if there is none)."""
    mode, plain, optimized, target = _tiers(name, key, mode, optimized_flags)
    if mode != "off" and optimized.exists():
        return optimized
    flags = optimized_flags if target == optimized else FLAGS
    if not build:
        return target if target.exists() else plain if plain.exists() else None
    if not target.exists():
        with _compiling(target):
            if not target.exists():  # not compiled by the process this one waited for
                t0 = time.perf_counter()
                with tempfile.TemporaryDirectory() as tmp:
                    notice(f"compiling this model's equations with the C compiler (once per machine and model; cached in {target.parent})")
                    c_path = write_c(Path(tmp))
                    if mode == "now":
                        log.info("compiling %s optimized (about 30 s for the seed vehicle's DAE)", name)
                    build_library(find_compiler(), flags, c_path, target)
                    if mode == "background" and not optimized.exists():
                        atomic_write(source_path(optimized), c_path.read_bytes())
                COMPILED["n"] += 1
                COMPILED["seconds"] += time.perf_counter() - t0
    if mode == "background" and source_path(optimized).exists():  # also a job that died
        start_background(optimized, optimized_flags)
    return target


def existing_library(name: str, key: bytes, mode: str | None = None,
                     optimized_flags: tuple = OPTIMIZED_FLAGS) -> Path | None:
    """What :func:`compiled_library` with these arguments would return if that needs no
    compiler now (the library it picks is cached; the optimized tier's background compiler is
    started as it would start it), else None."""
    mode, plain, optimized, target = _tiers(name, key, mode, optimized_flags)
    if mode != "off" and optimized.exists():
        return optimized
    if not target.exists():
        return None
    if mode == "background" and source_path(optimized).exists():
        start_background(optimized, optimized_flags)
    return target


def _tiers(name: str, key: bytes, mode: str | None, optimized_flags: tuple) -> tuple[str, Path, Path, Path]:
    """``(mode, plain, optimized, target)``: the optimization mode (default ``$SYMCAT_OPTIMIZE``),
    the -O0 and optimized libraries' cache paths, and the one a run compiles when neither is
    there (the optimized one in mode ``now``)."""
    mode = optimize_mode() if mode is None else mode
    plain = cached_library(name, key, FLAGS)
    optimized = cached_library(name, key, optimized_flags)
    return mode, plain, optimized, optimized if mode == "now" else plain


@contextmanager
def _compiling(target: Path):
    """Held while this process compiles ``target``: an exclusive lock on ``<target>.compiling``
    (released by the system if the process dies), so that another process needing the same
    library waits for it instead of compiling it a second time. Without ``fcntl`` (not POSIX)
    nothing is held: both compile, and :func:`os.replace` installs either intact library."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    target.parent.mkdir(parents=True, exist_ok=True)
    with open(target.with_suffix(".compiling"), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def write_dae_c(build: Callable[[], ca.Function], name: str, folder: Path) -> Path:
    """Generate the C of the DAE ``build()`` (named ``name``) and of its Jacobian into ``folder``
    (expanded over the kernels' SX and differentiated, subexpressions merged); its path.

    Raises
    ------
    RuntimeError
        If the graph calls a compiled kernel that does not expand (see :func:`compiled_dae`).
    """
    with symbolic_kernels():
        sx = build().expand()
    if any(sx.instruction_id(k) == ca.OP_CALL for k in range(sx.n_instructions())):
        # A kernel captured as an external before `build` ran: the C code would call a
        # symbol no library defines.
        raise RuntimeError(f"the DAE {name!r} calls compiled kernels that do not expand to SX")
    # Merged subexpressions (the expanded kernels repeat each other's work). The seed
    # vehicle: residual 63k -> 43k operations, Jacobian 222k -> 167k; the -O0 library 7.2
    # -> 5.4 MB, compiled in 10 s instead of 17 s; with cold caches, as IDAS meets it, the
    # Jacobian takes 1.1 ms instead of 1.8 ms and the residual 0.45 ms instead of 0.64 ms.
    sx = merged(sx)
    jac = merged(sx.jacobian())
    log.info("compiling the model's DAE (%d operations) and its Jacobian (%d)", sx.n_instructions(),
             jac.n_instructions())
    return write_functions_c([sx, jac], f"model_{name}", folder)
