"""Generalized-alpha steps run in compiled C, many per call: the plain steps of a run without
events (:func:`.generalized_alpha.integrate_alpha`), recording each step's state for a run's
per-step monitor.

Why: on a small model (a cable pendulum of a hundred coordinates, a wire under a moving load)
a step's arithmetic takes tens of microseconds, and the Python around each Newton iteration
of :func:`.alpha_newton.solve_step` (residual calls, SciPy factorizations and solves,
bookkeeping) several hundred; stepped from Python, symcat was several times slower than a
compiled code. Here the same steps (unknowns, scaled residual, modified Newton iteration and
its convergence test) are one CasADi function of up to :data:`MAX_STEPS` steps, generated to
C and compiled once per model (cached on disk like the models' DAEs,
:func:`symcat.codegen.model_dae.compiled_library`):

- the residual is the wires' rows and the rest's (:mod:`.alpha_chunk_residual`), the rest on
  whole-wire windows or, when windows move, on a proxy element of each wire filled at run time
  with the element holding the point;
- the iteration matrix is the step's Jacobian (but for what a point adds to the wires' own
  block), factorized in the code as a band (the wires, ordered by reverse Cuthill-McKee) with a
  dense border (bodies, arc lengths, multipliers: :class:`.bordered_band.BorderedBand`; of
  its couplings to the wires only the columns and rows that can hold entries), kept across
  steps; when the iteration contracts slower than :data:`CONTRACTIONS` its border is renewed
  at the current iterate, then the whole matrix, as :func:`~.alpha_newton.solve_step` prepares
  the rest, then refactorizes (the thresholds are inputs of the code, not part of it);
- a run of a model whose steps were compiled before finds them from the model
  (:mod:`.alpha_chunk_cache`) and builds the Python step equations only if a step falls back;
- a step that fails even with a fresh matrix (divergence, :data:`MAX_ITERATIONS`, a
  non-finite update) ends the call; that step is then taken by
  :meth:`.alpha_integrator.Integrator.advance` (its own matrices, halving) and the compiled
  steps resume after it.

The results are the Python steps' to the Newton tolerance. Models with wheel/rail contacts
(events), windows that move without proxy elements or a border of more than :data:`MAX_BORDER`
unknowns keep the Python steps. A line's wires (more than
:data:`.alpha_chunk_wires.LOOPED_ELEMENTS` elements) are code of loops over their elements
(:mod:`.alpha_chunk_wires`), whose size does not grow with the line; its optimized library is
compiled in the background for the model's later runs, the first run stepping in Python
(:func:`_compiled`)."""
from __future__ import annotations

import hashlib
import logging
from pathlib import Path

import casadi as ca
import numpy as np

from ..codegen.band_c import store_function
from ..codegen.library import symbolic_kernels
from ..errors import CompilerError
from .alpha_bulk import step_data
from .alpha_chunk_cache import loaded, model_key, read_record, write_record
from .alpha_chunk_later import compile_later, write_c
from .alpha_chunk_residual import ChunkResidual
from .alpha_chunk_wires import looped, unloopable
from .alpha_integrator import Integrator, State
from .alpha_newton import SLOW_CONTRACTION
from .alpha_step import StepEquations, step_sizes
from .bordered_band import step_layout

log = logging.getLogger(__name__)

#: The compiled calls' lengths in steps (the code holds one call of the step per step; a call
#: takes the shortest that covers an output interval and skips the steps past it, so one
#: library serves every step size and output interval; a skipped step still copies the state).
LENGTHS = (1, 2, 4, 8, 16, 32)
MAX_STEPS = LENGTHS[-1]
#: Newton iterations of a compiled step before it counts as failed (the iteration matrix is
#: factorized afresh at most :data:`ROUNDS` - 1 times in a step).
MAX_ITERATIONS = 18
ROUNDS = 3
#: The contraction per iteration above which a round of a compiled step counts as slow and the
#: next round starts from a renewed iteration matrix (one per round; inputs of the code, not
#: part of it): for a matrix that is a band alone (wires), :data:`~.alpha_newton.SLOW_CONTRACTION`
#: as in the Python steps, whose renewal is a refactorization of the wires.
CONTRACTIONS = (SLOW_CONTRACTION,) * ROUNDS
#: The same for a matrix with a border (bodies, sliding joints, contacts), renewed first at its
#: border and then whole: a point moving along a wire slows the iteration by what a renewal at
#: the current iterate does not remove (the element under the point changes within the step,
#: its curvature terms are left out), so renewing at a contraction that low costs more
#: renewals than the iterations they save.
BORDER_CONTRACTIONS = (0.7,) * ROUNDS
#: Unknowns besides the wires' at most (the border's Schur complement is dense).
MAX_BORDER = 60

#: The optimized tier's flags (:mod:`symcat.codegen.optimized`; the DAEs use -Og): steps run
#: millions of times, where -O3's scheduling and vectorization of the wires' long straight-line
#: residual pay for its compiler time; -fno-semantic-interposition inlines CasADi's helpers
#: (``casadi_sq``, used a thousand times in a step, is else a call through the symbol table).
OPTIMIZED_FLAGS = ("-O3", "-fno-semantic-interposition", "-fPIC", "-shared")

#: The code the compiled library follows from (this module, the residual, the factorization and
#: the proxies), part of its cache key.
_SOURCE = b"".join((Path(__file__).parent / name).read_bytes()
                   for name in ("alpha_chunk.py", "alpha_chunk_residual.py", "alpha_chunk_wires.py",
                                "alpha_chunk_later.py", "bordered_band.py", "alpha_proxies.py", "../codegen/band_c.py"))


class CompiledSteps:
    """The compiled steps of one run of ``integ`` with steps of ``h`` (s), at most ``per`` per
    call (one output interval). The code is generated, or loaded from the cache, at the first
    call; :attr:`disabled` says why a model's steps stay in Python (None: they do not)."""

    def __init__(self, integ: Integrator, h: float, per: int, build: bool | str = True):
        self.integ, self.h, self.per, self.build = integ, h, min(int(per), MAX_STEPS), build
        self._fns = None  # length -> compiled function
        self._factor = None  # the iteration matrix's factor the compiled steps carry (see _prepare)
        self._renew = True  # factorize it at the next call's first step
        self._last = None  # (state, packed) of the last call (see _call)
        self._scale = None
        self._mass_scale = None  # the multipliers' tolerance scale of the compiled steps (kg)
        # The model's record (:mod:`.alpha_chunk_cache`): its library is found without the
        # Python step equations, which are then built only if a step falls back to them.
        self._key = model_key(integ.model, integ.form, _settings(integ.variant, integ.coef))
        self._record = read_record(self._key)
        self.disabled = unsupported(integ, self._record is not None)
        self._awaited = None  # a line's library that a background job is building (see _pick_up)

    def advance(self, s: State, t0: float, n: int, states: list | None = None) -> State:
        """The state ``n`` steps of :attr:`h` after ``s`` at ``t0``; with ``states`` (a list),
        the :class:`~.alpha_run.StepStates` after each step appended to it (a monitored run)."""
        integ, h = self.integ, self.h
        k = 0
        if self._awaited is not None:
            self._pick_up()
        while k < n:
            renew = self._renew
            if self.disabled is None and self._ready(s, t0 + k * h):
                done, s, iterations = self._call(s, t0 + k * h, n - k, states)
                integ.stats["steps"] += done
                integ.stats["compiled_steps"] = integ.stats.get("compiled_steps", 0) + done
                integ.stats["newton_iterations"] += iterations
                k += done
                # (no window to move: the compiled steps run on proxy elements or on windows
                # that never move, see unsupported)
                if k == n or done or not renew:
                    continue  # all done, or a failure that a call with a fresh matrix may pass
            if k < n:  # no compiled steps here, or failed on a fresh matrix: one Python step
                if self._mass_scale is not None and integ.stepper.mass_scale is None:
                    integ.stepper.mass_scale = self._mass_scale  # the compiled steps' tolerance
                s = integ.advance(s, t0 + k * h, h)
                self._renew = True
                k += 1
                if states is not None:
                    states.append(integ.step_state(s, t0 + k * h))
        integ.stats["nsteps"] = integ.stats["steps"]
        return s

    def _ready(self, s: State, t: float) -> bool:
        """Whether the compiled steps can run (building or loading them at the first call)."""
        if self._fns is not None:
            return True
        if self._record is not None and self._load_recorded():
            return True
        st = self.integ.stepper
        st.scale_multipliers(s.u)  # the scale of the multipliers' tolerance
        try:
            n_r = st.n_y - st.bulk.n_b
            if n_r > MAX_BORDER:  # (the border's Schur complement is dense straight-line code)
                self.disabled = f"{n_r} unknowns besides the wires' (at most {MAX_BORDER})"
                return False
            if looped(st.form.model) and unloopable(st.form) is not None:
                self.disabled = f"a line whose wires cannot be compiled as loops ({unloopable(st.form)})"
                return False
            self._fns, key = _compiled(st, self.integ.coef, self.build)
            # recorded even before its library exists (a background job may be building it):
            # the next runs find it without the step equations or the library key
            write_record(self._key, key, st.mass_scale)
            if self._fns is None:
                self.disabled = ("not compiled yet, and a short run or a line (see generalized_alpha's compiled and "
                                 "_compiled)")
                self._awaited = awaited_library(st, key)
                return False
        except (RuntimeError, CompilerError) as exc:  # no compiler, or a kernel without SX form
            log.warning("generalized-alpha steps could not be compiled (%s); stepping in Python", exc)
            self.disabled = str(exc)
            return False
        self._prepare(st.mass_scale)
        return True

    def _pick_up(self) -> None:
        """Load the library :attr:`_awaited` if its background job has built it: the rest of a
        line's first run steps compiled (the job takes seconds to a minute; a first run of a
        long passage would else step in Python to its end)."""
        if not self._awaited.exists():
            return
        self._fns, self._awaited = loaded(self._awaited), None
        self._prepare(self.integ.stepper.mass_scale)
        self.disabled, self._renew = None, True
        log.info("generalized-alpha: the compiled steps built in the background are loaded; the run continues on them")

    def _load_recorded(self) -> bool:
        """Load the library of the model's record (without the Python step equations); False
        if it is not cached (any more) in the tier this run wants."""
        from ..codegen.model_dae import cached_library, existing_library
        from ..codegen.optimized import optimize_mode

        key = self._record["library"].encode()
        if looped(self.integ.model) and optimize_mode() == "background":  # a line: its optimized library only
            path = cached_library("alpha_chunk", key, OPTIMIZED_FLAGS)
            path = path if path.exists() else None
        else:
            path = existing_library("alpha_chunk", key, optimized_flags=OPTIMIZED_FLAGS)
        if path is None:
            return False
        self._fns = loaded(path)
        st = self.integ.built_stepper
        self._prepare(self._record["mass_scale"] if st is None or st.mass_scale is None else st.mass_scale)
        return True

    def _prepare(self, mass_scale: float) -> None:
        """The factor's storage (its size the library's), the packed state's layout and the
        Newton tolerance's scale."""
        n_u, n_c, n_sc, n_y = step_sizes(self.integ.form, self.integ.variant)
        # the factor's memory, which the calls read and renew in place (no copies, _call)
        self._factor = np.zeros(self._fns[LENGTHS[0]].function.nnz_in(4))
        self._cuts = _packed_cuts(n_u, n_c, n_sc)[:-2]
        self._mass_scale = mass_scale
        model = self.integ.model
        border = n_y > np.count_nonzero(model.free < model.ancf.n)  # unknowns besides the wires'
        self._scale = np.r_[np.full(n_y, self.integ.tol), BORDER_CONTRACTIONS if border else CONTRACTIONS]
        self._scale[n_u : n_u + n_c] *= mass_scale

    def _call(self, s: State, t: float, n: int, states: list | None = None):
        """``(steps done, state after them, Newton iterations)`` of one compiled call of at most
        ``min(n, per)`` steps from ``s`` at ``t`` (``states``: see :meth:`advance`)."""
        per, h = self.per, self.h
        length = next(L for L in LENGTHS if L >= min(n, per))
        fn, factor = self._fns[f"recorded_{length}" if states is not None else length], self._factor
        last = self._last  # (the state the last call gave, packed): the next call's input as it is
        packed = last[1] if last is not None and last[0] is s else self._pack(s)
        if self._renew:  # the matrix afresh at the first step's predictor
            renew = self._fns["renew"]
            renew.bind(outputs={0: factor})
            renew.outputs(packed, t, h)
            self.integ.compiled_factorizations += 1
        fn.bind({4: factor})  # read and renewed in place: after the call, the factor the steps ended with
        x, its, factorizations, *records = fn.outputs(
            packed, t + h * np.arange(length), h, min(n, per), factor, float(self._renew), self._scale)
        its = its.copy()
        self.integ.compiled_factorizations += int(factorizations[0])
        done = min(int(np.argmin(its > 0)) if its.min() <= 0 else length, n, per)
        self._renew = done < min(n, per)  # a failure: renew the matrix where the next call starts
        if done:
            if states is not None:
                states.append(self._states(records[0], t, done))
            s, x = self._unpack(x)
            self._last = (s, x)
        return done, s, int(its[:done].sum())

    def _states(self, records: np.ndarray, t: float, done: int):
        """The :class:`~.alpha_run.StepStates` of the first ``done`` steps' ``records`` (a
        call's output, one column per step) of a call from ``t``."""
        n_u, n_c, n_sc, _ = step_sizes(self.integ.form, self.integ.variant)
        r = records.reshape(-1, record_size(n_u, n_c, n_sc))[:done]
        cuts = np.cumsum([0, n_u, n_u, n_u, n_c, n_sc, n_sc, n_sc])
        parts = [r[:, i:j] for i, j in zip(cuts[:-1], cuts[1:])]
        return self.integ.step_states(t + self.h * np.arange(1, done + 1), *parts)

    # --- the packed state: u v v_dot a lam sc a_prev lam_prev sc_prev h failed --------------
    def _pack(self, s: State) -> np.ndarray:
        a_prev, lam_prev, sc_prev = s.prev
        return np.concatenate([s.u, s.v, s.v_dot, s.a, s.lam, s.sc, a_prev, lam_prev, sc_prev, [s.h, 0.0]])

    def _unpack(self, x: np.ndarray) -> tuple[State, np.ndarray]:
        """``(state, x)``: the state of the packed ``x`` (views of ``x`` copied, the output array)."""
        cuts, x = self._cuts, x.copy()
        x[-1] = 0.0  # (the failed flag, set when a later step of the call failed: a state to start from)
        u, v, v_dot, a, lam, sc, a_prev, lam_prev, sc_prev = (x[i:j] for i, j in zip(cuts[:-1], cuts[1:]))
        return State(u, v, v_dot, a, lam, sc, (a_prev, lam_prev, sc_prev), float(x[cuts[-1]])), x


def _packed_cuts(n_u: int, n_c: int, n_sc: int) -> list[int]:
    """Where the packed state's parts start: ``u v v_dot a lam sc a_prev lam_prev sc_prev``,
    then ``h`` and the failed flag (one entry each)."""
    return np.cumsum([0, n_u, n_u, n_u, n_u, n_c, n_sc, n_u, n_c, n_sc, 1, 1]).tolist()


def _settings(variant: str, coef) -> tuple:
    """The run's settings that shape the compiled code (with its module's constants)."""
    return (LENGTHS, MAX_ITERATIONS, ROUNDS, SLOW_CONTRACTION, variant, coef.rho_inf)


def unsupported(integ: Integrator, recorded: bool = False) -> str | None:
    """Why ``integ``'s steps cannot run compiled, or None: wheel/rail contacts (events), or
    element windows that move without proxy elements (``recorded``: the model's steps were
    compiled before, see :mod:`.alpha_chunk_cache`)."""
    if integ.model.wheelrail:
        return "wheel/rail contacts"
    if recorded:
        return None
    if integ.model.windows_move() and integ.stepper.proxies is None:
        return ("element windows that move, without proxy elements (see symcat.integrate.alpha_proxies: "
                "the code would hold every element under a point)")
    return None


def library_key(st: StepEquations, coef) -> str:
    """The digest of the compiled steps' library key: the residual over the compiled kernels
    names the model; the rest of the code follows from this module's source and the settings."""
    key = _graph(ChunkResidual(st)).serialize().encode() + repr(_settings(st.variant, coef)).encode()
    return hashlib.sha256(key + b"|alpha_chunk|" + _SOURCE).hexdigest()


def _compiled(st: StepEquations, coef, build: bool | str) -> tuple[dict | None, str]:
    """The compiled functions of :func:`_chunk_functions` by length, from the cache or
    (``build``) generated now (None if not cached and not ``build``), and the digest of the
    library's key (which names it, for the model's record). A line (wires built as loops,
    :func:`.alpha_chunk_wires.looped`) under ``$SYMCAT_OPTIMIZE=background`` uses its
    optimized library only: without one, it is left to a background job for the next runs
    (:mod:`.alpha_chunk_later`) and this run's steps stay in Python (None) until it is built
    (:meth:`CompiledSteps._pick_up`). Under ``off`` a
    line is built (at -O0, slower than its Python steps) only when asked (``build=True``, not
    ``"long"``: a long run's own choice)."""
    from ..codegen.model_dae import compiled_library
    from ..codegen.optimized import optimize_mode

    key = library_key(st, coef)
    if looped(st.form.model) and optimize_mode() == "off" and build is not True:
        return None, key
    library = awaited_library(st, key)
    if library is not None:
        if library.exists():
            return loaded(library), key
        with symbolic_kernels():
            functions = _chunk_functions(st, coef)
        compile_later(functions, library, OPTIMIZED_FLAGS)
        return None, key

    def write(folder):
        with symbolic_kernels():
            return write_c(_chunk_functions(st, coef), folder)

    path = compiled_library("alpha_chunk", key.encode(), write, build=bool(build),  # -O0 first, optimized in the background
                            optimized_flags=OPTIMIZED_FLAGS)
    if path is None:
        return None, key
    return loaded(path), key


def awaited_library(st: StepEquations, key: str) -> Path | None:
    """The optimized library a background job builds for a line (:func:`_compiled` under
    ``$SYMCAT_OPTIMIZE=background``) whose library key digests to ``key``; None for any other
    model or mode (nothing is built while the run goes on)."""
    from ..codegen.model_dae import cached_library
    from ..codegen.optimized import optimize_mode

    if not (looped(st.form.model) and optimize_mode() == "background"):
        return None
    return cached_library("alpha_chunk", key.encode(), OPTIMIZED_FLAGS)


def _graph(residual: ChunkResidual) -> ca.Function:
    """``(y, p) -> (rows, shift)`` of ``residual``."""
    y, p = ca.MX.sym("y", residual.n_y), ca.MX.sym("p", 3 * residual.n_u + 4)
    return ca.Function("alpha_chunk_residual", [y, p], list(residual.rows_and_shift(y, p)))


def _chunk_functions(st: StepEquations, coef) -> list:
    """``alpha_chunk_<per>(x0, t (per), h, n, factor, renew, scale) -> (x, iterations (per),
    factorizations)`` for each ``per`` of :data:`LENGTHS`: up to ``n`` steps of ``h`` from the
    packed state ``x0`` at the times ``t``, with the iteration matrix's ``factor`` (``renew``:
    made at the first step's predictor, by ``alpha_chunk_renew``); ``x`` is the state after
    the last step that converged; a step's iterations are 0 (not taken: past ``n`` or after a
    failure) or -1 (failed). ``factor`` is the caller's memory, read where it is and renewed
    in place (:func:`~symcat.codegen.band_c.store_function`): after the call it holds the
    factor the steps ended with, the next call's. Then ``alpha_chunk_renew(x0, t0, h) ->
    factor``: the matrix at the predictor of the step from ``x0`` at ``t0``, which the caller
    runs, into the same memory, before a call that renews it. ``alpha_chunk_recorded_<per>``:
    the same with a fourth output, each step's record (:func:`_record_function`, one column per
    step), for a monitored run (its own functions: the records cost a copy of the state per
    step, which an unmonitored run does not pay)."""
    n_u, n_c, n_sc, n_y = st.n_u, st.n_c, st.n_sc, st.n_y
    n_x = 5 * n_u + 2 * (n_c + n_sc) + 2
    y, p = ca.MX.sym("y", n_y), ca.MX.sym("p", 3 * n_u + 4)
    # The wires' and the rest's functions expanded to scalar operations, shared subexpressions
    # merged: as MX graphs their code spends most of its time on sparse bookkeeping.
    residual = ChunkResidual(st, expand=True)
    rows, shift = residual.rows_and_shift(y, p)
    rows_of = ca.Function("alpha_chunk_rows", [y, p], [rows])
    shift_of = ca.Function("alpha_chunk_shift", [y, p], [shift]) if st.variant == "stabilized" and n_c else None
    y_b, y_r = ca.MX.sym("y_b", st.bulk.n_b), ca.MX.sym("y_r", n_y - st.bulk.n_b)
    jacobian = ca.Function("alpha_chunk_jacobian", [y_b, y_r, p], [residual.jacobian(y_b, y_r, p)])
    layout = step_layout(st, residual.couplings())
    jacobian_border = ca.Function("alpha_chunk_jacobian_border", [y_b, y_r, p],
                                  [residual.jacobian(y_b, y_r, p, wires=False)])
    jac = ca.project(jacobian(y[: st.bulk.n_b], y[st.bulk.n_b :], p), layout.pattern)
    # The factor's memory is an input the caller owns (read in place, renewed by stores into
    # it, never copied); the token of its last store orders the functions that read it after
    # that store (see band_c.store_function).
    factor, token = ca.MX.sym("factor", layout.size), ca.MX.sym("token")
    factorization = ca.Function("alpha_chunk_factorization", [y, p], [layout.factorize(_nonzeros(jac))])
    store = store_function(layout.size, 0, layout.size)
    factorize = ca.Function("alpha_chunk_factorize", [y, p, factor, token], [store(factor, factorization(y, p))])
    keep_factor = ca.Function("alpha_chunk_keep_factor", [y, p, factor, token], [token])
    refresh = ca.Function.if_else("alpha_chunk_refresh", factorize, keep_factor)
    # the border alone (bodies, joints, contacts: what moves with a point), the band's LU kept
    border = layout.n_r > 0
    if border:
        jac_border = ca.project(jacobian_border(y[: st.bulk.n_b], y[st.bulk.n_b :], p), layout.pattern)
        store_border = store_function(layout.size, layout.band_entries, layout.size - layout.band_entries)
        refactorize_border = ca.Function("alpha_chunk_border", [y, p, factor, token],
                                         [store_border(factor, layout.border(factor, _nonzeros(jac_border)))])
        refresh_border = ca.Function.if_else("alpha_chunk_refresh_border", refactorize_border, keep_factor)
    rhs = ca.MX.sym("rhs", n_y)
    solve = ca.Function("alpha_chunk_solve", [factor, rhs], [layout.solve(factor, rhs)])

    # The step's predictor: (packed state, t0, h) -> (y, p)
    xk, t0, h = ca.MX.sym("x", n_x), ca.MX.sym("t0"), ca.MX.sym("h")
    parts = ca.vertsplit(xk, _packed_cuts(n_u, n_c, n_sc))
    u, v, v_dot, a, lam, sc, a_prev, lam_prev, sc_prev, h_prev, _ = parts
    c = coef
    bh2 = c.beta * h * h
    p_k = ca.vertcat(u + h * v + h * h * (0.5 - c.beta) * a, v + h * (1 - c.gamma) * a,
                     (c.alpha_m * a - c.alpha_f * v_dot) / (1 - c.alpha_f), t0 + h, bh2, c.gamma * h,
                     (1 - c.alpha_m) / (1 - c.alpha_f))
    ratio = h / h_prev
    y_k = ca.vertcat(p_k[:n_u] + bh2 * (a + ratio * (a - a_prev)), bh2 * (lam + ratio * (lam - lam_prev)),
                     ca.MX(n_y - n_u - n_c - n_sc, 1), sc + ratio * (sc - sc_prev))
    predictor = ca.Function("alpha_chunk_predictor", [xk, t0, h], [y_k, p_k])
    # the matrix afresh at a step's predictor (run by the caller before a call that renews it)
    renew_matrix = ca.Function("alpha_chunk_renew", [xk, t0, h], [factorization(y_k, p_k)])

    # One Newton iteration: (y, previous error, status, count, fresh) -> (y, error, status,
    # count); status 0 running, 1 converged, 2 failed, 3 slow (wants a fresh matrix): the
    # tests of solve_step. fresh: the matrix was factorized in this step. scale: the Newton
    # tolerance of each unknown, then the contraction above which the iteration is slow.
    scale = ca.MX.sym("scale", n_y + 1)
    prev, status, count, fresh = ca.MX.sym("prev"), ca.MX.sym("status"), ca.MX.sym("count"), ca.MX.sym("fresh")
    dy = -solve(factor, rows_of(y, p))
    err = ca.mmax(ca.fabs(dy / scale[:n_y]))
    theta = ca.if_else(prev > 0, err / prev, 0)
    finite = err < np.inf
    converged = ca.logic_and(finite, ca.logic_or(
        ca.logic_and(ca.logic_and(err <= 1, theta < 1), theta / ca.fmax(1 - theta, 1e-300) * err <= 1), err <= 1e-3))
    slow = ca.logic_and(prev > 0, theta > scale[n_y])
    diverging = ca.logic_and(fresh > 0, theta >= 1)  # on a fresh matrix: the step fails
    failed = ca.logic_or(ca.logic_or(ca.logic_not(finite), ca.logic_and(slow, diverging)),
                         count + 1 >= MAX_ITERATIONS)
    new_status = ca.if_else(converged, 1, ca.if_else(failed, 2, ca.if_else(slow, 3, 0)))
    args = [y, prev, status, count, fresh, p, scale, factor, token]
    iterate = ca.Function("alpha_chunk_iteration", args, [y + dy, err, new_status, count + 1])
    keep = ca.Function("alpha_chunk_keep", args, [y, prev, status, count])
    newton = ca.Function.if_else("alpha_chunk_newton", keep, iterate)
    # One step: (packed state, factor, token, (renew,) t0, h, scale) -> (state, token,
    # iterations, factorizations); renew: the factor was made at this step's predictor (the
    # first step's input; the later steps' is 0). A call's arguments are never constants:
    # CasADi's call of a function on a line's sizes with a constant argument takes tens of
    # milliseconds, each of the hundreds of calls here.
    def step_function(first: bool) -> ca.Function:
        xk, t0, h = ca.MX.sym("x", n_x), ca.MX.sym("t0"), ca.MX.sym("h")
        scale = ca.MX.sym("scale", n_y + ROUNDS)  # then per round the contraction that is slow
        renew = ca.MX.sym("renew")
        parts = ca.vertsplit(xk, _packed_cuts(n_u, n_c, n_sc))
        u, v, v_dot, a, lam, sc, a_prev, lam_prev, sc_prev, h_prev, was_failed = parts
        bh2 = coef.beta * h * h
        y_k, p_k = predictor(xk, t0, h)
        active = was_failed == 0  # (a step past the call's steps is skipped, see below)
        fr = ca.logic_and(active, renew) if first else ca.MX(0)
        e, stat, cnt = ca.MX(0), ca.if_else(active, 0, 1), ca.MX(0)  # an inactive step: "converged" untouched
        tk, factorizations = token, ca.MX(0)
        for round_ in range(ROUNDS):
            round_scale = ca.vertcat(scale[:n_y], scale[n_y + round_])
            for _ in range(MAX_ITERATIONS // ROUNDS):
                y_k, e, stat, cnt = newton(stat != 0, y_k, e, stat, cnt, fr, p_k, round_scale, factor, tk)
            wanted = stat == 3
            if round_ == ROUNDS - 1:
                continue
            # slow: the border afresh at the current iterate first, then the whole matrix
            if border and round_ == 0:
                tk = refresh_border(wanted, y_k, p_k, factor, tk)
            else:
                tk = refresh(wanted, y_k, p_k, factor, tk)
                fr, factorizations = ca.logic_or(fr, wanted), factorizations + wanted
            stat, e = ca.if_else(wanted, 0, stat), ca.if_else(wanted, 0, e)
        ok = ca.logic_and(active, stat == 1)
        u_pred, v_pred, b, _, _, gh, cm = step_data(p_k, n_u)
        a_new = (y_k[:n_u] - u_pred - (shift_of(y_k, p_k) if shift_of is not None else 0)) / bh2
        stepped = ca.vertcat(y_k[:n_u], v_pred + gh * a_new, cm * a_new + b, a_new, y_k[n_u : n_u + n_c] / bh2,
                             y_k[n_y - n_sc :], a, lam, sc, h, 0)
        new_x = ca.if_else(ok, stepped, ca.vertcat(xk[:-1], ca.logic_or(was_failed, active)))
        iterations = ca.if_else(ok, cnt, ca.if_else(active, -1, 0))
        inputs = [xk, factor, token] + ([renew] if first else []) + [t0, h, scale]
        name = "alpha_chunk_step" + ("_first" if first else "")
        step = ca.Function(name, inputs, [new_x, tk, iterations, factorizations])
        skip = ca.Function(name + "_skip", inputs, [xk, token, 0, 0])
        return ca.Function.if_else(name + "_or_skip", step, skip)

    first_step, step = step_function(True), step_function(False)
    record = _record_function(residual, n_u, n_c, n_sc, n_y)
    # A loop of calls, not mapaccum: its code copies the inputs common to the steps once per
    # step, which cost more than the steps.
    functions = []
    h, n, renew, scale = ca.MX.sym("h"), ca.MX.sym("n"), ca.MX.sym("renew"), ca.MX.sym("scale", n_y + ROUNDS)
    for recorded in (False, True):
        for per in LENGTHS:
            x0, times = ca.MX.sym("x0", n_x), ca.MX.sym("t", per)
            # (the first token: any input, no store precedes the first step)
            x, tk, counts, total, records = x0, h, [], 0, []
            for k in range(per):  # a failed step leaves the state as it was: x is the last good one
                if k == 0:
                    x, tk, count, fk = first_step(k < n, x, factor, tk, renew, times[k], h, scale)
                else:
                    x, tk, count, fk = step(k < n, x, factor, tk, times[k], h, scale)
                counts.append(count)
                total += fk
                if recorded:
                    records.append(record(x, times[k] + h))
            outputs = [x, ca.vertcat(*counts), total] + ([ca.horzcat(*records)] if recorded else [])
            name = f"alpha_chunk_{'recorded_' if recorded else ''}{per}"
            functions.append(ca.Function(name, [x0, times, h, n, factor, renew, scale], outputs))
    return functions + [renew_matrix]


def _record_function(residual: ChunkResidual, n_u: int, n_c: int, n_sc: int, n_y: int) -> ca.Function:
    """``alpha_chunk_record(x, t) -> [u, v, v_dot, lam, sc, gap, force]``: what a monitored
    run records of the packed state ``x`` at time ``t`` (:meth:`CompiledSteps.advance`), the
    penalty contacts' gaps and forces as :meth:`.alpha_step.StepEquations.contacts` has them
    (the rest at ``y = [u, 0, sc]``, step data whose velocity is ``v``)."""
    x, t = ca.MX.sym("x", 5 * n_u + 2 * (n_c + n_sc) + 2), ca.MX.sym("t")
    u, v, v_dot, _, lam, sc = ca.vertsplit(x, _packed_cuts(n_u, n_c, n_sc))[:6]
    contacts = []
    if n_sc:
        # (dense: the proxies pick their elements from them by parametric indices)
        y = ca.vertcat(u, ca.MX.zeros(n_y - n_u - n_sc, 1), sc)
        p = ca.vertcat(u, v, ca.MX.zeros(n_u, 1), t, 1, 1, 1)
        contacts = [ca.densify(c) for c in residual.contacts(y, p)]
    return ca.Function("alpha_chunk_record", [x, t], [ca.densify(ca.vertcat(u, v, v_dot, lam, sc, *contacts))])


def record_size(n_u: int, n_c: int, n_sc: int) -> int:
    """Numbers a compiled step records per step (:func:`_record_function`)."""
    return 3 * n_u + n_c + 3 * n_sc


def _nonzeros(m: ca.MX) -> ca.MX:
    """The nonzeros of ``m`` as a column (in its CCS order)."""
    return ca.sparsity_cast(m, ca.Sparsity.dense(m.nnz(), 1))
