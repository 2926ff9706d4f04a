"""The rest of a generalized-alpha step (:mod:`.alpha_step`: bodies, joints, contacts,
multipliers) as the functions the Newton iteration evaluates: expanded to scalar operations in
CasADi, or compiled to C and cached.

A short run (``build=None`` in :func:`compiled_rest`) does not wait for the compiler: it
evaluates the expanded functions and, unless ``$SYMCAT_OPTIMIZE`` says otherwise
(:mod:`symcat.codegen.optimized`), leaves the rest's graph in the cache for a background
process (this module's ``__main__``) that writes its C and compiles it, so that the model's
later runs load the library. Writing the seed scene's C takes longer than its short run
itself, which is why that is not done in the run."""
from __future__ import annotations

import logging
import sys
from pathlib import Path

import casadi as ca

from ..errors import CompilerError

log = logging.getLogger(__name__)

#: What the cache key of the rest's library adds to its graph's serialization.
KEY_SUFFIX = b"|alpha_rest|cse"


def expanded_rest(rest: ca.Function) -> tuple[ca.Function, ca.Function]:
    """The rest's function (built on the kernels' SX forms) expanded to scalar operations, and
    its Jacobian in the unknowns; the MX graph if a kernel has no SX form."""
    try:
        rest = rest.expand()
        args = rest.sx_in()
    except RuntimeError:
        args = rest.mx_in()
    jac = ca.Function("alpha_rest_jacobian", args, [ca.jacobian(rest(*args)[0], args[0])])
    return rest, jac


def _write_c(rest: ca.Function, folder: Path) -> Path:
    """The C of the rest's expanded function and Jacobian (subexpressions merged) in ``folder``."""
    from ..codegen.library import merged, write_functions_c

    sx, jac = expanded_rest(rest)
    return write_functions_c([merged(sx), merged(jac)], "alpha_rest", folder)


def compiled_rest(rest: ca.Function, build: bool | None = True) -> tuple[ca.Function, ca.Function]:
    """The rest's function and its Jacobian compiled to C, cached under a key of the graph
    (:func:`symcat.codegen.model_dae.compiled_library`: once per machine and model, -O0 at
    once and optimized in the background). A vehicle's rest (hundreds of unknowns, the wheel/rail
    contacts' geometry and creep) is most of the step's work: optimized, its Jacobian evaluates
    about 20 times faster than expanded in CasADi's virtual machine, and a cached library also
    spares differentiating it at the start of every run. ``build=None``: a library already
    cached, else the expanded functions (a short run: compiling the seed scene's step takes
    about 30 s, which its first thousand steps would not repay) while the library is built in
    the background (module docstring)."""
    from ..codegen.model_dae import compiled_library

    key = rest.serialize().encode() + KEY_SUFFIX
    try:
        path = compiled_library("alpha_rest", key, lambda folder: _write_c(rest, folder), build=build is not None)
    except (RuntimeError, CompilerError) as exc:  # no SX form, or no compiler: evaluated in CasADi
        log.warning("the generalized-alpha step could not be compiled (%s); evaluating it in CasADi", exc)
        return expanded_rest(rest)
    if path is None:
        compile_later(rest, key)
        return expanded_rest(rest)
    return ca.external("alpha_rest", str(path)), ca.external("alpha_rest_jacobian", str(path))


def _graph_path(library: Path) -> Path:
    """Where the rest's serialized graph waits for the background job that compiles ``library``."""
    return library.with_suffix(".casadi")


def compile_later(rest: ca.Function, key: bytes) -> bool:
    """Leave ``rest`` (its library's cache ``key``) for a background job that writes its C and
    compiles the optimized library that :func:`compiled_rest` then finds; True if a job was
    started. Not in ``$SYMCAT_OPTIMIZE`` modes ``now`` and ``off``, nor when one failed on this
    graph before, nor while any background job compiles into the cache: a study of many short
    runs of different models (each its own graph) must not start as many compilers; a later
    run starts the next."""
    from ..codegen import model_dae
    from ..codegen.optimized import OPTIMIZED_FLAGS, failed_path, jobs_running, optimize_mode, start_background

    if optimize_mode() != "background":
        return False
    library = model_dae.cached_library("alpha_rest", key, OPTIMIZED_FLAGS)
    if library.exists() or failed_path(library).exists() or jobs_running(library.parent):
        return False
    from ..codegen.paths import atomic_write

    atomic_write(_graph_path(library), rest.serialize().encode())
    return start_background(library, OPTIMIZED_FLAGS, module=__name__)


def _build_library(library: Path, flags: tuple) -> int:
    """The background job of :func:`compile_later`: the waiting graph's C, then its compilation
    (:func:`symcat.codegen.optimized.compile_written`)."""
    from ..codegen.optimized import compile_written

    return compile_written(library, flags, _graph_path(library),
                           lambda graph, folder: _write_c(ca.Function.deserialize(graph.read_text()), folder))


if __name__ == "__main__":
    sys.exit(_build_library(Path(sys.argv[1]), tuple(sys.argv[2:])))
