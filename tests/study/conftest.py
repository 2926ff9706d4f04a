"""The study tests share one local Dask cluster of two single-threaded workers (started once:
a cluster's start-up is the slow part of a small study)."""
from __future__ import annotations

from pathlib import Path

import pytest

#: The instant model of these tests.
TOY = str(Path(__file__).resolve().parent / "models" / "toy.py")


@pytest.fixture(scope="session")
def client():
    from symcat.study.runner import connect

    with connect("local", 2) as c:
        yield c
