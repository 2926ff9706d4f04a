"""Studies on Dask (:mod:`symcat.study`): parallel efficiency of benchmark2015 runs at the 1 %
settings on two local workers against the same runs one after the other in one process, and the
overhead per run (scheduling, serialization, result collection, the row written to the study
folder) from a study of instant runs. ``python -m bench.study`` prints the section; ``make bench``
adds it to the report. ``SYMCAT_BENCH_STUDY=0`` leaves it out.

The serial runs are warm (kernels loaded, the model imported); the parallel ones are timed on a
cluster whose workers have already run the model once (a study's steady state), and also with the
cluster's start and the workers' first imports included.
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

#: The 1 % settings of bench/pantograph.py (statistics within about 1 % of converged).
ONE_PERCENT = dict(elements_per_span=50, dt=2e-3, tol=1e-3, wires="linear", paraview=False, progress=False)
#: Eight speeds: eight runs.
SPEEDS = "250:320:10"
WORKERS = 2
#: Targets: parallel wall over serial wall, and the overhead per run (s).
RATIO_TARGET = 0.6
OVERHEAD_TARGET_S = 0.2
#: Instant runs for the overhead.
OVERHEAD_RUNS = 60
#: Serial and parallel timings, interleaved; the report gives their medians (a noisy machine).
REPEATS = 3


def _serial(speeds: list[float]) -> tuple[float, float]:
    """Wall and CPU time (s) of the runs one after the other in this process."""
    from symcat.model import load_model, run_model

    model = load_model("benchmark2015")
    run_model(model, {**ONE_PERCENT, "speed_kmh": speeds[0], "t_end": 0.05})  # warm: kernels loaded
    t0, cpu0 = time.perf_counter(), time.process_time()
    for v in speeds:
        run_model(model, {**ONE_PERCENT, "speed_kmh": v})
    return time.perf_counter() - t0, time.process_time() - cpu0


def measure() -> dict:
    from symcat.study import run_study
    from symcat.study.runner import connect
    from symcat.study.spec import parse_grid
    from symcat.model import load_model

    speeds = parse_grid(load_model("benchmark2015"), f"speed_kmh={SPEEDS}")[1]
    load_before = os.getloadavg()[0]
    serials, parallels, studies = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        with connect("local", WORKERS) as client:
            up = time.perf_counter() - t0
            # the workers' first imports, outside the steady-state timing
            run_study("benchmark2015", {**ONE_PERCENT, "t_end": 0.05}, {"speed_kmh": "250,260"}, client=client,
                      progress=False)
            cold = time.perf_counter() - t0
            for k in range(REPEATS):
                serials.append(_serial(speeds))
                warm_start = time.perf_counter()
                studies.append(run_study("benchmark2015", ONE_PERCENT, {"speed_kmh": SPEEDS}, client=client,
                                         out=Path(tmp) / f"speeds_{k}", progress=False, plots=False))
                parallels.append(time.perf_counter() - warm_start)
            cold += parallels[0]  # the cluster's start and first imports, then one study
            order = sorted(range(REPEATS), key=lambda k: parallels[k] / serials[k][0])
            median = order[REPEATS // 2]
            (serial, serial_cpu), parallel, study = serials[median], parallels[median], studies[median]
            t1 = time.perf_counter()
            instant = run_study("taut_wire", {"n_elements": 2, "n_modes": 1}, {"tension": f"1000:{1000 * OVERHEAD_RUNS}:1000"},
                                client=client, out=Path(tmp) / "instant", progress=False, plots=False)
            overhead_wall = time.perf_counter() - t1
    busy = float(instant.table["run_wall_s"].sum())
    # On an idle machine each worker has its core: the study's wall would be its busiest worker's CPU
    # time plus the engine's share (its wall not spent in runs).
    cpu = study.table.groupby("worker")["run_cpu_s"].sum()
    engine = parallel - float(study.table.groupby("worker")["run_wall_s"].sum().max())
    return {"load": (load_before, os.getloadavg()[0]), "serial_cpu_s": serial_cpu,
            "idle_estimate_s": float(cpu.max()) + max(engine, 0.0), "worker_cpu_s": float(cpu.sum()),
            "busy": float(study.table["run_wall_s"].sum()) / (WORKERS * parallel), "serial_s": serial, "parallel_s": parallel, "cold_s": cold, "cluster_start_s": up,
            "failed": study.failed, "run_walls": list(study.table["run_wall_s"]),
            "ratios": sorted(p / w for p, (w, _) in zip(parallels, serials)),
            "overhead_s": (WORKERS * overhead_wall - busy) / OVERHEAD_RUNS, "instant_run_s": busy / OVERHEAD_RUNS}


def section(report_dir=None) -> list[str]:
    if os.environ.get("SYMCAT_BENCH_STUDY", "1") == "0":
        return []
    m = measure()
    ratio = m["parallel_s"] / m["serial_s"]
    return [
        "## Studies on Dask (two local workers)",
        "",
        f"Eight `benchmark2015` runs at the 1 % settings (50 elements/span, dt 2 ms, tol 1e-3 m, linear wires), "
        f"speeds {SPEEDS} km/h, as `symcat study benchmark2015 --grid speed_kmh={SPEEDS} --workers {WORKERS}`. "
        "Serial: the same runs one after the other in one warm process. The machine's two cores may be shared "
        f"with other work while this runs. {REPEATS} interleaved serial and study timings; the table shows the pair "
        "with the median ratio (all ratios: " + ", ".join(f"{r:.2f}" for r in m["ratios"]) + ").",
        "",
        "| | wall [s] | / serial |",
        "|---|---:|---:|",
        f"| serial, one process | {m['serial_s']:.1f} | 1.00 |",
        f"| study, workers warm | {m['parallel_s']:.1f} | {ratio:.2f} |",
        f"| study, cluster start ({m['cluster_start_s']:.1f} s) and first imports included | {m['cold_s']:.1f} | "
        f"{m['cold_s'] / m['serial_s']:.2f} |",
        "",
        f"Target: at most {RATIO_TARGET} of the serial time (efficiency >= {0.5 / RATIO_TARGET:.0%}): "
        f"{'met' if ratio <= RATIO_TARGET else 'not met'} ({ratio:.2f}, efficiency {0.5 / ratio:.0%}). "
        f"The workers were busy with runs {m['busy']:.0%} of the study's wall time (the rest is the engine's); "
        f"the machine's load average was {m['load'][0]:.1f} before and {m['load'][1]:.1f} after on "
        f"{os.cpu_count()} cores (above 1, other work shares the cores and the runs on two workers slow down).",
        "",
        "CPU time, which other work on the machine inflates less than wall time (it still shares caches and "
        f"cores): serial {m['serial_cpu_s']:.1f} s, the "
        f"workers {m['worker_cpu_s']:.1f} s for the same runs. The study's wall on an idle machine, estimated as its "
        f"busiest worker's CPU time plus the engine's share of the wall: {m['idle_estimate_s']:.1f} s, "
        f"{m['idle_estimate_s'] / m['serial_cpu_s']:.2f} of the serial CPU time.",
        "",
        f"Overhead per run (scheduling, serialization, result collection, the row written), from {OVERHEAD_RUNS} "
        f"instant `taut_wire` runs ({m['instant_run_s'] * 1e3:.0f} ms each on the worker): "
        f"(workers x wall - run time) / runs = {m['overhead_s'] * 1e3:.0f} ms; target below "
        f"{OVERHEAD_TARGET_S * 1e3:.0f} ms: {'met' if m['overhead_s'] < OVERHEAD_TARGET_S else 'not met'}.",
        "",
    ]


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    print("\n".join(section()))
