"""The moving element windows of sliding joints and penalty contacts: the elements of a wire
whose coordinates a point's kernels see (:meth:`ElementWindows._selection`
selects the one containing the point among them). A window over a whole line would make the
contact's Jacobian block dense over every element; it is kept a few elements wide and moved
with the point between integrator calls or steps."""
from __future__ import annotations

import casadi as ca
import numpy as np
import scipy.sparse as sps


class ElementWindows:
    """The window bookkeeping of :class:`~.multibody.MultibodyModel` (a mixin: it uses the
    model's ``sliding``, ``contacts``, ``s0``, ``sc0``, ``n_sliding``, ``window_size``, ``n_q`` and
    ``element_override``)."""

    def set_window(self, sl, s: float) -> bool:
        """Centre the window of a sliding joint on ``s``; returns True if it moved."""
        n_el = len(sl.element_start) - 1
        size = min(self.window_size, n_el)
        k = int(np.clip(np.searchsorted(sl.element_start, s, side="right") - 1, 0, n_el - 1))
        first = int(np.clip(k - size // 2, 0, n_el - size))
        new = (first, first + size)
        moved = new != sl.window
        sl.window = new
        return moved

    def center_windows(self) -> bool:
        """Centre every element window on its point's initial arc length (``s0``, ``sc0``, as
        a static solution leaves them): an integration must start with its points inside their
        windows, wherever an earlier run left them. True if one moved."""
        moved = False
        for sl, s in zip(self.windowed(), np.r_[self.s0[: self.n_sliding], self.sc0]):
            moved |= self.set_window(sl, float(s))
        return moved

    def windowed(self) -> list:
        """Sliding joints, then contacts: everything that has an element window."""
        return self.sliding + self.contacts

    def windows_move(self) -> bool:
        """Whether any element window can move: some sliding or contact point's wire has more
        elements than :attr:`window_size` (else every window is its whole wire)."""
        return any(len(sl.element_start) - 1 > self.window_size for sl in self.windowed())

    def window_margin(self, s: np.ndarray) -> float:
        """Smallest distance, in elements, from any sliding or contact point (``s`` in the order
        of :meth:`windowed`) to the edge of its window (a wire end counts as no edge)."""
        margin = np.inf
        for sl, s_k in zip(self.windowed(), s):
            lo, hi = sl.window
            n_el = len(sl.element_start) - 1
            length = sl.element_start[1] - sl.element_start[0]
            if lo > 0:
                margin = min(margin, (s_k - sl.element_start[lo]) / length)
            if hi < n_el:
                margin = min(margin, (sl.element_start[hi] - s_k) / length)
        return margin

    def _selection(self, sl, s: ca.MX):
        """Sparse ``Sel(s)`` with ``e = Sel q`` the coordinates of the element containing ``s``
        (within the window), and that element's start and length. The masks are piecewise
        constant in ``s`` (zero derivative), so one sparse product carries the chain rule.

        Past a wire's free end (``s`` below 0 or above its length, the window at that end) the
        point is on the wire's straight continuation along its end tangent
        (:func:`extension_rows`): a contact can then follow a pan-head that has left a wire
        (the wire of the next tension section, raised towards its anchor), with the closest
        point defined everywhere, instead of a cubic extrapolated far beyond its element."""
        lo, hi = sl.window
        lower, upper, weight_of, pattern, starts, lengths = self._structure(
            ("selection", id(sl), lo, hi), lambda: self._selection_layout(sl))
        masks = ca.logic_and(s >= lower, s < upper)
        n_el = len(sl.element_start) - 1
        if lo == 0:
            masks = ca.vertcat(masks, s < sl.element_start[0])
        if hi == n_el:
            masks = ca.vertcat(masks, s >= sl.element_start[n_el])
        values = ca.mtimes(weight_of, masks)
        sel = ca.sparsity_cast(values, pattern)
        start = ca.dot(masks, starts)
        length = ca.dot(masks, lengths)
        override = self.element_override.get(id(sl))
        if override is not None:  # a stand-in element: the actual one's start and length given
            start, length = override
        return sel, start, length

    def _selection_layout(self, sl):
        """The constants of :meth:`_selection` for ``sl``'s window: the elements' bounds (one
        comparison per bound for the whole window; its first and last elements reach to its
        edges unless a wire end is there), the weights that turn the masks into ``Sel``'s
        nonzeros, ``Sel``'s pattern, and the elements' starts and lengths (the wire's straight
        continuations last)."""
        lo, hi = sl.window
        n_el = len(sl.element_start) - 1
        n_loc = sl.element_indices.shape[1]
        before, after = lo == 0, hi == n_el
        lower = np.array(sl.element_start[lo:hi], float)
        upper = np.array(sl.element_start[lo + 1 : hi + 1], float)
        if not before:
            lower[0] = -np.inf
        if not after:
            upper[-1] = np.inf
        # triplets: (local row, global column, weight) per window element
        triplets = [(np.arange(n_loc), sl.element_indices[k], np.ones(n_loc)) for k in range(lo, hi)]
        starts = list(sl.element_start[lo:hi])
        lengths = list(np.diff(sl.element_start)[lo:hi])
        dim = sl.wire.element.dim
        reach = extension_length(sl.element_start)
        if before:
            triplets.append(extension_rows(sl.element_indices[0], dim, at_end=False, length=reach))
            starts.append(sl.element_start[0] - reach)
            lengths.append(reach)
        if after:
            triplets.append(extension_rows(sl.element_indices[n_el - 1], dim, at_end=True, length=reach))
            starts.append(sl.element_start[n_el])
            lengths.append(reach)
        rows = np.concatenate([t[0] for t in triplets])
        cols = np.concatenate([t[1] for t in triplets])
        weights = np.concatenate([t[2] for t in triplets])
        owner = np.concatenate([np.full(t[0].size, e) for e, t in enumerate(triplets)])
        # Sel = sum over window elements of mask_e * Sel_e: a (row, column) shared by two of them
        # (a common node; the end node of a wire and its continuation) sums their entries.
        keys, inverse = np.unique(cols * n_loc + rows, return_inverse=True)  # CSC order: by column, then row
        weight_of = sps.csr_matrix((weights, (inverse, owner)), shape=(keys.size, len(triplets)))
        pattern = ca.Sparsity.triplet(n_loc, self.n_q, (keys % n_loc).tolist(), (keys // n_loc).tolist())
        return ca.DM(lower), ca.DM(upper), ca.DM(weight_of), pattern, ca.DM(starts), ca.DM(lengths)


def extension_length(element_start: np.ndarray) -> float:
    """Length (m) of the element that stands for a wire's straight continuation: twice the
    wire, so that a point up to a wire length past the end sits at ``xi <= 1/2`` (the Hermite
    shape functions of a far-extrapolated ``xi`` lose the straight line to round-off)."""
    return 2.0 * float(element_start[-1] - element_start[0])


def extension_rows(element: np.ndarray, dim: int, at_end: bool, length: float):
    """The element coordinates ``(rows, columns, weights)`` of a wire's straight continuation
    past its end (``at_end``) or its start, as one element of ``length`` beside the real end
    element ``element`` (its global coordinate indices, two nodes of position then gradients).

    A cubic Hermite element whose nodes have the same gradient ``r'`` and positions ``length r'``
    apart is exactly the straight line ``r_end + (s - s_end) r'``; its coordinates are linear in
    the end node's: the far node's position is ``r_end +/- length r'``, every other coordinate a
    copy. Coordinates that are fixed stay in ``q`` with their values, so the map needs no
    constant."""
    n_loc = element.size
    half = n_loc // 2
    node = element[half:] if at_end else element[:half]
    rows, cols, weights = [], [], []
    for side in (0, 1):  # the virtual element's two nodes
        far = side == 1 if at_end else side == 0
        for i in range(half):
            rows.append(side * half + i), cols.append(node[i]), weights.append(1.0)
            if far and i < dim:  # position: plus (or minus) length times the gradient
                rows.append(side * half + i), cols.append(node[dim + i]), weights.append(length if at_end else -length)
    return np.array(rows), np.array(cols), np.array(weights)
