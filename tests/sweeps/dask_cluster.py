"""A Dask cluster for the tests: worker processes of one thread on the loopback interface."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def loopback_client(workers: int = 2) -> Iterator[Any]:
    """A client of a local cluster of ``workers`` one-thread worker processes on 127.0.0.1 (no dashboard)."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=workers, threads_per_worker=1, host="127.0.0.1", processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:  # fmt: skip
        yield client
