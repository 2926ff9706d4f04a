"""BLAS threads for symcat's solves.

symcat's dense and banded solves are small (a capacitance of a few hundred unknowns, a banded
Cholesky factor a few dozen wide): BLAS threads only contend for the cores, and on a busy
machine a threaded LAPACK call can take ten times longer than a serial one. The time
integrations and the multibody static solve therefore run with one BLAS thread (a modal
analysis's dense eigensolver, large, keeps them).
"""
from __future__ import annotations

import functools
import sys
from contextlib import contextmanager

#: The thread-pool controller and the number of imported modules it was made with: finding
#: the loaded BLAS libraries scans every shared library of the process (milliseconds, as much
#: as a short run's integration), so it is done again only after new imports (which may load
#: another BLAS).
_CONTROLLER: list = [None, -1]


@contextmanager
def serial_blas():
    """Run the body with one BLAS thread (restored on exit)."""
    from threadpoolctl import ThreadpoolController

    if _CONTROLLER[1] != len(sys.modules):
        _CONTROLLER[:] = [ThreadpoolController(), len(sys.modules)]
    with _CONTROLLER[0].limit(limits=1, user_api="blas"):
        yield


def serially(fn):
    """``fn`` run with one BLAS thread (:func:`serial_blas`): a solver made of small banded
    factorizations (form finding, a catenary's static states)."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with serial_blas():
            return fn(*args, **kwargs)

    return wrapper
