"""Proxy elements of a generalized-alpha step (:mod:`.alpha_step`): the rest of the step is
built once on a stand-in element of each wire, whatever element its contact is on."""
from __future__ import annotations

import bisect

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

    def restrict(self, y_columns: np.ndarray, p_columns: np.ndarray) -> None:
        """The rest takes ``y[y_columns]`` and ``p[p_columns]`` only: where each proxy's places
        are in them (-1: not an input)."""
        n_u = self.n_u
        y_at = np.full(int(max(y_columns.max(initial=0), 0)) + 1, -1)
        y_at[y_columns] = np.arange(y_columns.size)
        p_at = np.full(int(max(p_columns.max(initial=0), 0)) + 1, -1)
        p_at[p_columns] = np.arange(p_columns.size)

        def at(table, index):
            inside = (index >= 0) & (index < table.size)
            return np.where(inside, table[np.clip(index, 0, table.size - 1)], -1)

        self._columns = (y_columns, p_columns)
        self._elements: dict[int, dict] = {}
        self._starts = [np.asarray(sl.element_start, float).tolist() for (sl, *_) in self.items]
        self._places = [(at(y_at, index[j]), [at(p_at, index[j] + block * n_u) for block in range(3)])
                        for (_, j, index, _, _) in self.items]

    def substitute(self, y, p):
        """The rest's inputs ``y[y_columns]`` and ``p[p_columns]`` (:meth:`restrict`) with each
        proxy's places holding its actual element's values, the elements' start and length
        ``w``, and the maps ``(proxy, actual)`` of y indices."""
        y_columns, p_columns = self._columns
        y_rest, p_rest = y[y_columns], p[p_columns]
        w = np.empty(2 * len(self.items))
        maps = []
        for i, (*_, where) in enumerate(self.items):
            starts = self._starts[i]
            k = min(max(bisect.bisect_right(starts, float(y[where])) - 1, 0), len(starts) - 2)
            proxy, actual, (y_to, y_from, y_fixed, y_values), (p_to, p_from, p_fixed, p_values) = self._element(i, k)
            y_rest[y_to] = y[y_from]
            y_rest[y_fixed] = y_values
            p_rest[p_to] = p[p_from]
            p_rest[p_fixed] = p_values
            w[2 * i] = starts[k]
            w[2 * i + 1] = starts[k + 1] - starts[k]
            maps.append((proxy, actual))
        return y_rest, p_rest, w, maps

    def _element(self, i: int, k: int):
        """Where the values of element ``k`` go in item ``i``'s proxy places of the rest's
        inputs: ``(proxy, actual, y_parts, p_parts)``, each part ``(to, from, fixed_to,
        fixed_values)`` (a fixed coordinate enters with its value and zero rates). Cached: a
        contact stays on an element for many evaluations."""
        cache = self._elements.setdefault(i, {})
        found = cache.get(k)
        if found is None:
            n_u = self.n_u
            _, j, index, fixed, _ = self.items[i]
            y_at, p_at = self._places[i]
            proxy, actual = index[j], index[k]
            free = actual >= 0

            def parts(places, offset, values):
                on, off = (places >= 0) & free, (places >= 0) & ~free
                return places[on], actual[on] + offset, places[off], values[off]

            y_parts = parts(y_at, 0, fixed[k])
            p_blocks = [parts(places, block * n_u, fixed[k] if block == 0 else np.zeros(fixed[k].shape))
                        for block, places in enumerate(p_at)]
            p_parts = tuple(np.concatenate([b[m] for b in p_blocks]) for m in range(4))
            found = cache[k] = (proxy, actual, y_parts, p_parts)
        return found


def move_back(vector: np.ndarray, maps) -> None:
    """Add the proxies' entries of ``vector`` to their actual elements' (in place)."""
    values = [vector[proxy].copy() for proxy, _ in maps]
    for proxy, _ in maps:
        vector[proxy] = 0.0
    for (_, actual), v in zip(maps, values):
        keep = actual >= 0
        np.add.at(vector, actual[keep], v[keep])
