"""The event stepping driver's integrators (see :mod:`.event_stepping`): the DAE in the state's scaled
departure from its linear extrapolation over a call, consistent at zero for every start, and the
cache of integrators built on it."""
from __future__ import annotations

import casadi as ca


def shifted_dae(dae_fn: ca.Function, normalized: bool = False) -> ca.Function:
    """The DAE ``(t, x, z, p, u) -> (ode, alg, quad, zero)`` in the state's scaled departure from
    its linear extrapolation: ``x = x_a + t x_dot_a + D xi``, ``xi_dot = (ode - x_dot_a) / D``,
    with ``p`` extended by ``x_a``, ``x_dot_a`` and ``D``. ``xi = 0`` with ``xi_dot = 0`` is a
    consistent start when ``x_dot_a`` is the DAE's own ``ode`` there (see the module docstring).
    ``normalized``: in a time ``tau`` in ``[0, 1]`` over the call, with ``p`` extended further
    by the call's length ``h`` (s) and a warp ``a`` (in ``(-1, 1)``): ``t = h w(tau)``,
    ``w(tau) = tau + a tau (1 - tau)``, so that one integrator serves calls of every length
    (``a = 0``: ``tau = t / h``) and, warped, with one output inside at any fraction near its
    grid point (:func:`warped_grid`)."""
    n_x, n_z, n_p = dae_fn.size1_in(1), dae_fn.size1_in(2), dae_fn.size1_in(3)
    tau, xi, z = ca.MX.sym("t"), ca.MX.sym("xi", n_x), ca.MX.sym("z", n_z)
    p_ext, u = ca.MX.sym("p", n_p + 3 * n_x + 2 * int(normalized)), ca.MX.sym("u", dae_fn.size1_in(4))
    p, x_a = p_ext[:n_p], p_ext[n_p : n_p + n_x]
    x_dot_a, scale = p_ext[n_p + n_x : n_p + 2 * n_x], p_ext[n_p + 2 * n_x : n_p + 3 * n_x]
    t, t_rate = tau, None
    if normalized:
        h, warp = p_ext[-2], p_ext[-1]
        t, t_rate = h * (tau + warp * tau * (1 - tau)), h * (1 + warp * (1 - 2 * tau))
    ode, alg, quad, zero = dae_fn(t, x_a + t * x_dot_a + scale * xi, z, p, u)
    xi_dot = (ode - x_dot_a) / scale
    if t_rate is not None:
        xi_dot, quad = t_rate * xi_dot, t_rate * quad
    return ca.Function(f"{dae_fn.name()}_shifted", [tau, xi, z, p_ext, u], [xi_dot, alg, quad, zero],
                       dae_fn.name_in(), dae_fn.name_out())


#: Grid points (fractions of a call) of the warped integrators (:func:`warped_grid`).
WARP_ANCHORS = (1 / 16, 1 / 8, 1 / 4, 1 / 2, 3 / 4, 7 / 8, 15 / 16)
#: Largest warp: the time runs between ``1 - a`` and ``1 + a`` times as fast as in a plain call.
WARP_MAX = 0.75


def warped_grid(fraction: float) -> tuple[list[float], float]:
    """``(grid, a)``: the normalized grid and warp (:func:`shifted_dae`) of a call with one output
    inside, at ``fraction`` of its length: the grid point of :data:`WARP_ANCHORS` that needs the
    least warp (``w(g) = fraction``), else the fraction itself, unwarped. An integrator is built
    per grid (about 2 ms for the seed vehicle with :class:`SharedDerivatives`, 10 to 15 ms when
    CasADi derived the DAE's Jacobian anew for each): calls that end at predicted contact jumps put their outputs at
    any fraction, and one output in a call is the common case (S1002 vehicle, rtol 1e-6: 62 -> 44
    integrators built in the first simulated second)."""
    warps = [((fraction - g) / (g * (1 - g)), g) for g in WARP_ANCHORS]
    a, g = min(warps, key=lambda w: abs(w[0]))
    return ([g, 1.0], a) if abs(a) <= WARP_MAX else ([fraction, 1.0], 0.0)


def call_grid(grid, h: float, normalized: bool, warpable: bool) -> tuple[list[float], float]:
    """``(grid, a)`` of the integrator of a call of length ``h`` (s) with outputs at ``grid``
    (s after its start, the last its end): in seconds, or ``normalized`` by ``h``, warped
    (:func:`warped_grid`) if there is one output inside and ``warpable`` (no step limit in
    seconds, which a warped time would stretch)."""
    if not normalized:
        return list(grid), 0.0
    if len(grid) == 2 and warpable:
        return warped_grid(grid[0] / h)
    return [v / h for v in grid], 0.0


class SharedDerivatives(ca.Callback):
    """``fn`` as an integrator's DAE whose derived functions are built once for every
    integrator: CasADi builds an IDAS integrator's residual and Jacobian functions (``daeF``,
    ``jacF``) through the DAE's ``factory``, deriving the Jacobian of its graph anew for each
    integrator (6 of the 9 ms of a build for the seed vehicle), which this DAE answers from
    its cache (a build then takes about 2 ms). The integrators evaluate only what the factory
    returned; :meth:`eval` (through Python) serves any other caller.

    Parameters
    ----------
    fn : casadi.Function
        The DAE ``(t, x, z, p, u) -> (ode, alg, quad, zero)``.
    """

    def __init__(self, fn: ca.Function):
        ca.Callback.__init__(self)
        self.fn = fn
        self.derived = {}  # (name, inputs, outputs, aux, options) -> Function
        self.construct(f"{fn.name()}_shared", {})

    def get_n_in(self):
        return self.fn.n_in()

    def get_n_out(self):
        return self.fn.n_out()

    def get_sparsity_in(self, i):
        return self.fn.sparsity_in(i)

    def get_sparsity_out(self, i):
        return self.fn.sparsity_out(i)

    def get_name_in(self, i):
        return self.fn.name_in(i)

    def get_name_out(self, i):
        return self.fn.name_out(i)

    def eval(self, arg):
        return self.fn.call(arg)

    def get_factory(self, name, s_in, s_out, aux, opts):
        key = (name, tuple(s_in), tuple(s_out), repr(aux), repr(opts))
        derived = self.derived.get(key)
        if derived is None:
            derived = self.derived[key] = self.fn.factory(name, s_in, s_out, aux, opts)
        return derived


#: IDAS's first step relative to the call without a suggested one (first call, failure, index 1).
INITIAL_STEP = 1e-3
#: Integrators kept (one per call grid and linear solver; a long run meets many grids).
MAX_INTEGRATORS = 64


class CallIntegrators:
    """IDAS integrators of one DAE for the event stepping driver's calls, built on first use over one
    :class:`SharedDerivatives` per DAE variant (about 2 ms each for the compiled seed vehicle,
    mostly the linear solver's set-up; 9 ms when each derived the DAE's Jacobian anew) and kept,
    the oldest dropped beyond :data:`MAX_INTEGRATORS`.

    Parameters
    ----------
    dae_fn : casadi.Function
        The driver's DAE ``(t, x, z, p, u) -> (ode, alg, quad, zero)``.
    opts : dict
        IDAS options (``max_step_size``, if any, in seconds).
    """

    def __init__(self, dae_fn: ca.Function, opts: dict):
        self.dae_fn, self.opts = dae_fn, opts
        self._shifted = {}  # normalized -> shifted DAE (SharedDerivatives)
        self._plain = None  # the DAE itself (SharedDerivatives), for IDACalcIC
        self._built = {}

    def get(self, grid, solver: str, shifted: bool, normalized: bool = False, level: int | None = None,
            time_unit: float = 1.0):
        """The integrator of the shifted DAE (or, not ``shifted``, of the DAE itself with
        IDACalcIC) on ``grid`` with ``solver``; ``normalized``: the shifted DAE in time
        normalized by the call's length ``time_unit`` (s; ``grid`` in ``(0, 1]``); IDAS's first
        step is ``2^-level`` of the call, :data:`INITIAL_STEP` if None."""
        max_step = self.opts.get("max_step_size")
        if max_step is not None and normalized:
            max_step = float(f"{max_step / time_unit:.12e}")  # in units of the call
        key = (solver, shifted, normalized, level, max_step) + tuple(float(f"{v:.12e}") for v in grid)  # last bits differ
        integ = self._built.get(key)
        if integ is None:
            if shifted:
                if normalized not in self._shifted:
                    self._shifted[normalized] = SharedDerivatives(shifted_dae(self.dae_fn, normalized))
                # IDAS's first step would be a thousandth of the first output time (xi_dot = 0
                # gives it no other scale): the call's length instead, so that the steps do not
                # depend on the outputs inside the call.
                step0 = (INITIAL_STEP if level is None else 2.0**-level) * grid[-1]
                dae, opts = self._shifted[normalized], {**self.opts, "calc_ic": False, "step0": step0}
                if max_step is not None:
                    opts["max_step_size"] = max_step
            else:
                if self._plain is None:
                    self._plain = SharedDerivatives(self.dae_fn)
                dae, opts = self._plain, self.opts
            if len(self._built) >= MAX_INTEGRATORS:
                del self._built[next(iter(self._built))]  # the oldest
            integ = self._built[key] = ca.integrator("idas", "idas", dae, 0.0, grid, {**opts, "linear_solver": solver})
        return integ
