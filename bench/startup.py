"""Start-up: the import of the package's top level and a warm `symcat run <model> --quiet` of each
static model, whole processes, medians of repeats. A model imports only what its scene uses (no
multibody, wheel/rail, SymPy or, unless it plots, matplotlib: tests/test_imports.py), so a static
run costs NumPy, SciPy's sparse solvers, CasADi and its kernels' loading plus the computation.
``python -m bench.startup`` prints the section; ``make bench`` adds it to the report."""
from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REPEATS = 5
STATIC_MODELS = ("cantilever", "rollup", "taut_wire", "hanging_cable")
#: Targets in seconds: a warm run of a static model, the import of ``symcat``.
RUN_TARGET_S = 1.0
IMPORT_TARGET_S = 0.2


def _symcat_command() -> list[str]:
    exe = Path(sys.executable).with_name("symcat")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "symcat.cli"]


def _wall(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, cwd=ROOT, capture_output=True)
    return time.perf_counter() - t0


def _median_wall(cmd: list[str], repeats: int = REPEATS) -> float:
    return statistics.median(_wall(cmd) for _ in range(repeats))


def _import_seconds(module: str) -> float:
    """Time of ``import module`` inside a fresh interpreter (its own start-up excluded)."""
    code = f"import time; t = time.perf_counter(); import {module}; print(time.perf_counter() - t)"
    out = subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT, capture_output=True, text=True)
    return float(out.stdout.split()[-1])


def _imports_of_run(model: str) -> float:
    """Seconds of a run spent importing (``-X importtime``, the top-level imports' cumulative sum)."""
    cmd = [sys.executable, "-X", "importtime", "-m", "symcat.cli", "run", model, "--quiet"]
    out = subprocess.run(cmd, check=True, cwd=ROOT, capture_output=True, text=True)
    total_us = 0
    for line in out.stderr.splitlines():
        if line.startswith("import time:") and "|" in line:
            _, cumulative, name = line.split("|")
            if name.startswith(" ") and not name.startswith("  ") and cumulative.strip().isdigit():
                total_us += int(cumulative)
    return total_us * 1e-6


def startup_times() -> tuple[dict, list[tuple[str, float, float]]]:
    """(top-level figures, [(model, median warm wall s, of which imports s)])."""
    interpreter = _median_wall([sys.executable, "-c", "pass"])
    top = {
        "interpreter": interpreter,
        "python -c 'import symcat'": _median_wall([sys.executable, "-c", "import symcat"]),
        "import symcat": statistics.median(_import_seconds("symcat") for _ in range(REPEATS)),
    }
    rows = []
    for model in STATIC_MODELS:
        cmd = [*_symcat_command(), "run", model, "--quiet"]
        _wall(cmd)  # warm: kernels compiled and cached, files in the page cache
        rows.append((model, _median_wall(cmd), statistics.median(_imports_of_run(model) for _ in range(3))))
    return top, rows


def _verdict(ok: bool) -> str:
    return "pass" if ok else "**fail**"


def section(report_dir=None) -> list[str]:
    top, rows = startup_times()
    imp = top["import symcat"]
    process = top["python -c 'import symcat'"]
    return [
        "## Start-up (whole processes, warm)",
        "",
        (f"Medians of {REPEATS} processes. A static model's run imports NumPy, SciPy's sparse solvers, CasADi, the "
         "scene, the assembly and its analytic reference, not the multibody, wheel/rail, SymPy or plotting code. "
         f"The Python interpreter alone starts in {top['interpreter']:.3f} s."),
        "",
        "| measure | seconds | target | |",
        "|---|---:|---:|---|",
        f"| `import symcat` (in the process) | {imp:.3f} | < {IMPORT_TARGET_S:g} | {_verdict(imp < IMPORT_TARGET_S)} |",
        f"| `python -c 'import symcat'` (whole process) | {process:.3f} | | |",
        "",
        "| `symcat run <model> --quiet` | wall [s] | of which imports [s] | target | |",
        "|---|---:|---:|---:|---|",
        *[f"| {m} | {w:.2f} | {i:.2f} | < {RUN_TARGET_S:g} | {_verdict(w < RUN_TARGET_S)} |" for m, w, i in rows],
        "",
        ("Imports: the sum of the top-level imports' cumulative times under `python -X importtime` (which "
         "slows them somewhat), median of 3 runs."),
        "",
    ]


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    print("\n".join(section()))
    sys.exit(0)
