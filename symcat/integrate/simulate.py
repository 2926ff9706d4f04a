"""Integrate a multibody model with CasADi's IDAS.

The run is split into chunks of output points (progress, window moves of sliding joints);
each chunk continues from the previous state. Models with events between integrator calls
(wheel/rail contact jumps, lift-off and touchdown) run shorter calls with the events checked
between them: :mod:`.event_stepping`, the events decided by plug-in handlers
(:class:`.events.EventHandler`, ``handlers=``). This layer knows no wheel/rail contact: a model
with wheel/rail contacts and no handlers is refused, naming the function that attaches its
default handlers (:func:`symcat.simulation.simulate`), rather than run without contact jumps.
Accelerations and multipliers are algebraic and kept out of the error test
(``suppress_algebraic``): on stiff ANCF models this cuts the step count by two orders of
magnitude. A failure raises :class:`SolverError` with the time, IDAS's reason, the largest
residual by name and the result up to the last completed chunk.

The tuning is one :class:`.settings.IdasSettings`; the old keywords (``rtol=``, ``n_out=``,
...) still build it.
"""
from __future__ import annotations

import contextlib
import io
import logging
import time

import casadi as ca
import numpy as np

from ..assembly.multibody import MultibodyModel
from ..codegen.model_dae import compiled_dae
from ..dae.formulation import Formulation
from ..dae.initial import consistent_state
from ..errors import ParameterError, SolverError
from ..progress import Progress
from ..run_control import check_interrupt, ended_early, integrating
from .alpha_chunk_cache import one_run
from .event_stepping import CallFailed, EventStepper
from .events import EventHandler
from .failure import failure, split_state
from .results import SimulationResult, collect_result
from .settings import VELOCITY_ATOL_FACTOR, IdasSettings, settings_from

log = logging.getLogger(__name__)

#: Simulated time (s) one event stepper span covers (many output intervals if they are short).
CONTACT_GROUP_S = 0.1

STAT_KEYS = ("nsteps", "nfevals", "nlinsetups", "netfails", "nniters", "nncfails")

__all__ = ["CONTACT_GROUP_S", "STAT_KEYS", "VELOCITY_ATOL_FACTOR", "IdasSettings", "simulate", "update_windows"]


@one_run
def simulate(model: MultibodyModel, t_end: float, formulation: str = "augmented", index: str = "1",
             settings: IdasSettings | None = None, *, handlers=None, **legacy) -> SimulationResult:
    """Simulate ``model`` from 0 to ``t_end`` seconds.

    Parameters
    ----------
    model : MultibodyModel
    t_end : float
        Simulated time (s), > 0.
    formulation, index : str
        ``augmented``/``embedded`` and ``1``/``ggl`` (see :mod:`symcat.dae.formulation`).
    settings : IdasSettings, optional
        Tolerances, solver and output (default :class:`~.settings.IdasSettings`).
    handlers : sequence of EventHandler, optional
        Events between integrator calls (:mod:`.events`; one handler for now): the run then
        goes in short calls with the events checked between them (:mod:`.event_stepping`).
        Required for a model with wheel/rail contacts (:func:`symcat.simulation.simulate`
        attaches them).
    **legacy
        The fields of :class:`~.settings.IdasSettings` as keywords (``rtol=1e-8``, ...),
        replacing those of ``settings``.

    Raises
    ------
    ParameterError
        A bad time, setting or keyword (naming it), or a model with wheel/rail contacts and no
        handlers.
    SolverError
        IDAS failed; ``partial`` holds the result up to the last completed chunk.
    """
    settings = settings_from(settings, **legacy)
    if not t_end > 0:
        raise ParameterError(f"t_end={t_end}: must be > 0 s")
    handler = one_handler(model, handlers)
    rtol, n_out, chunks, max_step = settings.rtol, settings.n_out, settings.chunks, settings.max_step
    wall0 = time.perf_counter()
    form = Formulation(model, formulation, index, settings.baumgarte, settings.cholesky)
    abstol_x = _atol_vector(form, settings.atol, settings.velocity_atol)  # checked before any work
    compiled, linear_solver = settings.compiled, settings.linear_solver
    if compiled is None:
        # The embedded form's linear solve (an MX node) does not expand to SX.
        compiled = bool(model.wheelrail) and not model.windowed() and formulation == "augmented"
    if linear_solver is None:
        linear_solver = "csparse" if form.index == "1" else "qr"
    stats = dict.fromkeys(STAT_KEYS, 0)
    stats["restarts"] = 0
    if handler is not None:
        handler.attach(form, stats)
    x, z = consistent_state(form, 0.0, open_rows=handler.open_rows() if handler is not None else [])
    t_grid = np.linspace(0.0, t_end, n_out + 1)
    fixed_edges = None
    if chunks:
        fixed_edges = np.unique(np.linspace(0, n_out, int(chunks) + 1).astype(int))
    # Algebraic variables (accelerations, multipliers) are out of the error test, but their
    # absolute tolerance still weighs IDAS's Newton convergence test: with the differential
    # atol, GGL's mu (identically ~0) can never "converge" and IDAS reports IDA_CONV_FAIL.
    n_z = len(z)
    opts = {"reltol": rtol, "abstolv": abstol_x + [settings.algebraic_atol] * n_z, "suppress_algebraic": True,
            "calc_ic": False, "max_num_steps": int(settings.max_steps), "linear_solver": linear_solver}
    if max_step:
        opts["max_step_size"] = max_step
    xs, zs = [x], [z]
    walls = [time.perf_counter() - wall0]  # when each output was known (s)
    # The handler's mode (wheel/rail: contacts lifted off) at each output, and its events.
    modes = [handler.mode().copy() if handler is not None else np.zeros(0)]
    events = handler.events if handler is not None else []
    bar = Progress("simulate", t_end, "s", enabled=settings.progress)
    dae_fn = None
    done = 0

    def call(x, z, t_a, times):
        """One IDAS call from ``t_a`` with outputs at ``times``: (x, z) columns per output."""
        # IDAS needs a consistent x_dot at every (re)start; it would otherwise assume zero.
        x_dot = np.asarray(dae_fn(0.0, x, z, t_a, ca.DM(0, 1))[0]).ravel()
        grid = (np.atleast_1d(times) - t_a).tolist()
        integ = ca.integrator("idas", "idas", dae_fn, 0.0, grid, {**opts, "init_xdot": x_dot.tolist()})
        # IDAS prints its errors (through CasADi, to sys.stderr): kept for the failure report,
        # which is the one line the user reads.
        with contextlib.redirect_stderr(io.StringIO()) as said:
            try:
                out = integ(x0=x, z0=z, p=t_a)
            except RuntimeError as err:
                idas = said.getvalue().strip().splitlines()[-1:]
                if not idas:
                    raise
                raise RuntimeError(f"{str(err).strip().splitlines()[-1]} (IDAS: {idas[0]} [t from the call's "
                                   f"start at {t_a:.6g} s])") from None
        st = integ.stats()
        for k in STAT_KEYS:
            stats[k] += int(st.get(k, 0))
        return np.asarray(out["xf"]), np.asarray(out["zf"])

    def dae_function():
        if compiled:
            try:
                return compiled_dae(form.dae_function)
            except RuntimeError as exc:  # a kernel outside the SX build: keep the graph
                log.warning("the model's DAE could not be compiled (%s); evaluating its graph", exc)
        return form.dae_function()

    try:
        with integrating():
            if handler is not None:
                # Short calls with the handler's events checked between them (see event_stepping).
                dae_fn = dae_function()
                stepper = EventStepper(form, dae_fn, opts, x, z, stats, STAT_KEYS, handler)
                # Output intervals grouped into spans of about CONTACT_GROUP_S (one per interval
                # where element windows can move, moved between intervals): the stepper's calls cross output
                # times, so dense output costs neither event checks nor IDAS restarts.
                group = 1 if model.windows_move() else max(1, int(CONTACT_GROUP_S / (t_grid[1] - t_grid[0]) + 1e-9))

                def emit(j, x_j, z_j):
                    nonlocal done
                    xs.append(x_j)
                    walls.append(time.perf_counter() - wall0)
                    zs.append(z_j)
                    modes.append(handler.mode().copy())
                    done = a + j + 1
                    bar.update(t_grid[done])

                a = 0
                while a < n_out:
                    if update_windows(model, form, x, z):
                        stats["restarts"] += 1
                        stepper.set_dae(dae_function())
                    b = min(n_out, a + group)
                    try:
                        x, z = stepper.advance(x, z, t_grid[a], t_grid[a + 1 : b + 1], emit)
                    except CallFailed as exc:
                        raise failure(form, exc.error, exc.t, exc.x, exc.z, stepper.dae_fn, t_grid[1] - t_grid[0],
                                      handler.mode()) from None
                    a = b
                    check_interrupt(t_grid[a], t_end)
            a, limit = (n_out if handler is not None else 0), None
            while a < n_out:
                b = _chunk_end(model, form, x, z, a, n_out, t_grid, fixed_edges)
                if limit is not None:
                    b = min(b, a + limit)
                if update_windows(model, form, x, z) or dae_fn is None:
                    stats["restarts"] += dae_fn is not None
                    dae_fn = dae_function()
                try:
                    xf, zf = call(x, z, t_grid[a], t_grid[a + 1 : b + 1])
                except RuntimeError as exc:
                    if b - a > 1 and model.windowed():
                        # Possibly a sliding point left its window: retry shorter before giving up.
                        stats["retries"] = stats.get("retries", 0) + 1
                        limit = max(1, (b - a) // 2)
                        continue
                    if settings.linear_solver is None and opts["linear_solver"] == "qr":
                        # GGL's default QR has failed to start at tight tolerances (h -> 1e-18 on a
                        # driven carrier at rtol 1e-9) where LU integrates: once, the rest of the run.
                        opts["linear_solver"] = "csparse"
                        stats["linear_solver_fallbacks"] = stats.get("linear_solver_fallbacks", 0) + 1
                        continue
                    raise failure(form, exc, t_grid[a], x, z, dae_fn, t_grid[a + 1] - t_grid[a]) from None
                if b - a > 1 and any(_left_window(model, form, xf[:, j], zf[:, j]) for j in range(b - a)):
                    # A sliding point ran out of its window inside the call (the physics there would
                    # be an extrapolated element): redo the call, shorter, from the same state.
                    stats["retries"] = stats.get("retries", 0) + 1
                    limit = max(1, (b - a) // 2)
                    continue
                limit = None
                for j in range(b - a):
                    xs.append(xf[:, j])
                    walls.append(time.perf_counter() - wall0)
                    zs.append(zf[:, j])
                x, z = xf[:, -1], zf[:, -1]
                done = b
                bar.update(t_grid[b])
                a = b
                check_interrupt(t_grid[b], t_end)
    except SolverError as err:
        bar.close()
        err.partial = collect_result(form, t_grid[: done + 1], xs, zs, stats, wall0, modes, events, walls)
        if ended_early(err, t_grid[done], t_end):
            return err.partial
        raise
    bar.close()
    return collect_result(form, t_grid, xs, zs, stats, wall0, modes, events, walls)


def one_handler(model, handlers) -> EventHandler | None:
    """The run's event handler, checked: one or none, and one for a model with wheel/rail
    contacts (whose DAE takes their open flags as parameters)."""
    handlers = list(handlers or [])
    for h in handlers:
        if not isinstance(h, EventHandler):
            raise ParameterError(f"handlers: {h!r} is not an EventHandler (symcat.integrate.events)")
    if len(handlers) > 1:
        raise ParameterError(f"handlers: {len(handlers)} given; one event handler per run for now")
    if model.wheelrail and not handlers:
        names = ", ".join(e.joint.name for e in model.wheelrail)
        raise ParameterError(f"the model has wheel/rail contacts ({names}), which need their contact-event handlers: "
                             "use symcat.simulation.simulate (or integrate_model), which attaches them")
    return handlers[0] if handlers else None


def _atol_vector(form, atol, velocity_atol=None) -> list:
    """Absolute tolerances of the differential states from scalars or per-coordinate arrays
    (``velocity_atol`` for the velocities, default ``atol``)."""
    xb, _ = form.blocks()
    n_x = sum(b.size for b in xb.values())
    q_atol = _free_atol(form, "atol", atol)
    out = np.full(n_x, float(np.min(atol)))  # the other differential states (surface parameters, ...)
    out[xb["q"].slice] = q_atol
    out[xb["v"].slice] = q_atol if velocity_atol is None else _free_atol(form, "velocity_atol", velocity_atol)
    return out.tolist()


def _free_atol(form, name: str, value) -> np.ndarray:
    """Tolerance ``value`` (a number or one per generalized coordinate) on the free coordinates."""
    per = np.atleast_1d(np.asarray(value, dtype=float))
    if per.size not in (1, form.model.n_q):
        raise ParameterError(f"{name}: give a number or {form.model.n_q} values (one per coordinate), not {per.size}")
    if not np.all(np.isfinite(per) & (per > 0)):
        raise ParameterError(f"{name}={value!r}: must be > 0 (m, rad; m/s, rad/s for the velocities)")
    if per.size == 1:
        return np.full(form.n_f, float(per[0]))
    return per[form.model.free] if not form.cholesky else np.full(form.n_f, per.min())


def _chunk_end(model, form, x, z, a, n_out, t_grid, fixed_edges) -> int:
    """End (output index) of the next integrator call: about 10 % of the run for progress, and
    short enough that no sliding point travels more than a quarter of its window (the window
    is only moved between calls). Each call builds an integrator and restarts IDAS at order 1,
    so fewer calls are faster."""
    if fixed_edges is not None:
        return int(fixed_edges[np.searchsorted(fixed_edges, a, side="right")])
    dt = t_grid[1] - t_grid[0]
    span = max(1, int(round(0.1 * n_out)))
    if model.windowed():
        s_dot = np.abs(_s_dot(form, x, z))
        for sl, v in zip(model.windowed(), s_dot):
            lo, hi = sl.window
            if lo == 0 and hi == len(sl.element_start) - 1:
                continue  # the window is the whole wire
            reach = 0.25 * (sl.element_start[hi] - sl.element_start[lo])
            if v > 0:
                span = min(span, max(1, int(reach / (v * dt))))
    return min(n_out, a + span)


def _left_window(model, form, x, z) -> bool:
    """True if a sliding point lies outside its window (wire ends excepted)."""
    if not model.windowed():
        return False
    s = _window_s(form, x, z)
    for sl, s_k in zip(model.windowed(), s):
        lo, hi = sl.window
        n_el = len(sl.element_start) - 1
        if (lo > 0 and s_k < sl.element_start[lo]) or (hi < n_el and s_k > sl.element_start[hi]):
            return True
    return False


def _s_dot(form, x, z) -> np.ndarray:
    """Rates of the windowed arc lengths (sliding joints, then contacts)."""
    parts = split_state(form, x, z)
    # Algebraic arc lengths (embedded form, contacts): the largest velocity bounds s_dot well enough here.
    bound = np.abs(parts["v"]).max(initial=0.0)
    n = form.model.n_sliding  # wheel/rail surface parameters have no window
    sliding = parts["w"][:n] if "w" in parts else np.full(n, bound)
    return np.r_[sliding, np.full(form.n_sc, bound)]


def _window_s(form, x, z) -> np.ndarray:
    """Arc lengths of the sliding joints, then of the contacts."""
    parts = split_state(form, x, z)
    return np.r_[parts["s"][: form.model.n_sliding], parts.get("sc", np.zeros(0))]


def update_windows(model, form, x, z) -> bool:
    """Move the element windows of the sliding points that near their edges; True if one moved
    (the DAE is then rebuilt)."""
    if not model.windowed():
        return False
    s = _window_s(form, x, z)
    if model.window_margin(s) >= 2:
        return False
    moved = False
    for sl, s_k in zip(model.windowed(), s):
        moved |= model.set_window(sl, s_k)
    return moved
