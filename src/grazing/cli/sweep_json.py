"""A sweep's ``--json`` samples, encoded chunk by chunk while the threads compute the next chunks.

The ``samples`` key (each point's samples of the first state, the points sorted
by value) is most of a sweep's JSON text: 32000 points of 100 periods are 3.2
million numbers, 0.2 s to gather and encode after the last point, a serial part
of every sweep (issue 29).  :class:`JsonMemoryStore` keeps the results in memory
as :class:`~grazing.sweeps.store.MemoryStore` does and encodes each chunk's rows
when the chunk is written (while the threads compute); at the end the encoded
runs are written one after the other (:meth:`SampleRows.text`,
:class:`~grazing.cli.common.JsonText`).  The text is the one encoding the whole
array at the end gives, byte for byte.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import orjson

from grazing.cli.common import JsonText
from grazing.sweeps.spec import ChunkResult, SweepSpec
from grazing.sweeps.store import MemoryStore


@dataclass(frozen=True)
class _Run:
    """A chunk's rows in the JSON: where they start among the sorted points, how many, their text."""

    start: int
    size: int
    text: bytes  # (the rows, without the list's brackets)


class SampleRows:
    """The JSON text of the points' first-state samples, sorted by value within each chain of ``spec``.

    Examples
    --------
    >>> import grazing
    >>> from grazing.sweeps.spec import sweep_spec
    >>> from grazing.core.options import SweepSettings
    >>> spec = sweep_spec(grazing.models.pendulum("B"), "eta", [0.4, 0.41, 0.42], direction="down",
    ...                   settings=SweepSettings(chunk_size=2, periods=2))
    >>> rows = SampleRows(spec)
    >>> rows.add(0, np.array([[[4.0, 0.0], [4.5, 0.0]], [[3.0, 0.0], [np.nan, 0.0]]]))  # 0.42, 0.41
    >>> rows.text(0) is None  # (not every chunk yet)
    True
    >>> rows.add(1, np.array([[[2.0, 0.0], [2.5, 0.0]]]))  # 0.40
    >>> b"".join(rows.text(0).pieces)
    b'[[2.0,2.5],[3.0,null],[4.0,4.5]]'
    """

    def __init__(self, spec: SweepSpec) -> None:
        self.spec = spec
        self._rank: np.ndarray | None = None  # (each point's place in the JSON's lists: at the first chunk)
        self._runs: dict[int, _Run] = {}

    def _places(self) -> np.ndarray:
        if self._rank is None:
            spec, n = self.spec, self.spec.segment_points
            first = np.asarray(spec.points, dtype=float)[:, 0]
            self._rank = np.empty(spec.n_points, dtype=np.int64)
            for s in range(spec.segments):
                by_value = np.argsort(first[s * n : (s + 1) * n], kind="stable")  # (as the JSON sorts them)
                self._rank[s * n + by_value] = s * n + np.arange(n)
        return self._rank

    def add(self, index: int, samples: np.ndarray) -> None:
        """Encode the samples (points x periods x states) of chunk ``index`` (again: replaced)."""
        place = self._places()[self.spec.chunk(index)]
        step = int(place[1] - place[0]) if place.size > 1 else 1
        if abs(step) != 1 or np.any(np.diff(place) != step):  # (not one run of the sorted points)
            self._runs.pop(index, None)
            return
        rows = np.ascontiguousarray(samples[::step, :, 0])
        text = orjson.dumps(rows, option=orjson.OPT_SERIALIZE_NUMPY)
        self._runs[index] = _Run(int(place.min()), place.size, text[1:-1])

    def text(self, segment: int) -> JsonText | None:
        """The samples of chain ``segment`` as JSON, once every chunk of it is encoded (else None)."""
        n = self.spec.segment_points
        runs = sorted((r for r in self._runs.values() if segment * n <= r.start < (segment + 1) * n),
                      key=lambda r: r.start)  # fmt: skip
        at = segment * n
        for run in runs:
            if run.start != at:
                return None
            at += run.size
        if at != (segment + 1) * n:
            return None
        pieces = [b"["]
        for run in runs:
            pieces += [run.text, b","]
        pieces[-1] = b"]"
        return JsonText(tuple(pieces))


class JsonMemoryStore(MemoryStore):
    """A :class:`~grazing.sweeps.store.MemoryStore` encoding each chunk's samples (:class:`SampleRows`)."""

    def __init__(self, spec: SweepSpec) -> None:
        super().__init__(spec)
        self.rows = SampleRows(spec)

    def write(self, res: ChunkResult) -> None:
        super().write(res)
        self.rows.add(res.index, res.samples)  # (what the store now holds: not self.arrays, which fills)
