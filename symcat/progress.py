"""A minimal progress bar on stderr for long runs (shown only after a couple of seconds)."""
from __future__ import annotations

import sys
import time


class Progress:
    """Progress of a quantity from 0 to ``total``.

    Prints nothing during the first ``delay`` seconds, so short runs stay quiet.
    """

    def __init__(self, label: str, total: float, unit: str = "", enabled: bool = True, delay: float = 2.0):
        self.label, self.total, self.unit = label, float(total), unit
        self.enabled = enabled
        self.start = time.perf_counter()
        self.delay = delay
        self.shown = False
        self._last = 0.0

    def update(self, value: float) -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        elapsed = now - self.start
        if elapsed < self.delay or now - self._last < 0.2:
            return
        self._last = now
        frac = min(1.0, max(0.0, value / self.total)) if self.total else 1.0
        width = 30
        bar = "#" * int(frac * width) + "-" * (width - int(frac * width))
        eta = elapsed * (1 - frac) / frac if frac > 0 else float("nan")
        sys.stderr.write(f"\r{self.label} [{bar}] {100 * frac:5.1f}% {value:.4g}/{self.total:.4g} {self.unit} "
                         f"elapsed {elapsed:.1f} s eta {eta:.1f} s")
        sys.stderr.flush()
        self.shown = True

    def close(self) -> None:
        if self.shown:
            sys.stderr.write("\n")
            sys.stderr.flush()
