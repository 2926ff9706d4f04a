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
    columns are moved back to the actual element's (dropping fixed coordinates): index maps
    built once per placement (:meth:`placement`, :mod:`.alpha_placement`).

    The actual element may also be a wire's straight continuation past one of its ends
    (:func:`~symcat.assembly.windows.extension_rows`), whose coordinates are linear
    combinations of the end node's: each proxy coordinate is a weighted sum of actual ones
    (:class:`ElementMap`), and results move back by its transpose."""

    def __init__(self, step, items, elements):
        form = step.form
        model = form.model
        y_of_q = np.full(model.n_q, -1)
        y_of_q[model.free] = np.arange(form.n_f)
        q_fixed = np.array(form.q_fixed).ravel()
        n_sliding = len(model.sliding)
        self.n_u = step.n_u
        self._model = model
        self._y_of_q, self._q_fixed = y_of_q, q_fixed
        self.items = []
        for i, (sl, j) in enumerate(zip(items, elements)):
            where = form.n_f + i if i < n_sliding else step.n_y - step.n_sc + (i - n_sliding)
            self.items.append((sl, j, y_of_q[sl.element_indices], q_fixed[sl.element_indices], where))

    @classmethod
    def choose(cls, step, y, p):
        """``(proxies, probe)`` for ``step``'s model, or ``(None, None)`` when its windows never
        move or no element qualifies (the windows are then rebuilt as the points move).
        ``probe``: the step's rows on the chosen proxies, their symbols ``w`` and the rows'
        Jacobian pattern in ``y``, ``(w, rows, pattern)``, which the step builds on (the graph
        of a line's rows takes tens of milliseconds to build)."""
        model = step.form.model
        items = model.windowed()
        if not items or not model.windows_move():
            return None, None
        y_of_q = np.full(model.n_q, -1)
        y_of_q[model.free] = np.arange(step.form.n_f)

        def candidates(offset):
            picked, used = [], set()
            for sl in items:
                n_el = len(sl.element_start) - 1
                ok = next((j for j in range(1 + offset, n_el - 1) if np.all(y_of_q[sl.element_indices[j]] >= 0)
                           and not used & set(sl.element_indices[max(j - 1, 0) : j + 2].ravel().tolist())), None)
                if ok is None:
                    return None
                picked.append(ok)
                used |= set(sl.element_indices[ok].tolist())
            return picked

        first, second = candidates(0), candidates(3)
        if first is None or second is None:
            return None, None
        # Bulk columns of the rest that belong to no proxy: other rest terms on the wires.
        others, probes = set(), []
        for elements in (first, second):
            proxy = cls(step, items, elements)
            w = ca.MX.sym("w", 2 * len(items))
            saved = [sl.window for sl in items]
            try:
                proxy.install(w)
                mode = step.mode_symbol
                rows = step._rows(y, p, mode, contacts=True)
                pattern = ca.Function("probe", [y, p, w, mode], [rows[0]]).sparsity_jac(0, 0)
                probes.append((w, rows, pattern))
            finally:
                model.element_override.clear()
                for sl, window in zip(items, saved):
                    sl.window = window
            cols = set(np.array(pattern.get_col(), int).tolist())
            mine = set(y_of_q[np.concatenate([sl.element_indices[j] for sl, j in zip(items, elements)])].tolist())
            others |= {c for c in cols - mine if c < step.bulk.n_b}
        proxy = cls(step, items, first)
        if others & set(y_of_q[np.concatenate([sl.element_indices[j] for sl, j in zip(items, first)])].tolist()):
            return None, None
        return proxy, probes[0]

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
        # y index -> (item, position in its proxy element) of the proxies' coordinates
        top = max(int(index[j].max()) for (_, j, index, _, _) in self.items) + 1
        self._owner, self._local = np.full(top, -1), np.zeros(top, int)
        for i, (_, j, index, _, _) in enumerate(self.items):
            self._owner[index[j]], self._local[index[j]] = i, np.arange(index[j].size)
        self._starts = [np.asarray(sl.element_start, float).tolist() for (sl, *_) in self.items]
        self._places = [(at(y_at, index[j]), [at(p_at, index[j] + block * n_u) for block in range(3)])
                        for (_, j, index, _, _) in self.items]

    def expand(self, maps, index: np.ndarray):
        """Entries at y indices ``index`` re-expressed on the actual elements of ``maps`` (one
        :class:`ElementMap` per item): ``(position in
        index, y index, weight)`` per term; an index of no proxy stays (weight 1). All maps at
        once: an actual element may be another item's proxy element."""
        inside = index < self._owner.size
        at = np.where(inside, index, 0)
        item = np.where(inside, self._owner[at], -1)
        local = self._local[at]
        positions, actuals, weights = [np.flatnonzero(item < 0)], [], []
        actuals.append(index[positions[0]])
        weights.append(np.ones(positions[0].size))
        for i, m in enumerate(maps):
            mine = np.flatnonzero(item == i)
            if mine.size:
                at_term, actual, weight = m.terms(local[mine])
                positions.append(mine[at_term]), actuals.append(actual), weights.append(weight)
        return np.concatenate(positions), np.concatenate(actuals), np.concatenate(weights)

    def key(self, y) -> tuple:
        """The element of each item's wire that holds its point in ``y`` (-1 and ``n_el``: the
        straight continuations past the wire's start and end)."""
        key = []
        for i, (*_, where) in enumerate(self.items):
            starts = self._starts[i]
            k = bisect.bisect_right(starts, float(y[where])) - 1
            key.append(min(max(k, -1), len(starts) - 1))
        return tuple(key)

    def placement(self, key: tuple) -> tuple:
        """The rest's inputs with each proxy's places holding the actual elements' of ``key``
        (:meth:`key`): ``(y terms, p terms, w, expand)`` for :class:`~.alpha_placement.Placement`,
        ``w`` the elements' starts and lengths and ``expand`` the output map (:meth:`expand`
        on these elements)."""
        from .alpha_placement import Terms

        y_columns, p_columns = self._columns
        maps = [self._element(i, k) for i, k in enumerate(key)]
        terms = []
        for block, columns in enumerate((y_columns, p_columns)):
            replaced = np.zeros(columns.size, bool)
            constant = np.zeros(columns.size)
            place, source, weight = [np.arange(columns.size)], [columns], [np.ones(columns.size)]
            for m in maps:
                for to_set, values, to_add, sources, weights in (m.fills[:1] if block == 0 else m.fills[1:]):
                    replaced[to_set] = True
                    constant[to_set] = values
                    place.append(to_add), source.append(sources), weight.append(weights)
            place[0], source[0], weight[0] = place[0][~replaced], source[0][~replaced], weight[0][~replaced]
            terms.append(Terms(np.concatenate(place), np.concatenate(source), np.concatenate(weight), constant))
        w = np.array([[m.start, m.length] for m in maps]).ravel()
        return terms[0], terms[1], w, lambda index: self.expand(maps, index)

    def _element(self, i: int, k: int) -> "ElementMap":
        """The :class:`ElementMap` of element ``k`` of item ``i``'s wire (-1 and ``n_el``: the
        straight continuations past its start and end). Cached: a contact stays on an element
        for many evaluations."""
        cache = self._elements.setdefault(i, {})
        found = cache.get(k)
        if found is None:
            sl, j, index, _, _ = self.items[i]
            rows, sources, weights, constant, start, length = element_terms(sl, k, self._y_of_q, self._q_fixed)
            # (to set, their values, to add to, sources, weights) for y and the three blocks of p
            fills = []
            y_at, p_at = self._places[i]
            for block, places in enumerate([y_at, *p_at]):
                on, add = places >= 0, places[rows] >= 0
                offset = 0 if block == 0 else (block - 1) * self.n_u
                fills.append((places[on], constant[on] if block <= 1 else np.zeros(int(on.sum())), places[rows[add]],
                              sources[add] + offset, weights[add]))
            found = cache[k] = ElementMap(index[j], rows, sources, weights, fills, float(start), float(length))
        return found


def element_terms(sl, k: int, y_of_q: np.ndarray, q_fixed: np.ndarray):
    """Element ``k`` of the wire of the sliding joint or contact ``sl`` (-1 and ``n_el``: its
    straight continuations past its start and end) as terms on the free coordinates: local
    coordinate ``rows[t]`` gets ``weights[t] * y[sources[t]]``, plus ``constant`` (the fixed
    coordinates' share); with the element's ``start`` and ``length`` (m)."""
    from ..assembly.windows import extension_length, extension_rows

    n_el, n_loc = len(sl.element_start) - 1, sl.element_indices.shape[1]
    starts = sl.element_start
    if 0 <= k < n_el:
        rows, cols, weights = np.arange(n_loc), sl.element_indices[k], np.ones(n_loc)
        start, length = starts[k], starts[k + 1] - starts[k]
    else:
        end = k == n_el
        edge = n_el - 1 if end else 0
        length = extension_length(starts)
        rows, cols, weights = extension_rows(sl.element_indices[edge], sl.wire.element.dim, end, length)
        start = starts[n_el] if end else starts[0] - length
    sources = y_of_q[cols]
    free = sources >= 0
    constant = np.zeros(n_loc)
    np.add.at(constant, rows[~free], weights[~free] * q_fixed[cols[~free]])
    return rows[free], sources[free], weights[free], constant, float(start), float(length)


class ElementMap:
    """How a proxy element's coordinates are made of the actual element's (y indices):
    proxy coordinate ``rows[t]`` gets ``weights[t] * y[sources[t]]`` summed over the terms ``t``,
    plus the fixed coordinates' values; ``proxy`` are the proxy's own y indices, ``fills`` the
    writes into the rest's inputs (y, then the three blocks of p), ``start``/``length`` the
    actual element's (m). For a real element the map is a one-to-one copy; for a wire's straight continuation the
    far node's position also takes the end gradient times the element length."""

    def __init__(self, proxy, rows, sources, weights, fills, start, length):
        self.proxy, self.fills, self.start, self.length = proxy, fills, start, length
        # per proxy coordinate, its terms (sorted): for expanding Jacobian entries
        order = np.argsort(rows, kind="stable")
        self.rows, self.sources, self.weights = rows[order], sources[order], weights[order]
        self._count = np.bincount(self.rows, minlength=proxy.size)
        self._first = np.cumsum(self._count) - self._count

    def terms(self, local: np.ndarray):
        """The terms of proxy coordinates ``local`` (positions in :attr:`proxy`): ``(position in
        local, actual y index, weight)`` per term (a coordinate with only fixed terms has none)."""
        counts = self._count[local]
        position = np.repeat(np.arange(local.size), counts)
        within = np.arange(position.size) - np.repeat(np.cumsum(counts) - counts, counts)
        term = self._first[local[position]] + within
        return position, self.sources[term], self.weights[term]
