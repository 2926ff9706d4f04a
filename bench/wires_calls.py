"""Time of the compiled line steps alone: after a run of a case of :mod:`bench.wires_speed`
(its library compiled), repeated compiled calls from the run's last state, of the run's
steps per call (``$PER`` to set it; the runs' output interval is one step).
Prints the median and the least CPU ms per step over ``repeats`` calls (the least: the
machine is shared). Usage:
python -m bench.wires_calls CASE [repeats] [seconds to keep calling, for a profiler]"""
from __future__ import annotations

import json
import os
import sys
import time

os.environ.setdefault("SYMCAT_OPTIMIZE", "background")


def main(case: str, repeats: int = 30, hold: float = 0.0) -> dict:
    import numpy as np

    import symcat.integrate.alpha_chunk as ac
    from bench.wires_speed import main as run

    captured = {}
    call = ac.CompiledSteps._call

    def call_(self, s, t, n, states=None):
        captured.update(cs=self, s=s, t=t)
        return call(self, s, t, n, states)

    ac.CompiledSteps._call = call_
    res = run(case)
    cs, s, t = captured["cs"], captured["s"], captured["t"]
    times, its = [], []
    end = time.perf_counter() + hold
    k = 0
    per = int(os.environ.get("PER", cs.per))
    res["run_per"], cs.per = cs.per, per
    while k < repeats or time.perf_counter() < end:
        cs._last = None
        t0 = time.thread_time()  # (CPU time: the machine is shared)
        done, _, iterations = cs._call(s, t, 32)
        times.append((time.thread_time() - t0) / max(done, 1))
        its.append(iterations / max(done, 1))
        k += 1
    res.update(call_ms_per_step=1e3 * float(np.median(times)), call_min_ms=1e3 * float(np.min(times)), call_iterations=float(np.median(its)), done=done)
    return res


if __name__ == "__main__":
    a = sys.argv[1:]
    print(json.dumps(main(a[0], int(a[1]) if len(a) > 1 else 30, float(a[2]) if len(a) > 2 else 0.0)))
