"""The terms of a formulation at each output of a run, for its result
(:mod:`.results`): one function of ``(q, v, s, w, t, sc)`` mapped over the outputs, kept for
the next model of the same digest, and compiled for runs whose steps are compiled."""
from __future__ import annotations

import logging

import casadi as ca
import numpy as np

from ..codegen.library import BufferedFunction
from ..dae.formulation import Formulation

log = logging.getLogger(__name__)


class Mapped:
    """A CasADi function of column vectors evaluated for many inputs in one call
    (``Function.map``, built once per batch size): inputs and outputs with one row per
    evaluation."""

    def __init__(self, fn: ca.Function):
        self.fn, self._maps = fn, {}
        self._sizes = [fn.sparsity_out(i).numel() for i in range(fn.n_out())]
        if any(fn.sparsity_out(i).size2() != 1 and size for i, size in enumerate(self._sizes)):
            raise ValueError(f"{fn.name()}: the outputs must be column vectors to be mapped row-wise")
        # The mapped outputs' nonzeros are each evaluation's in turn: per output, the rows
        # its nonzeros fill.
        self._rows = [np.array(fn.sparsity_out(i).row(), int) for i in range(fn.n_out())]

    def __call__(self, *rows) -> list[np.ndarray]:
        n = rows[0].shape[0]
        if n not in self._maps:
            self._maps[n] = BufferedFunction(self.fn.map(n))
        # The mapped inputs are (size, n), column-major: the rows' own row-major order.
        out = self._maps[n].nonzeros(*(np.asarray(r, float).reshape(n, -1).ravel() for r in rows))
        dense = []
        for nz, size, where in zip(out, self._sizes, self._rows):
            d = np.zeros((n, size))
            d[:, where] = nz.reshape(n, where.size)
            dense.append(d)
        return dense


def mapped_terms(form: Formulation, light: bool, contacts: bool, compiled: bool = False
                  ) -> tuple[ca.Function, dict, Mapped]:
    """:func:`_terms_function` and its :class:`Mapped` evaluations, kept for the next model of
    the same digest and windows (:func:`~.alpha_chunk_cache.model_memo`): a run's model is built
    anew, and building the function and its map over the outputs cost about as much as the
    compiled steps of a coarse run on a small model. ``compiled``: evaluated by compiled C
    (:func:`_compiled_terms`) when it can be, but not on wires of many elements
    (:func:`.alpha_chunk_wires.looped`), whose expanded terms are straight-line code over every
    element (minutes of compiler time and gigabytes of its memory on a line)."""
    from .alpha_chunk_cache import model_memo
    from .alpha_chunk_wires import looped

    compiled = compiled and not looped(form.model)

    def build():
        fn, patterns = _terms_function(form, light, contacts)
        return fn, patterns, Mapped((_compiled_terms(form, light, contacts, fn) if compiled else None) or fn)

    windows = tuple(sl.window for sl in form.model.windowed())
    return model_memo(form.model, form, ("post terms", light, contacts, windows, compiled), build)


def _compiled_terms(form: Formulation, light: bool, contacts: bool, fn: ca.Function) -> ca.Function | None:
    """``fn`` (:func:`_terms_function`) as compiled C, expanded over the kernels' expressions
    (cached on disk under its graph, :func:`~symcat.codegen.model_dae.compiled_library`), or
    None if it cannot be expanded or compiled.

    Why: CasADi's virtual machine spends about 40 us per output on its work vectors, whatever
    the terms (8 ms for the 201 outputs of a 60-element wire, as much as the compiled steps
    of 15 generalized-alpha steps); compiled, the outputs cost about a tenth of that. Compiling
    takes seconds once per model: runs whose steps are compiled ask for it."""
    from ..codegen.library import merged, symbolic_kernels, write_functions_c
    from ..codegen.model_dae import compiled_library
    from ..errors import CompilerError

    def write(folder):
        with symbolic_kernels():
            sx = _terms_function(form, light, contacts)[0].expand()
        ins = sx.sx_in()
        return write_functions_c([merged(ca.Function("post_terms", ins, sx.call(ins)))], "post_terms", folder)

    try:
        path = compiled_library("post_terms", fn.serialize().encode() + b"|post_terms", write)
    except (RuntimeError, CompilerError) as exc:  # a kernel without SX form, or no compiler
        log.info("post-processing terms stay in CasADi's virtual machine (%s)", exc)
        return None
    return ca.external("post_terms", str(path)) if path is not None else None


def _terms_function(form: Formulation, light: bool = False, contacts: bool = True) -> tuple[ca.Function, dict]:
    """One output's terms as a function of ``(q, v, s, w, t, sc)``: ``C``, its rate ``C_dot``,
    ``s_dot``, the nonzeros of ``Cq``, ``Cs`` and ``M``, ``Q``, ``Qd``, contact ``gap`` and ``fc``,
    ``kinetic`` and ``potential`` energy; and the patterns of the sparse matrices. ``light``:
    without ``M``, ``Q`` and ``Qd`` (the KKT system's, not solved when the integrator's
    multipliers are given). ``contacts=False`` (light only): without the penalty contacts'
    terms, whose values the integrator gave."""
    if not (light or contacts):
        raise ValueError("_terms_function: contacts=False needs light=True (the KKT forces include the contacts)")
    model = form.model
    n_f, n_s = form.n_f, form.n_s
    qs, vs = ca.MX.sym("q", n_f), ca.MX.sym("v", n_f)
    ss, ws, ts = ca.MX.sym("s", n_s), ca.MX.sym("w", n_s), ca.MX.sym("t")
    scs = ca.MX.sym("sc", form.n_sc)
    if form.formulation == "embedded" and n_s:
        s_dot = form.embedded_terms(qs, vs, ss, ts, scs)["s_dot"]
    else:
        s_dot = ws
    kk = form.terms(qs, vs, ss, s_dot, ts, scs, contacts=contacts)
    qf = form.q_fixed + ca.mtimes(form.P, qs)
    vf = ca.mtimes(form.P, vs)
    sparse = {"Cq": kk["Cq"], "Cs": kk["Cs"]} if light else {"Cq": kk["Cq"], "Cs": kk["Cs"], "M": kk["M"]}
    kkt = {} if light else {"Q": kk["Q"], "Qd": kk["Qd"]}
    outs = {"C": kk["C"], "C_dot": ca.mtimes(kk["Cq"], vs) + ca.mtimes(kk["Cs"], s_dot) + kk["Ct"], "s_dot": s_dot,
            **{name: ca.vec(x.nz[:]) for name, x in sparse.items()}, **kkt, "gap": kk["gap"],
            "fc": kk["fc"], "kinetic": model.kinetic_energy(qf, vf), "potential": model.potential_energy(qf)}
    fn = ca.Function("post", [qs, vs, ss, ws, ts, scs], list(outs.values()),
                     ["q", "v", "s", "w", "t", "sc"], list(outs))
    return fn, {name: x.sparsity() for name, x in sparse.items()}
