"""Failure reports of the IDAS driver (the time, IDAS's reason, the worst residual by name and
nearly dependent constraint rows) and the state's blocks by name, which they and the event
handlers read."""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..errors import SolverError


def split_state(form, x, z) -> dict:
    """The state ``(x, z)`` by block name (:meth:`symcat.dae.Formulation.blocks`: ``q``, ``v``,
    ``s``, ``lambda``, ...)."""
    xb, zb = form.blocks()
    out = {k: np.asarray(x)[b.slice] for k, b in xb.items()}
    out.update({k: np.asarray(z)[b.slice] for k, b in zb.items() if k not in out})
    return out


def physical_coordinates(form, parts) -> tuple[np.ndarray, np.ndarray]:
    """All generalized coordinates and velocities of the model (fixed ones at their initial
    values) from :func:`split_state`'s ``parts``."""
    model = form.model
    q, v = model.q0.copy(), np.zeros(model.n_q)
    q[model.free] = form.to_physical(parts["q"])
    v[model.free] = form.to_physical(parts["v"])
    return q, v


def restart_point(form, parts: dict, s=None) -> dict:
    """``start`` for :func:`symcat.dae.initial.consistent_state` from a split state (``s``
    replaces the surface parameters, e.g. after a contact jump)."""
    return {"q": parts["q"], "v": parts["v"], "s": parts["s"] if s is None else s,
            "w": parts.get("w", np.zeros(form.n_s)), "sc": parts.get("sc", np.zeros(form.n_sc))}


def failure(form, exc, t, x, z, dae_fn, dt, open_flags=()) -> SolverError:
    """Explain an IDAS failure: time, IDAS's reason, the largest algebraic residual (by name) of
    the last accepted state pushed one output step ahead along its derivative, and constraint
    rows that have become nearly dependent. ``open_flags``: the wheel/rail contacts lifted off."""
    reason = str(exc).strip().splitlines()[-1] if str(exc).strip() else repr(exc)
    nil = ca.DM(0, 1)
    p = np.r_[t, open_flags]
    x_dot = np.asarray(dae_fn(0.0, x, z, p, nil)[0]).ravel()
    res = np.abs(np.asarray(dae_fn(dt, x + dt * x_dot, z, p, nil)[1]).ravel())
    names = form.residual_names()
    worst = names[int(np.argmax(res))] if res.size else "none"
    message = (f"IDAS failed in the step after t = {t:.6g} s: {reason}. Largest algebraic residual one "
               f"output step ahead: {worst} ({res.max(initial=0):.3g}).")
    message += _dependent_rows(form, x, z, t)
    message += (" Try a smaller rtol or max_step, the other formulation or index, or look for a joint or "
                "force that becomes singular")
    return SolverError(message)


def _dependent_rows(form, x, z, t) -> str:
    model = form.model
    if not 0 < model.n_c <= 2000:
        return ""
    parts = split_state(form, x, z)
    n_s = form.n_s
    qs, vs, ss, ws = ca.MX.sym("q", form.n_f), ca.MX.sym("v", form.n_f), ca.MX.sym("s", n_s), ca.MX.sym("w", n_s)
    k = form.terms(qs, vs, ss, ws, ca.MX(t), ca.MX.sym("sc", form.n_sc))
    jac = ca.Function("j", [qs, vs, ss, ws], [ca.horzcat(k["Cq"], k["Cs"])])
    j = np.asarray(ca.densify(jac(parts["q"], parts["v"], parts["s"], parts.get("w", np.zeros(n_s)))))
    u, sv, _ = np.linalg.svd(j, full_matrices=False)
    if sv.size == 0 or sv[-1] > 1e-6 * sv[0]:
        return ""
    weights = np.abs(u[:, -1])
    rows = [model.row_names[r] for r in np.argsort(weights)[::-1][:3] if weights[r] > 0.1]
    return f" The constraints are nearly dependent (a locked or singular mechanism?): {', '.join(rows)}."
