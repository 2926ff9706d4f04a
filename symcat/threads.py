"""BLAS threads for symcat's solves.

symcat's dense and banded solves are small (a capacitance of a few hundred unknowns, a banded
Cholesky factor a few dozen wide): BLAS threads only contend for the cores, and on a busy
machine a threaded LAPACK call can take ten times longer than a serial one. The time
integrations and the multibody static solve therefore run with one BLAS thread (a modal
analysis's dense eigensolver, large, keeps them).
"""
from __future__ import annotations

from contextlib import contextmanager


@contextmanager
def serial_blas():
    """Run the body with one BLAS thread (restored on exit)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield
