"""The rest of a generalized-alpha step (:mod:`.alpha_step`: bodies, joints, contacts,
multipliers) as the functions the Newton iteration evaluates: expanded to scalar operations in
CasADi, or compiled to C and cached."""
from __future__ import annotations

import logging

import casadi as ca

from ..errors import CompilerError

log = logging.getLogger(__name__)


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


def compiled_rest(rest: ca.Function, build: bool | None = True) -> tuple[ca.Function, ca.Function]:
    """The rest's function and its Jacobian compiled to C, cached under a key of the graph
    (:func:`symcat.codegen.model_dae.compiled_library`: once per machine and model, -O0 at
    once and optimized in the background). A vehicle's rest (hundreds of unknowns, the wheel/rail
    contacts' geometry and creep) is most of the step's work: optimized, its Jacobian evaluates
    about 20 times faster than expanded in CasADi's virtual machine, and a cached library also
    spares differentiating it at the start of every run. ``build=None``: a library already
    cached, else the expanded functions (a short run: compiling the seed scene's step takes
    about 30 s, which its first thousand steps would not repay)."""
    from ..codegen.library import merged, write_functions_c
    from ..codegen.model_dae import compiled_library

    def write(folder):
        sx, jac = expanded_rest(rest)
        return write_functions_c([merged(sx), merged(jac)], "alpha_rest", folder)

    try:
        path = compiled_library("alpha_rest", rest.serialize().encode() + b"|alpha_rest|cse", write,
                                build=build is not None)
    except (RuntimeError, CompilerError) as exc:  # no SX form, or no compiler: evaluated in CasADi
        log.warning("the generalized-alpha step could not be compiled (%s); evaluating it in CasADi", exc)
        return expanded_rest(rest)
    if path is None:
        return expanded_rest(rest)
    return ca.external("alpha_rest", str(path)), ca.external("alpha_rest_jacobian", str(path))
