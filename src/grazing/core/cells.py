"""Sampled points on a grid of cells: which aperiodic end states are on one attractor.

An aperiodic end state (no period detected in its stroboscopic samples) is
known only through its samples, and these are not reproducible: any rounding
difference moves them after a few periods.  What is reproducible is the set
they lie on.  As Attractors.jl's recurrences do, the samples are recorded on a
grid of cells, and end states whose samples share a cell (directly, or through
other end states) are on one attractor.  The basins' classifier
(:class:`grazing.attractors.classify.Catalogue`) groups its end states so, and
a sweep's chain check (:mod:`grazing.sweeps.chain`) decides so whether a chunk
computed from a guess is on the chain's attractor.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CellGroups:
    """Point sets grouped by the cells they share.

    Attributes
    ----------
    keys
        The distinct cells the points fall in, one key (bytes of the cell's integer indices) each.
    cell_of
        The index in ``keys`` of each point's cell.
    group
        The group of each set: sets sharing a cell, directly or through other sets, are in one group.
    """

    keys: np.ndarray
    cell_of: np.ndarray
    group: np.ndarray

    def cells_of(self, owner: np.ndarray, sets: np.ndarray) -> set[bytes]:
        """The keys of the cells that the points of ``sets`` (``owner`` giving each point's set) fall in."""
        return {bytes(self.keys[u]) for u in np.unique(self.cell_of[np.isin(owner, sets)])}


def group_by_cells(
    points: np.ndarray, owner: np.ndarray, n_sets: int, origin: np.ndarray, cell: np.ndarray
) -> CellGroups:
    """Group ``n_sets`` point sets (``points``, one row each, in set ``owner[k]``) by the cells they share.

    The cells are boxes of size ``cell`` (per component) on a grid with a corner at ``origin``.

    Examples
    --------
    >>> pts = np.array([[0.1, 0.1], [0.2, 0.3], [5.0, 5.0], [0.9, 0.9], [5.2, 5.5]])
    >>> g = group_by_cells(pts, np.array([0, 0, 1, 2, 3]), 4, np.zeros(2), np.ones(2))
    >>> g.group.tolist()   # sets 0 and 2 share the cell [0, 1)^2, sets 1 and 3 the cell [5, 6)^2
    [0, 1, 0, 1]
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    points = np.asarray(points, dtype=float)
    keys = cell_keys(points, origin, cell)
    ukeys, cell_of = np.unique(keys, return_inverse=True)
    cell_of = cell_of.ravel()
    size = n_sets + ukeys.size
    graph = coo_matrix((np.ones(points.shape[0]), (np.asarray(owner), n_sets + cell_of)), shape=(size, size))
    _, comp = connected_components(graph, directed=False)
    return CellGroups(ukeys, cell_of, comp[:n_sets])


def cell_keys(points: np.ndarray, origin: np.ndarray, cell: np.ndarray) -> np.ndarray:
    """The key of the cell each point (row) of ``points`` falls in, on the grid of boxes of size ``cell`` with
    a corner at ``origin``: the bytes of its integer coordinates (one value per point, comparable).

    Examples
    --------
    >>> k = cell_keys(np.array([[0.1, 0.1], [0.9, 0.2], [1.1, 0.1]]), np.zeros(2), np.ones(2))
    >>> bool(k[0] == k[1]), bool(k[0] == k[2])
    (True, False)
    """
    q = np.floor((np.asarray(points, dtype=float) - origin) / cell).astype(np.int64)
    return np.ascontiguousarray(q).view(np.dtype((np.void, 8 * q.shape[1]))).ravel()


def box_cell(points: np.ndarray, cells: int) -> np.ndarray:
    """The cell size per component of a grid of ``cells`` cells along each side of the box of ``points``.

    Where the box is flat, the cell is the largest of the others (``1 / cells`` if it is a point).

    Examples
    --------
    >>> box_cell(np.array([[0.0, -1.0, 5.0], [1.0, 1.0, 5.0]]), 64) * 64
    array([1., 2., 2.])
    """
    span = np.ptp(np.asarray(points, dtype=float), axis=0) / cells
    fallback = float(span.max()) if span.max() > 0 else 1.0 / cells
    return np.where(span > 0, span, fallback)


def one_attractor(a: np.ndarray, b: np.ndarray, cells: int) -> bool:
    """Whether the samples ``a`` and ``b`` (one row per sampled state) of two aperiodic end states are on one
    attractor: they share a cell of the grid of ``cells`` cells along each side of their joint box.

    Examples
    --------
    >>> k = np.arange(200.0)
    >>> ring = np.stack([np.cos(k), np.sin(k)], 1)        # samples on a circle...
    >>> one_attractor(ring[:100], ring[100:], 64), one_attractor(ring, 0.5 * ring, 64)
    (True, False)
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.size == 0 or b.size == 0 or not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return False
    points = np.concatenate([a, b])
    keys = cell_keys(points, points.min(axis=0), box_cell(points, cells))
    return bool(np.intersect1d(keys[: a.shape[0]], keys[a.shape[0] :]).size)  # (two sets: one shared cell)
