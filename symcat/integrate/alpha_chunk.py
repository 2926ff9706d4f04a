"""Generalized-alpha steps run in compiled C, many per call: the plain steps of a run without
events (:func:`.generalized_alpha.integrate_alpha`), recording each step's state for a run's
per-step monitor.

Why: on a small model (a cable pendulum of a hundred coordinates, a wire under a moving load)
a step's arithmetic takes tens of microseconds, and the Python around each Newton iteration
of :func:`.alpha_newton.solve_step` (residual calls, SciPy factorizations and solves,
bookkeeping) several hundred; stepped from Python, symcat was several times slower than a
compiled code. Here the same steps (unknowns, scaled residual, modified Newton iteration and
its convergence test) are one CasADi function of up to
:data:`~.alpha_chunk_code.MAX_STEPS` steps (:mod:`.alpha_chunk_code`), generated to C and
compiled once per model (cached on disk like the models' DAEs,
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
- a step that fails even with a fresh matrix (divergence,
  :data:`~.alpha_chunk_code.MAX_ITERATIONS`, a
  non-finite update) ends the call; that step is then taken by
  :meth:`.alpha_integrator.Integrator.advance` (its own matrices, halving) and the compiled
  steps resume after it.

The results are the Python steps' to the Newton tolerance. Models with wheel/rail contacts
(events), windows that move without proxy elements or a border of more than :data:`MAX_BORDER`
unknowns keep the Python steps. A line's wires (more than
:data:`.alpha_chunk_wires.LOOPED_ELEMENTS` elements) are code of loops over their elements
(:mod:`.alpha_chunk_wires`), whose size does not grow with the line; its optimized library is
compiled in the background for the model's later runs, the first run stepping in Python
until it is built (:func:`_compiled`)."""
from __future__ import annotations

import hashlib
import logging
from pathlib import Path

import casadi as ca
import numpy as np

from ..codegen.library import symbolic_kernels
from ..errors import CompilerError
from .alpha_chunk_cache import loaded, model_key, read_record, write_record
from .alpha_chunk_later import compile_later, write_c
from .alpha_chunk_residual import ChunkResidual
from .alpha_chunk_wires import looped, unloopable
from .alpha_integrator import Integrator, State
from .alpha_newton import SLOW_CONTRACTION
from .alpha_chunk_code import LENGTHS, MAX_ITERATIONS, MAX_STEPS, ROUNDS, chunk_functions, packed_cuts, record_size
from .alpha_step import StepEquations, step_sizes

log = logging.getLogger(__name__)

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

#: The code the compiled library follows from (the steps' code, the residual, the factorization
#: and the proxies; not this module, the runtime, whose edits leave the code as it was), part of
#: its cache key.
_SOURCE = b"".join((Path(__file__).parent / name).read_bytes()
                   for name in ("alpha_chunk_residual.py", "alpha_chunk_wires.py",
                                "alpha_chunk_later.py", "alpha_chunk_code.py", "bordered_band.py", "alpha_proxies.py",
                                "../codegen/band_c.py", "../codegen/sparse_c.py"))


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
        # the factor's memory, which the calls read and renew in place (no copies, _call); its
        # size from the function that renews it, which every run loads (a function's loading
        # allocates its work, tens of megabytes on a line)
        self._factor = np.zeros(self._fns["renew"].function.nnz_out(0))
        self._cuts = packed_cuts(n_u, n_c, n_sc)[:-2]
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
    """The compiled functions of :func:`.alpha_chunk_code.chunk_functions` by length, from the cache or
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
            functions = chunk_functions(st, coef)
        compile_later(functions, library, OPTIMIZED_FLAGS)
        return None, key

    def write(folder):
        with symbolic_kernels():
            return write_c(chunk_functions(st, coef), folder)

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
