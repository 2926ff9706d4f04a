"""The C of the compiled generalized-alpha steps (:mod:`.alpha_chunk`), and its optimized
library built by a background process for a model's later runs.

Why: a catenary line's compiled steps (its wires as loops, :mod:`.alpha_chunk_wires`) are slower
than the Python steps when compiled at -O0 (their element kernels and band solves at -O0) and
take the optimizing compiler tens of seconds. A run that finds no optimized library therefore
takes the Python steps and leaves the compiled ones to a background process (this module's
``__main__``): their functions, serialized by the run, written to C and compiled there
(:func:`symcat.codegen.optimized.compile_waiting`); the model's next runs load the library."""
from __future__ import annotations

import os
import re
import sys
from pathlib import Path

import casadi as ca

from ..codegen.band_c import include_in, inputs_by_reference
from ..codegen.library import write_functions_c
from ..errors import CompilerError


def write_c(functions: list[ca.Function], folder: Path) -> Path:
    """The C of the compiled steps' ``functions`` in ``folder`` (its path), with the band's
    kernels it calls; the factor's memory (the first function's input 4) read and written where
    the caller holds it."""
    with inputs_by_reference():
        path = include_in(write_functions_c(functions, "alpha_chunk", folder))
    size = functions[0].nnz_in(4)
    if re.search(rf"casadi_copy\(arg\[\d+\], {size}, ", path.read_text()):
        raise CompilerError(f"the compiled steps' code copies the factor's memory ({size} numbers) it must write")
    return path


def compile_later(functions: list[ca.Function], library: Path, flags: tuple) -> bool:
    """Leave ``functions`` for a background job that writes their C and compiles ``library``
    with ``flags``; True if a job was started. Not when one failed on this library before, nor
    while any background job compiles into the cache (a study of many short runs must not start
    as many compilers; a later run starts the next)."""
    from ..codegen.optimized import failed_path, jobs_running, start_background

    if library.exists() or failed_path(library).exists() or jobs_running(library.parent):
        return False
    # one stream: the functions share their parts (each serialized alone repeats them all)
    graph = _graph_path(library)
    partial = graph.with_name(f".{graph.name}.{os.getpid()}.tmp")
    serializer = ca.FileSerializer(str(partial))
    serializer.pack(functions)
    del serializer  # (closes the file)
    os.replace(partial, graph)
    return start_background(library, flags, module=__name__)


def _graph_path(library: Path) -> Path:
    """Where the serialized functions wait for the background job."""
    return library.with_suffix(".casadi")


def _build_library(library: Path, flags: tuple) -> int:
    """The background job of :func:`compile_later`: the waiting functions' C, then its
    compilation (:func:`symcat.codegen.optimized.compile_written`)."""
    from ..codegen.optimized import compile_written

    return compile_written(library, flags, _graph_path(library),
                           lambda graph, folder: write_c(ca.FileDeserializer(str(graph)).unpack(), folder))


if __name__ == "__main__":
    sys.exit(_build_library(Path(sys.argv[1]), tuple(sys.argv[2:])))
