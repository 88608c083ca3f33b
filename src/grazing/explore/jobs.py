"""The page's requests in the background: one thread per lane, a newer request superseding older ones.

A click must not freeze the page, and ten quick clicks must not queue ten
computations: :class:`Jobs` runs each request on a worker thread of its lane
(the diagram has one, the clicked point's requests another), keeps at most one
request waiting per kind (a newer one replaces it), and tells a running one that
it is stale (its ``cancelled()`` becomes true), so that the computations of
:mod:`grazing.explore` stop at their next check (:class:`~.diagram.SupersededError`).
A stale result is never delivered.  Results and errors are handed to the page
through ``deliver`` (a server session's next tick).

Examples
--------
>>> import threading
>>> got, done = [], threading.Event()
>>> jobs = Jobs(deliver=lambda fn: fn())
>>> jobs.submit("point", lambda cancelled: 6 * 7, lambda r: (got.append(r), done.set()), print)
>>> done.wait(5), got
(True, [42])
>>> jobs.close()
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from grazing.explore.diagram import SupersededError

__all__ = ["LANES", "Jobs"]

LANES = {
    "diagram": "diagram",
    "refine": "diagram",
    "point": "point",
    "branch": "point",
    "grazings": "point",
    "curves": "point",
    "basins": "point",
}
"""The lane (worker thread) of each kind of request: a long diagram does not hold up a click."""


@dataclass
class _Job:
    kind: str
    token: int
    work: Callable[[Callable[[], bool]], Any]
    done: Callable[[Any], None]
    failed: Callable[[BaseException], None]


class Jobs:
    """Background work of one page (see the module docstring).

    Parameters
    ----------
    deliver
        Called (from a worker thread) with a function of no arguments that must
        run where the page may be changed: ``doc.add_next_tick_callback`` in a
        server session, a direct call elsewhere.
    """

    def __init__(self, deliver: Callable[[Callable[[], None]], None]) -> None:
        self.deliver = deliver
        self._tokens = itertools.count(1)
        self._latest: dict[str, int] = {}
        self._waiting: dict[str, dict[str, _Job]] = {lane: {} for lane in set(LANES.values())}
        self._lock = threading.Condition()
        self._threads: dict[str, threading.Thread] = {}
        self._closed = False

    def submit(
        self,
        kind: str,
        work: Callable[[Callable[[], bool]], Any],
        done: Callable[[Any], None],
        failed: Callable[[BaseException], None],
    ) -> None:
        """Run ``work(cancelled)`` in the background, then ``done(result)`` or ``failed(error)`` via deliver.

        ``work`` looks at ``cancelled()`` now and then (a newer request of the same
        kind, or :meth:`close`); a request of the same kind still waiting is dropped.
        """
        lane = LANES[kind]
        with self._lock:
            if self._closed:
                return
            token = next(self._tokens)
            self._latest[kind] = token
            self._waiting[lane][kind] = _Job(kind, token, work, done, failed)
            if lane not in self._threads:
                t = threading.Thread(
                    target=self._run, args=(lane,), name=f"grazing-explore-{lane}", daemon=True
                )
                self._threads[lane] = t
                t.start()
            self._lock.notify_all()

    def stale(self, kind: str, token: int) -> bool:
        return self._closed or self._latest.get(kind) != token

    def _run(self, lane: str) -> None:
        while True:
            with self._lock:
                while not self._waiting[lane] and not self._closed:
                    self._lock.wait()
                if self._closed:
                    return
                kind = next(iter(self._waiting[lane]))
                job = self._waiting[lane].pop(kind)
            cancelled = lambda job=job: self.stale(job.kind, job.token)  # noqa: E731
            try:
                result = job.work(cancelled)
            except SupersededError:
                continue
            except Exception as exc:  # the page shows it as a message; the server goes on
                if not cancelled():
                    self.deliver(lambda job=job, exc=exc: job.failed(exc))
                continue
            if not cancelled():
                self.deliver(lambda job=job, result=result: job.done(result))

    def close(self, timeout: float = 5.0) -> None:
        """Supersede everything, let the workers stop (waiting at most ``timeout`` seconds for each)."""
        with self._lock:
            self._closed = True
            self._lock.notify_all()
        for t in self._threads.values():
            if t is not threading.current_thread():
                t.join(timeout)
