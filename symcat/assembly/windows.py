"""The moving element windows of sliding joints and penalty contacts: the elements of a wire
whose coordinates a point's kernels see (:meth:`ElementWindows._selection`
selects the one containing the point among them). A window over a whole line would make the
contact's Jacobian block dense over every element; it is kept a few elements wide and moved
with the point between integrator calls or steps."""
from __future__ import annotations

import casadi as ca
import numpy as np


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
        constant in ``s`` (zero derivative), so one sparse product carries the chain rule."""
        lo, hi = sl.window
        masks = []
        for k in range(lo, hi):
            below = s >= sl.element_start[k] if k > lo else ca.MX(1)
            above = s < sl.element_start[k + 1] if k < hi - 1 else ca.MX(1)
            masks.append(ca.logic_and(below, above))
        masks = ca.vertcat(*masks)
        n_loc = sl.element_indices.shape[1]
        rows = np.tile(np.arange(n_loc), hi - lo)
        cols = sl.element_indices[lo:hi].ravel()
        order = np.lexsort((rows, cols))  # CSC order: by column, then row
        pattern = ca.Sparsity.triplet(n_loc, self.n_q, rows[order].tolist(), cols[order].tolist())
        values = ca.repmat(masks.T, n_loc, 1)  # entry (r, k): mask of window element k
        values = ca.vec(values)[order.tolist()]
        sel = ca.sparsity_cast(values, pattern)
        start = ca.dot(masks, ca.DM(sl.element_start[lo:hi]))
        length = ca.dot(masks, ca.DM(np.diff(sl.element_start)[lo:hi]))
        override = self.element_override.get(id(sl))
        if override is not None:  # a stand-in element: the actual one's start and length given
            start, length = override
        return sel, start, length
