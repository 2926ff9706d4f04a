"""Running a study's runs on Dask: a local cluster or an existing one, retries, progress.

``local`` starts a ``LocalCluster`` of single-threaded worker processes (one per core unless
``workers`` says otherwise), each run a task. The runner keeps as many runs in flight as there
are worker threads, so a worker holds only the run it is doing and a killed worker loses only
that run; on the local cluster a worker that dies fails its task at once (``allowed-failures``
0), the runner submits that run once more and records it as ``lost`` if it dies again. An
existing cluster (``tcp://HOST:PORT``) keeps its own scheduler settings: with Dask's defaults a
dead worker's task is retried by the scheduler itself up to three times before the runner's one
retry.
"""
from __future__ import annotations

import contextlib
import importlib.util
import logging
import os
import re
import socket
import sys
import time

from ..errors import ParameterError

#: How long to wait for an external scheduler (s): the refusal comes within 10 s of the command.
CONNECT_TIMEOUT_S = 8.0
#: How long to wait for ``workers`` workers to join an external scheduler (s).
WORKERS_TIMEOUT_S = 60.0


#: The environment of local workers: one BLAS/OpenMP thread each (a worker per core), and not
#: Dask's default ``MALLOC_TRIM_THRESHOLD_``, which (setting it turns glibc's dynamic mmap
#: threshold off) maps and unmaps every large NumPy array: form finding then takes twice as long.
#: Workers of an existing cluster keep their own settings.
LOCAL_WORKER_ENVIRON = {"OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1, "OPENBLAS_NUM_THREADS": 1}


class StudyProgress:
    """A one-line progress of the runs on stderr: done, failed, running, estimated time left.

    Silent for the first ``delay`` seconds; the estimate is the finished runs' rate since the
    first run ended (the cluster's start and the first compilations do not count)."""

    def __init__(self, total: int, done: int, slots: int, enabled: bool = True, delay: float = 1.0):
        self.total, self.done, self.failed, self.slots = total, done, 0, max(1, slots)
        self.enabled, self.delay = enabled, delay
        self.start = time.perf_counter()
        self._first: tuple[float, int] | None = None
        self._last = 0.0
        self.shown = False

    def update(self, done: int, failed: int, force: bool = False) -> None:
        now = time.perf_counter()
        if self._first is None and done > self.done:
            self._first = (now, done)
        self.done, self.failed = done, failed
        if not self.enabled or (not force and (now - self.start < self.delay or now - self._last < 0.2)):
            return
        self._last = now
        running = min(self.slots, self.total - done)
        eta = "--"
        if self._first is not None and done > self._first[1]:
            rate = (done - self._first[1]) / (now - self._first[0])
            eta = f"{(self.total - done) / rate:.0f} s"
        width = 30
        frac = done / self.total if self.total else 1.0
        bar = "#" * int(frac * width) + "-" * (width - int(frac * width))
        sys.stderr.write(f"\rstudy [{bar}] {done}/{self.total} runs, {failed} failed, {running} running, "
                         f"elapsed {now - self.start:.0f} s, eta {eta}   ")
        sys.stderr.flush()
        self.shown = True

    def close(self) -> None:
        if self.shown:
            sys.stderr.write("\n")
            sys.stderr.flush()


def _quiet_logs() -> None:
    for name in ("distributed", "distributed.nanny", "distributed.scheduler", "distributed.worker",
                 "distributed.core", "distributed.comm"):
        logging.getLogger(name).setLevel(logging.CRITICAL)  # what matters is in the rows


@contextlib.contextmanager
def connect(scheduler: str = "local", workers: int | None = None):
    """A Dask client for ``scheduler`` (``"local"`` or ``"tcp://HOST:PORT"``), closed on exit.

    Raises
    ------
    ParameterError
        A scheduler that is not of either form, or that cannot be reached within
        :data:`CONNECT_TIMEOUT_S`; ``workers`` not a positive integer.
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ParameterError(f"--workers {workers}: must be an integer >= 1")
    if scheduler != "local" and not re.fullmatch(r"tcp://[^\s:/]+:\d{1,5}", scheduler or ""):
        raise ParameterError(f"--scheduler {scheduler}: must be local or tcp://HOST:PORT")
    import dask
    from distributed import Client, LocalCluster

    _quiet_logs()
    if scheduler == "local":
        n = workers or os.cpu_count() or 1
        with dask.config.set({"distributed.scheduler.allowed-failures": 0,
                              "distributed.scheduler.worker-saturation": 1.0,
                              "distributed.nanny.pre-spawn-environ": LOCAL_WORKER_ENVIRON,
                              # the statistical profiler samples the running thread every 10 ms
                              "distributed.worker.profile.enabled": False}):
            # the dashboard needs bokeh (not a dependency): served when it is installed
            board = ":0" if importlib.util.find_spec("bokeh") is not None else None
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=board,
                                   worker_dashboard_address=None, silence_logs=logging.CRITICAL)
            client = Client(cluster)
        try:
            yield client
        except BaseException:  # Ctrl-C or an error: stop the workers' runs now, not after Dask's 4 s of grace
            with contextlib.suppress(Exception):
                for nanny in list(cluster.workers.values()):
                    cluster.sync(nanny.kill, timeout=0.5)
            raise
        finally:
            client.close()
            cluster.close()
        return
    host, port = scheduler[len("tcp://"):].rsplit(":", 1)
    t0 = time.perf_counter()
    try:  # a refused or unknown address is told at once, not after the client's retries
        socket.create_connection((host, int(port)), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as err:
        reason = err.strerror or type(err).__name__
        raise ParameterError(f"--scheduler {scheduler}: cannot reach it ({reason}); start a scheduler "
                             "(`dask scheduler`) or give its address") from None
    left = max(1.0, CONNECT_TIMEOUT_S - (time.perf_counter() - t0))
    try:
        client = Client(scheduler, timeout=f"{left:g}s")
    except Exception as err:  # refused, timed out, or something else answering there
        raise ParameterError(f"--scheduler {scheduler}: no Dask scheduler answered within {CONNECT_TIMEOUT_S:g} s "
                             f"({type(err).__name__}); start one (`dask scheduler`) or give its address") from None
    try:
        if workers:
            try:
                client.wait_for_workers(workers, timeout=WORKERS_TIMEOUT_S)
            except TimeoutError:
                raise ParameterError(f"--workers {workers}: fewer workers joined {scheduler} within "
                                     f"{WORKERS_TIMEOUT_S:g} s") from None
        yield client
    finally:
        client.close()


def _has_bokeh() -> bool:
    return importlib.util.find_spec("bokeh") is not None


def dashboard(client) -> str | None:
    """The address of the Dask dashboard, when the scheduler serves one."""
    try:
        # the scheduler's HTTP server is up either way; its dashboard pages need bokeh there
        if ("dashboard" in client.scheduler_info().get("services", {})
                and client.run_on_scheduler(_has_bokeh)):
            return client.dashboard_link
    except Exception:  # no dashboard is no reason to stop a study
        return None
    return None


def slots(client) -> int:
    """The number of worker threads."""
    return sum(w.get("nthreads", 1) for w in client.scheduler_info().get("workers", {}).values())


def execute(client, model_ref: str, runs, on_row, out_dir=None, progress: bool = True, done_before: int = 0,
            failed_before: int = 0, total: int | None = None) -> None:
    """Run ``runs`` on ``client``; ``on_row(run, row)`` receives each run's row as it ends.

    A run whose worker dies is submitted once more; if that one dies too, its row has status
    ``lost`` and the worker's error.
    """
    from distributed import as_completed

    from .task import run_one

    total = total if total is not None else len(runs) + done_before
    bar = StudyProgress(total, done_before, slots(client), enabled=progress)
    done, failed = done_before, failed_before

    def submit(run, attempt):
        out = None if out_dir is None else str(out_dir(run.run_id))
        return client.submit(run_one, model_ref, run.params, out, key=f"symcat-run-{run.run_id}-{attempt}",
                             pure=False)

    # As many runs in flight as there are worker threads: a worker holds only the run it is
    # doing (a killed one loses only that), whatever the scheduler's queuing settings.
    waiting = [(run, 0) for run in runs][::-1]
    futures: dict = {}
    pending = as_completed()

    def top_up():
        while waiting and len(futures) < max(1, slots(client)):
            run, attempt = waiting.pop()
            fut = submit(run, attempt)
            futures[fut] = (run, attempt)
            pending.add(fut)

    top_up()
    try:
        for fut in pending:
            run, attempt = futures.pop(fut)
            try:
                row = fut.result()
            except Exception as err:  # the worker died (KilledWorker) or the task could not run there
                if attempt == 0:
                    waiting.append((run, 1))
                    top_up()
                    continue
                line = (str(err).strip().splitlines() or [""])[0]
                row = {"status": "lost", "error": f"{type(err).__name__}: {line}"[:500], "summary": {},
                       "run_wall_s": None, "run_cpu_s": None, "worker": None}
            finally:
                fut.release()
            row["attempts"] = attempt + 1
            done += 1
            failed += row["status"] != "ok"
            on_row(run, row)  # recorded before the next run starts: an interruption keeps it
            top_up()
            bar.update(done, failed)
        bar.update(done, failed, force=bar.shown)
    finally:
        bar.close()
        for fut in futures:
            fut.cancel()
