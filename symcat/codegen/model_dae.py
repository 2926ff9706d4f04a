"""One compiled C library per model: its whole DAE residual and the residual's Jacobian.

IDAS spends most of a wheel/rail model's time in the Jacobian of the residual. Built as a
CasADi MX graph over the compiled kernels (externals), that Jacobian is thousands of small
sparse products run by CasADi's virtual machine: 4 to 8 ms for the seed vehicle (467 unknowns,
7745 nonzeros). The same DAE built over the kernels' SX expressions (:func:`symbolic_kernels`),
expanded to one SX function, differentiated in SX and compiled costs 0.3 ms, and its residual
0.1 ms instead of 0.2 to 0.4 (``python -m bench.model_dae`` measures both). The library is
cached under a key of the expanded function, so a model is compiled once per machine.
"""
from __future__ import annotations

import logging
import os
import tempfile
import time
from pathlib import Path
from typing import Callable

import casadi as ca

from .library import cached_library, compile_c, merged, symbolic_kernels

log = logging.getLogger(__name__)

#: The code is straight-line arithmetic at -O0. -O1 makes the vehicle's 5.4 MB of code 2.6
#: times smaller and its Jacobian twice as fast with cold caches (0.8 ms), but compiles for 40 s
#: (plain) to over 2 min (after :func:`_merged`): register allocation over 200k operations.
FLAGS = ("-O0", "-fPIC", "-shared")

#: What the library's code is, beyond the graph, in its cache key (merged subexpressions).
LAYOUT = b"|cse"

#: Compilations of this process (the tests check that a second run makes none).
COMPILED = {"n": 0, "seconds": 0.0}


def compiled_dae(build: Callable[[], ca.Function]) -> ca.Function:
    """The DAE function that ``build`` returns (an MX function over the kernels), as a compiled
    external with its Jacobian companion ``jac_<name>``: same inputs, outputs and values.

    ``build`` is called once as is (its serialization is the cache key) and, if the model is
    not in the cache yet, once inside :func:`symbolic_kernels`: it must obtain every kernel
    through :func:`symcat.codegen.library.kernel_library` while it runs.

    Raises
    ------
    RuntimeError
        If the graph cannot be expanded to SX (a kernel captured as an external outside
        ``build``); the caller then keeps the MX function.
    """
    fn = build()
    name = fn.name()
    # The graph over the externals names each kernel library by its content-addressed path:
    # its serialization identifies the model without deriving anything.
    key = fn.serialize().encode() + LAYOUT
    library = cached_library(f"model_{name}", key, FLAGS)
    if not library.exists():
        t0 = time.perf_counter()
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
        with tempfile.TemporaryDirectory() as tmp:
            cwd = os.getcwd()
            os.chdir(tmp)  # CasADi writes relative to the working directory
            try:
                gen = ca.CodeGenerator(f"model_{name}.c", {"with_header": False, "verbose": False})
                gen.add(sx)
                gen.add(jac)
                gen.generate()
            finally:
                os.chdir(cwd)
            compile_c(Path(tmp) / f"model_{name}.c", f"model_{name}", FLAGS, key_source=key)
        COMPILED["n"] += 1
        COMPILED["seconds"] += time.perf_counter() - t0
    return ca.external(name, str(library))
