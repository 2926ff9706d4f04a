"""The optimized tier of the compiled model DAEs (:mod:`.model_dae`), compiled in the background.

A model's DAE library is compiled at ``-O0`` first: the seed vehicle's 5 MB of straight-line C
then takes 11 s. At ``-Og`` the same code keeps its values in registers, and IDAS's Jacobian and
residual run about twice as fast (the seed vehicle's first simulated second on S1002/UIC60: 1.4 s
inside IDAS at -O0, 0.85 s at -Og), but it compiles for 27 s (-O1: 48 s, same speed; register
allocation over 200k operations dominates either). So a run that compiles a model keeps its C in
the cache and starts the compiler at -Og in a background process (niced); later runs of the model
load the optimized library. The environment variable ``SYMCAT_OPTIMIZE`` chooses:

``background`` (default)
    as above;
``now``
    a missing optimized library is compiled at once (the benchmarks);
``off``
    -O0 only, nothing in the background (the test suite).

A model whose -O0 library was compiled in mode ``off`` (or by a symcat without this tier) has no
C left to optimize in the background: one run in mode ``now`` compiles its optimized library.
"""
from __future__ import annotations

import logging
import os
import subprocess
import sys
import time
from pathlib import Path

from ..errors import ParameterError

log = logging.getLogger(__name__)

OPTIMIZE_ENV = "SYMCAT_OPTIMIZE"
MODES = ("background", "now", "off")
#: -Og: as fast as -O1 on this code, and compiled in half its time (see the module docstring).
OPTIMIZED_FLAGS = ("-Og", "-fPIC", "-shared")

#: Background compilers started by this process (kept so that they are not reported as
#: leaked; :func:`wait_for_background` joins them).
_JOBS: list[subprocess.Popen] = []


def optimize_mode() -> str:
    """The mode of ``$SYMCAT_OPTIMIZE`` (default ``background``).

    Raises
    ------
    ParameterError
        If the variable holds anything else than one of :data:`MODES`.
    """
    mode = os.environ.get(OPTIMIZE_ENV, "background").strip().lower() or "background"
    if mode not in MODES:
        raise ParameterError(f"{OPTIMIZE_ENV}={os.environ[OPTIMIZE_ENV]!r}: must be one of {', '.join(MODES)}")
    return mode


def source_path(library: Path) -> Path:
    """Where the C of an optimized library waits for its background compiler."""
    return library.with_suffix(".c")


def lock_path(library: Path) -> Path:
    """The lock file of the background job that compiles ``library`` (holding its process id)."""
    return library.with_suffix(".lock")


def _running(lock: Path) -> bool:
    """Whether the process named in ``lock`` is alive."""
    try:
        pid = int(lock.read_text().strip() or 0)
        age_s = time.time() - lock.stat().st_mtime
    except (OSError, ValueError):
        return False
    if pid <= 0:
        return age_s < 60.0  # being written by the process that starts the job, unless it died
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # alive, another user's
    return True


def jobs_running(folder: Path) -> bool:
    """Whether a background job compiles into ``folder`` (any process's)."""
    return any(_running(lock) for lock in folder.glob("*.lock"))


def start_background(library: Path, flags: tuple = OPTIMIZED_FLAGS, module: str = __name__) -> bool:
    """Start compiling :func:`source_path` of ``library`` into ``library`` with ``flags`` in a
    background process, unless one runs already; True if one was started. ``module``: the
    module whose ``__main__`` the process runs with the arguments ``library flags...`` (one that
    first writes the C, e.g. :mod:`symcat.integrate.alpha_rest`, then calls
    :func:`compile_waiting`)."""
    lock = lock_path(library)
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            break
        except FileExistsError:
            if _running(lock):
                return False
            lock.unlink(missing_ok=True)  # left by a compiler that died
    else:
        return False
    try:
        job = subprocess.Popen([sys.executable, "-m", module, str(library), *flags],
                               stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               start_new_session=True)
        os.write(fd, str(job.pid).encode())
    except OSError:
        lock.unlink(missing_ok=True)
        raise
    finally:
        os.close(fd)
    _JOBS.append(job)
    log.info("compiling an optimized %s in the background (about 30 s for the seed vehicle); later runs of "
             "this model load it", library.name)
    return True


def wait_for_background(timeout_s: float = 300.0) -> bool:
    """Wait until this process's background compilers have finished (``timeout_s`` s at
    most); True if none is left running."""
    end = time.monotonic() + timeout_s
    for job in _JOBS:
        try:
            job.wait(max(0.0, end - time.monotonic()))
        except subprocess.TimeoutExpired:
            return False
    _JOBS.clear()
    return True


def failed_path(library: Path) -> Path:
    """Where a background job that failed left its message (it would fail again)."""
    return library.with_suffix(".failed")


def compile_written(library: Path, flags: tuple, graph: Path, write) -> int:
    """The background job of a library whose C is written from a waiting serialized graph:
    ``write(graph, folder) -> path`` writes the C into ``folder``, then :func:`compile_waiting`
    compiles it; the graph is removed, a failure left in :func:`failed_path` (nobody reads the
    job's stderr) and the lock removed."""
    import shutil
    import tempfile

    try:
        os.nice(10)
        with tempfile.TemporaryDirectory() as tmp:
            shutil.move(str(write(graph, Path(tmp))), source_path(library))
    except Exception as exc:  # noqa: BLE001 - reported in a file: nobody reads this process's stderr
        failed_path(library).write_text(f"{type(exc).__name__}: {exc}\n")
        lock_path(library).unlink(missing_ok=True)
        return 1
    finally:
        graph.unlink(missing_ok=True)
    return compile_waiting(library, flags)


def compile_waiting(library: Path, flags: tuple = OPTIMIZED_FLAGS) -> int:
    """The background job: compile the waiting C into ``library`` with ``flags``, then remove
    the C and the lock (also on failure, whose message is left in :func:`failed_path`)."""
    from .library import build_library, find_compiler

    source = source_path(library)
    try:
        os.nice(10)
        build_library(find_compiler(), flags, source, library)
        return 0
    except Exception as exc:  # noqa: BLE001 - reported in a file: nobody reads this process's stderr
        failed_path(library).write_text(f"{type(exc).__name__}: {exc}\n")
        return 1
    finally:
        source.unlink(missing_ok=True)
        lock_path(library).unlink(missing_ok=True)


if __name__ == "__main__":
    sys.exit(compile_waiting(Path(sys.argv[1]), tuple(sys.argv[2:]) or OPTIMIZED_FLAGS))
