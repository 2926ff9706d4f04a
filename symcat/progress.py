"""A minimal progress bar on stderr for long runs (shown only after a couple of seconds), and
one-line notices of slow one-time work (compiling kernels)."""
from __future__ import annotations

import sys
import time


def notice(message: str) -> None:
    """Tell the user about slow work they would otherwise wait for in silence (one line on
    stderr, ``symcat: ...``), ending any progress bar's line first."""
    if Progress.active is not None and Progress.active.shown:
        sys.stderr.write("\n")
        Progress.active.shown = False
    sys.stderr.write(f"symcat: {message}\n")
    sys.stderr.flush()


class Progress:
    """Progress of a quantity from 0 to ``total``.

    Prints nothing during the first ``delay`` seconds, so short runs stay quiet. The estimate
    of the time left is the rate measured from the first :meth:`update` on, so that the set-up
    before it (compiling, static equilibrium) does not count.
    """

    #: The bar drawing now (notices end its line).
    active: "Progress | None" = None

    def __init__(self, label: str, total: float, unit: str = "", enabled: bool = True, delay: float = 2.0):
        self.label, self.total, self.unit = label, float(total), unit
        self.enabled = enabled
        self.start = time.perf_counter()
        self.delay = delay
        self.shown = False
        self._last = 0.0
        self._first: tuple[float, float] | None = None  # (wall time, value) of the first update

    def update(self, value: float) -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        if self._first is None:
            self._first = (now, value)
        elapsed = now - self.start
        if elapsed < self.delay or now - self._last < 0.2:
            return
        self._last = now
        frac = min(1.0, max(0.0, value / self.total)) if self.total else 1.0
        width = 30
        bar = "#" * int(frac * width) + "-" * (width - int(frac * width))
        t_first, v_first = self._first
        rate = (value - v_first) / (now - t_first) if value > v_first and now > t_first else 0.0
        eta = f"{(self.total - value) / rate:.1f} s" if rate > 0 else "--"
        sys.stderr.write(f"\r{self.label} [{bar}] {100 * frac:5.1f}% {value:.4g}/{self.total:.4g} {self.unit} "
                         f"elapsed {now - t_first:.1f} s eta {eta}")
        sys.stderr.flush()
        self.shown = True
        Progress.active = self

    def close(self) -> None:
        if self.shown:
            sys.stderr.write("\n")
            sys.stderr.flush()
            self.shown = False
        if Progress.active is self:
            Progress.active = None


class Status(Progress):
    """A one-line status of work whose length is not known in advance (an iteration that
    converges), rewritten in place; silent for the first ``delay`` seconds like the bar."""

    def __init__(self, label: str, enabled: bool = True, delay: float = 2.0):
        super().__init__(label, 1.0, enabled=enabled, delay=delay)
        self._width = 0

    def show(self, text: str) -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        if now - self.start < self.delay or now - self._last < 0.2:
            return
        self._last = now
        line = f"{self.label}: {text} (elapsed {now - self.start:.1f} s)"
        sys.stderr.write("\r" + line.ljust(self._width))
        sys.stderr.flush()
        self._width = len(line)
        self.shown = True
        Progress.active = self
