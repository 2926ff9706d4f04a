"""Tension sections along a line and the overlaps between them (geometry only, SI units).

A long line is a chain of tension sections, each with its own contact and messenger wire
anchored at both ends. Consecutive sections share a three-span overlap, the usual uninsulated
overlap of high-speed lines (EN 50119 practice):

- span 1: the ending wire A is still in running; the starting wire B is out of running;
- span 2 (transition, no presag): the two wires run side by side; A rises from mid-span on while B
  descends to working height, so at mid-span the pan-head touches both and hands over;
- span 3: B is in running, A out of running towards its anchor.

A wire out of running rises as ``h (u / (L/2))^2`` over the second half of the transition
span (``u`` from its mid-span, ``h = overlap_raise`` at the support) and then straight on
with the same slope to the anchor (``5 h`` there), so its droppers stay in tension. Each
section is offset laterally by ``+/- overlap_offset / 2`` so the two wires of an overlap are
apart in plan.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .design import CatenaryDesign


@dataclass(frozen=True)
class TensionSection:
    """One tension section of a line (x along the line, from the line's first support).

    Attributes
    ----------
    design : CatenaryDesign
        The section's design (``n_spans`` spans of ``span_length``).
    index : int
        Position in the line (0 first).
    first_support : int
        Line support number of the section's first support.
    lift_start, lift_end : bool
        Whether the wire goes out of running over its first/last two spans (an overlap).
    """

    design: CatenaryDesign
    index: int
    first_support: int
    lift_start: bool = False
    lift_end: bool = False

    @property
    def x0(self) -> float:
        """Position of the section's first support (m)."""
        return self.first_support * self.design.span_length

    @property
    def x_end(self) -> float:
        """Position of the section's last support (anchor) (m)."""
        return self.x0 + self.design.length

    @property
    def y_offset(self) -> float:
        """Lateral offset of the whole section (m): +/- half the overlap offset, alternating."""
        if self.design.n_sections == 1:
            return 0.0
        return 0.5 * self.design.overlap_offset * (1 if self.index % 2 == 0 else -1)

    def support_x(self) -> np.ndarray:
        """Support positions (m)."""
        return self.x0 + self.design.support_x()

    def dropper_x(self) -> np.ndarray:
        """Dropper positions (m)."""
        return self.x0 + self.design.dropper_x()

    def lift(self, x) -> np.ndarray:
        """Height of the contact wire above its working height from going out of running (m)."""
        d = self.design
        L, h = d.span_length, d.overlap_raise
        local = np.asarray(x, dtype=float) - self.x0
        out = np.zeros_like(local)
        for lifted, u in ((self.lift_start, 1.5 * L - local), (self.lift_end, local - (d.n_spans - 1.5) * L)):
            if lifted:
                s = np.maximum(u, 0.0) / (0.5 * L)
                out += h * np.where(s <= 1.0, s * s, 1.0 + 2.0 * (s - 1.0))
        return out

    def target_height(self, x) -> np.ndarray:
        """Design contact-wire height (m): presag, plus the lift where out of running. The
        overlap's transition and out-of-running spans have no presag (its curvature and the
        lift's would ask the droppers to push)."""
        d = self.design
        x = np.asarray(x, dtype=float)
        local = x - self.x0
        height = d.target_height(local)
        flat = np.zeros(local.shape, dtype=bool)
        if self.lift_start:
            flat |= local <= 2 * d.span_length
        if self.lift_end:
            flat |= local >= (d.n_spans - 2) * d.span_length
        return np.where(flat, d.contact_wire_height, height) + self.lift(x)

    def stagger_y(self, x) -> np.ndarray:
        """Contact-wire lateral position (m), zig-zag continued along the line."""
        sign = -1.0 if self.first_support % 2 else 1.0
        return sign * self.design.stagger_y(np.asarray(x, dtype=float) - self.x0) + self.y_offset

    def messenger_support_height(self) -> np.ndarray:
        """Messenger height at the supports (m): encumbrance above the contact wire's target."""
        return self.target_height(self.support_x()) + self.design.encumbrance

    def covers(self, x: float) -> bool:
        """Whether the section's contact wire spans position ``x`` (m)."""
        return self.x0 <= x <= self.x_end


def line_sections(design: CatenaryDesign) -> list[TensionSection]:
    """The tension sections of ``design``: ``n_sections`` of ``n_spans`` spans, each overlapping
    the next by three spans; a single section has no lifted ends."""
    n = design.n_sections
    step = design.n_spans - 3
    return [TensionSection(design, k, k * step, lift_start=k > 0, lift_end=k < n - 1) for k in range(n)]
