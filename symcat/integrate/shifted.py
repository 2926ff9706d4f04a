"""The DAE of the contact driver's integrators: the state's scaled departure from its linear
extrapolation over a call, consistent at zero for every start (see :mod:`.contact_stepping`)."""
from __future__ import annotations

import casadi as ca


def shifted_dae(dae_fn: ca.Function, normalized: bool = False) -> ca.Function:
    """The DAE ``(t, x, z, p, u) -> (ode, alg, quad, zero)`` in the state's scaled departure from
    its linear extrapolation: ``x = x_a + t x_dot_a + D xi``, ``xi_dot = (ode - x_dot_a) / D``,
    with ``p`` extended by ``x_a``, ``x_dot_a`` and ``D``. ``xi = 0`` with ``xi_dot = 0`` is a
    consistent start when ``x_dot_a`` is the DAE's own ``ode`` there (see the module docstring).
    ``normalized``: in the time ``tau = t / h``, with ``p`` extended further by ``h`` (s), so
    that one integrator on ``tau`` in ``[0, 1]`` serves calls of every length."""
    n_x, n_z, n_p = dae_fn.size1_in(1), dae_fn.size1_in(2), dae_fn.size1_in(3)
    tau, xi, z = ca.MX.sym("t"), ca.MX.sym("xi", n_x), ca.MX.sym("z", n_z)
    p_ext, u = ca.MX.sym("p", n_p + 3 * n_x + int(normalized)), ca.MX.sym("u", dae_fn.size1_in(4))
    p, x_a = p_ext[:n_p], p_ext[n_p : n_p + n_x]
    x_dot_a, scale = p_ext[n_p + n_x : n_p + 2 * n_x], p_ext[n_p + 2 * n_x : n_p + 3 * n_x]
    h = p_ext[-1] if normalized else None
    t = tau if h is None else h * tau
    ode, alg, quad, zero = dae_fn(t, x_a + t * x_dot_a + scale * xi, z, p, u)
    xi_dot = (ode - x_dot_a) / scale
    if h is not None:
        xi_dot, quad = h * xi_dot, h * quad
    return ca.Function(f"{dae_fn.name()}_shifted", [tau, xi, z, p_ext, u], [xi_dot, alg, quad, zero],
                       dae_fn.name_in(), dae_fn.name_out())
