"""Proxy elements of a generalized-alpha step (:mod:`.alpha_step`): the rest of the step is
built once on a stand-in element of each wire, whatever element its contact is on."""
from __future__ import annotations

import casadi as ca
import numpy as np


class Proxies:
    """Stand-in elements for the element windows of sliding joints and penalty contacts.

    A window of many elements makes the rest's Jacobian structurally dense over all of them
    (the element is chosen by masks of ``s``) and must be rebuilt whenever the point nears its
    edge: on a line, several times per simulated second at a fraction of a second each. Instead
    the rest is built once with a one-element window on a *proxy* element of each wire
    (interior, all coordinates free, touched by nothing else of the rest, proxies two elements
    apart) whose start and length are inputs; each evaluation writes the actual element's
    coordinates and step data into the proxy's places, and the results at the proxy's rows and
    columns are moved back to the actual element's (dropping fixed coordinates)."""

    def __init__(self, step, items, elements):
        form = step.form
        model = form.model
        y_of_q = np.full(model.n_q, -1)
        y_of_q[model.free] = np.arange(form.n_f)
        q_fixed = np.array(form.q_fixed).ravel()
        n_sliding = len(model.sliding)
        self.n_u = step.n_u
        self._model = model
        self.items = []
        for i, (sl, j) in enumerate(zip(items, elements)):
            where = form.n_f + i if i < n_sliding else step.n_y - step.n_sc + (i - n_sliding)
            self.items.append((sl, j, y_of_q[sl.element_indices], q_fixed[sl.element_indices], where))

    @classmethod
    def choose(cls, step, y, p):
        """Proxies for ``step``'s model, or None when its windows never move or no element
        qualifies (the windows are then rebuilt as the points move)."""
        model = step.form.model
        items = model.windowed()
        if not items or not model.windows_move():
            return None
        y_of_q = np.full(model.n_q, -1)
        y_of_q[model.free] = np.arange(step.form.n_f)

        def candidates(offset):
            picked, used = [], set()
            for sl in items:
                n_el = len(sl.element_start) - 1
                ok = [j for j in range(1 + offset, n_el - 1) if np.all(y_of_q[sl.element_indices[j]] >= 0)
                      and not used & set(sl.element_indices[max(j - 1, 0) : j + 2].ravel().tolist())]
                if not ok:
                    return None
                picked.append(ok[0])
                used |= set(sl.element_indices[ok[0]].tolist())
            return picked

        first, second = candidates(0), candidates(3)
        if first is None or second is None:
            return None
        # Bulk columns of the rest that belong to no proxy: other rest terms on the wires.
        others = set()
        for elements in (first, second):
            proxy = cls(step, items, elements)
            w = ca.MX.sym("w", 2 * len(items))
            saved = [sl.window for sl in items]
            try:
                proxy.install(w)
                mode = step.mode_symbol
                pattern = ca.Function("probe", [y, p, w, mode], [step._rows(y, p, mode)[0]]).sparsity_jac(0, 0)
            finally:
                model.element_override.clear()
                for sl, window in zip(items, saved):
                    sl.window = window
            cols = set(np.array(pattern.get_col(), int).tolist())
            mine = set(y_of_q[np.concatenate([sl.element_indices[j] for sl, j in zip(items, elements)])].tolist())
            others |= {c for c in cols - mine if c < step.bulk.n_b}
        proxy = cls(step, items, first)
        if others & set(y_of_q[np.concatenate([sl.element_indices[j] for sl, j in zip(items, first)])].tolist()):
            return None
        return proxy

    def install(self, w) -> None:
        """One-element windows on the proxies, their start and length the symbols ``w``."""
        for i, (sl, j, *_) in enumerate(self.items):
            sl.window = (j, j + 1)
            self._model.element_override[id(sl)] = (w[2 * i], w[2 * i + 1])

    def substitute(self, y, p):
        """``(y, p)`` with each proxy's places holding its actual element's values, the
        elements' start and length ``w``, and the maps ``(proxy, actual)`` of y indices."""
        n_u = self.n_u
        y2, p2 = y.copy(), p.copy()
        w = np.empty(2 * len(self.items))
        maps = []
        for i, (sl, j, index, fixed, where) in enumerate(self.items):
            n_el = len(sl.element_start) - 1
            k = int(np.clip(np.searchsorted(sl.element_start, y[where], side="right") - 1, 0, n_el - 1))
            proxy, actual = index[j], index[k]
            free = actual >= 0
            at = np.where(free, actual, 0)
            y2[proxy] = np.where(free, y[at], fixed[k])
            p2[proxy] = np.where(free, p[at], fixed[k])
            p2[n_u + proxy] = np.where(free, p[n_u + at], 0.0)
            p2[2 * n_u + proxy] = np.where(free, p[2 * n_u + at], 0.0)
            w[2 * i] = sl.element_start[k]
            w[2 * i + 1] = sl.element_start[k + 1] - sl.element_start[k]
            maps.append((proxy, actual))
        return y2, p2, w, maps


def move_back(vector: np.ndarray, maps) -> None:
    """Add the proxies' entries of ``vector`` to their actual elements' (in place)."""
    values = [vector[proxy].copy() for proxy, _ in maps]
    for proxy, _ in maps:
        vector[proxy] = 0.0
    for (_, actual), v in zip(maps, values):
        keep = actual >= 0
        np.add.at(vector, actual[keep], v[keep])
