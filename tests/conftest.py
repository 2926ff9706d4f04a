import os

# Parallel test workers (pytest-xdist, `make test`) each run one BLAS thread: as many workers as
# cores already keep the cores busy, and BLAS threads beyond them only contend (see
# symcat/threads.py). Set before NumPy is imported; a serial run keeps the library's default.
if os.environ.get("PYTEST_XDIST_WORKER"):
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

# No optimized model libraries compiled in the background while the tests run (they would
# compete for the cores); tests/codegen/test_optimized_tier.py sets the mode it tests.
os.environ.setdefault("SYMCAT_OPTIMIZE", "off")


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)


def pytest_xdist_auto_num_workers(config):
    """``-n auto`` (``make test``): one worker per CPU this process may run on, hyperthreads
    and a container's CPU set included (``os.sched_getaffinity``). pytest-xdist itself counts
    physical cores, one on a machine of two hyperthreads: no parallel run at all.
    ``PYTEST_XDIST_AUTO_NUM_WORKERS`` still sets the number."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS") or not hasattr(os, "sched_getaffinity"):
        return None  # pytest-xdist decides
    return max(1, len(os.sched_getaffinity(0)))


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """The files that hold a test marked ``slow`` first (otherwise as collected): ``make test``
    hands the tests out to its parallel workers a file at a time (``--dist loadfile``, in this
    order: ``--no-loadscope-reorder``), so that a module-scoped fixture is built once, and the
    longest files start first instead of one of them running alone at the end."""
    slow = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow)  # stable


def _plain(value):
    """``value`` with NumPy scalars and arrays as Python numbers and lists (nested in lists,
    tuples and dicts)."""
    if isinstance(value, (np.generic, np.ndarray)):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return type(value)(_plain(v) for v in value)
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Properties recorded with ``record_property`` as plain Python values: pytest-xdist's
    workers send each report to the controller through execnet, which cannot serialize a NumPy
    float (the worker would stop with an internal error)."""
    outcome = yield
    report = outcome.get_result()
    report.user_properties = [(name, _plain(value)) for name, value in report.user_properties]
