"""numba graph kernels: stoppable Dijkstra searches on a CSR graph and their drivers.

scipy's ``dijkstra`` returns a dense row of length n per source, even when bounded,
and starts from scratch each time: fine for a few hundred sources, not for the k-NN
search of every node (10^6 sources).  Two hand-written searches share one lazy
binary heap and touch only the nodes they reach (scratch is reset through the list
of touched nodes): :func:`settle` stops after enough *counted* nodes are settled
(k-NN rows; landmark-to-landmark rows, where scipy took 133 ms per source at 685k
nodes against 41 ms here with two threads, benchmarks/bench_landmarks.py), and
:func:`lower_distances` stops at every node it cannot improve (maxmin picks).
Landmark-to-landmark rows search with a bucket queue instead of the heap when every
edge weighs at least a fair share of the mean (:func:`settle_buckets`: the per-hop
cost h makes it so), with the same distances bit for bit, 2.5x faster
(benchmarks/bench_map.py).

Drivers run parallel over sources on numba's threads, or serially without the GIL in
a thread limited to one numba thread, so that the pipeline's window tasks can run
side by side in threads.

All drivers are deterministic: every source's search is independent, so the parallel
split over sources changes nothing but the time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import get_num_threads, njit, prange


@njit(cache=True)
def _sift_up(keys, nodes, i, key, node):
    """Place (key, node) at the hole ``i`` of the binary min-heap, moving it rootwards."""
    while i > 0:
        parent = (i - 1) >> 1
        if keys[parent] <= key:
            break
        keys[i] = keys[parent]
        nodes[i] = nodes[parent]
        i = parent
    keys[i] = key
    nodes[i] = node


@njit(cache=True)
def _heap_push(keys, nodes, size, key, node):
    """Insert (key, node) into the binary min-heap ``keys[:size]``; return the new size."""
    _sift_up(keys, nodes, size, key, node)
    return size + 1


@njit(cache=True)
def _heap_pop(keys, nodes, size):
    """Remove the root of the binary min-heap ``keys[:size]``; return the new size.

    Bottom-up (Floyd): the hole left by the root walks down to a leaf along the
    smaller children (a branch-free comparison per level), then the last element
    sifts up from there.  Measured 1.4x faster than a 4-ary heap here.
    """
    size -= 1
    key = keys[size]
    node = nodes[size]
    i = 0
    while True:
        child = 2 * i + 1
        if child + 1 < size:
            child += keys[child + 1] < keys[child]
        elif child >= size:
            break
        keys[i] = keys[child]
        nodes[i] = nodes[child]
        i = child
    _sift_up(keys, nodes, i, key, node)
    return size


@njit(cache=True)
def _relax(indptr, indices, weights, u, d, dist, bound, touched, n_touched, heap_keys, heap_nodes, size):
    """Relax the edges of ``u`` (settled at ``d``): push every neighbour v whose new
    distance beats both ``dist[v]`` and ``bound[v]`` (pass ``dist`` itself for no bound),
    recording first-reached nodes in ``touched``.  Returns (heap size, n_touched)."""
    for e in range(indptr[u], indptr[u + 1]):
        v = indices[e]
        nd = d + weights[e]
        if nd < dist[v] and nd < bound[v]:
            if dist[v] == np.inf:
                touched[n_touched] = v
                n_touched += 1
            dist[v] = nd
            size = _heap_push(heap_keys, heap_nodes, size, nd, v)
    return size, n_touched


@njit(cache=True)
def _restore(dist, touched, n_touched):
    """Reset the scratch ``dist`` to all +inf (only the touched entries changed)."""
    for i in range(n_touched):
        dist[touched[i]] = np.inf


@njit(cache=True)
def settle(indptr, indices, weights, source, count, stop_count,
           dist, touched, heap_keys, heap_nodes, found_node, found_dist):
    """Dijkstra from ``source``, settling nodes in order of distance.

    Every settled node ``u`` with ``count[u] > 0`` is appended to ``found_node`` / ``found_dist`` (so in
    non-decreasing distance order); the search stops as soon as the counts of the
    found nodes sum to ``>= stop_count``.

    Scratch: ``dist`` (n,) must be all +inf on entry and is all +inf again on exit;
    ``touched`` (n,) int64; ``heap_keys`` / ``heap_nodes`` of length ``nnz + 1``
    (the lazy heap holds at most one entry per strict improvement).

    Returns
    -------
    int
        Number of found nodes.
    """
    n_found = 0
    counted = 0
    dist[source] = 0.0
    touched[0] = source
    n_touched = 1
    size = _heap_push(heap_keys, heap_nodes, 0, 0.0, source)
    while size > 0:
        d = heap_keys[0]
        u = heap_nodes[0]
        size = _heap_pop(heap_keys, heap_nodes, size)
        if d > dist[u]:
            continue  # stale entry: u was settled at a smaller distance
        if count[u] > 0:
            found_node[n_found] = u
            found_dist[n_found] = d
            n_found += 1
            counted += count[u]
            if counted >= stop_count:
                break
        size, n_touched = _relax(indptr, indices, weights, u, d, dist, dist, touched, n_touched,
                                 heap_keys, heap_nodes, size)
    _restore(dist, touched, n_touched)
    return n_found


@njit(cache=True, nogil=True)
def lower_distances(indptr, indices, weights, source, to_set, dist, touched, heap_keys, heap_nodes, limit):
    """Lower ``to_set[x]`` to d(source, x) wherever that is smaller and at most ``limit``, in place.

    ``to_set`` holds d(x, L) for a landmark set L; ``source`` joins L.  The search
    expands a node v only while d(source, v) < to_set[v]: past such a v nothing can
    improve, since d(source, x) = d(source, v) + d(v, x) >= d(v, L) + d(v, x) >= d(x, L)
    (triangle inequality).  So it is exact and touches only the new landmark's
    Voronoi cell -- on hub-heavy graphs (static agents) a few nodes instead of most
    of the graph.  It stops at distances above ``limit`` (+inf: none).

    With a finite ``limit`` the argument holds on a weaker invariant: ``to_set[x]`` =
    d(x, L) wherever d(x, L) <= ``limit``, and ``to_set[x]`` >= d(x, L) elsewhere.  A
    node on a shortest path from ``source`` to a node it improves within ``limit`` is
    itself improved within ``limit``, so it is never cut off; the invariant holds
    after the call with ``limit`` (or any smaller bound) for L + {source}.  Scratch
    arrays as in :func:`settle`.  Returns the nodes settled.
    """
    dist[source] = 0.0
    touched[0] = source
    n_touched = 1
    settled = 0
    size = _heap_push(heap_keys, heap_nodes, 0, 0.0, source)
    while size > 0:
        d = heap_keys[0]
        u = heap_nodes[0]
        size = _heap_pop(heap_keys, heap_nodes, size)
        if d > limit:
            break  # every entry left is farther
        if d > dist[u]:
            continue
        to_set[u] = d
        settled += 1
        size, n_touched = _relax(indptr, indices, weights, u, d, dist, to_set, touched, n_touched,
                                 heap_keys, heap_nodes, size)
    _restore(dist, touched, n_touched)
    return settled


class Searcher:
    """Scratch arrays for repeated :func:`lower_distances` calls on one graph (single thread)."""

    def __init__(self, indptr, indices, weights):
        n = len(indptr) - 1
        self.indptr, self.indices, self.weights = indptr, indices, weights
        self.dist = np.full(n, np.inf)
        self.touched = np.empty(n, np.int64)
        self.heap_keys = np.empty(len(weights) + 1)
        self.heap_nodes = np.empty(len(weights) + 1, np.int64)

    def add_landmark(self, source: int, to_set: np.ndarray, limit: float = np.inf) -> int:
        """Lower ``to_set`` (d(x, L)) for L + {source} up to ``limit``; see :func:`lower_distances`."""
        return lower_distances(self.indptr, self.indices, self.weights, source, to_set, self.dist,
                               self.touched, self.heap_keys, self.heap_nodes, float(limit))


@njit(cache=True, nogil=True)
def _knn_block(indptr, indices, weights, multiplicity, k, block, n_blocks, out):
    """k-NN rows of the nodes block, block + n_blocks, ... into ``out``."""
    n = len(indptr) - 1
    dist = np.full(n, np.inf)
    touched = np.empty(n, np.int64)
    heap_keys = np.empty(len(weights) + 1)
    heap_nodes = np.empty(len(weights) + 1, np.int64)
    found_node = np.empty(k + 1, np.int64)
    found_dist = np.empty(k + 1)
    for x in range(block, n, n_blocks):
        # stop once x's own points plus k others are settled: each node counts its
        # multiplicity, so at most k + 1 nodes are found
        n_found = settle(indptr, indices, weights, x, multiplicity, k + 1,
                         dist, touched, heap_keys, heap_nodes, found_node, found_dist)
        filled = 0
        for j in range(n_found):
            copies = multiplicity[found_node[j]] - (1 if j == 0 else 0)  # j == 0 is x
            for _ in range(copies):
                if filled == k:
                    break
                out[x, filled] = found_dist[j]
                filled += 1


@njit(cache=True, parallel=True)
def _knn_rows_parallel(indptr, indices, weights, multiplicity, k, n_blocks):
    out = np.full((len(indptr) - 1, k), np.inf)
    for block in prange(n_blocks):
        _knn_block(indptr, indices, weights, multiplicity, k, block, n_blocks, out)
    return out


@njit(cache=True, nogil=True)
def _knn_rows_serial(indptr, indices, weights, multiplicity, k):
    out = np.full((len(indptr) - 1, k), np.inf)
    _knn_block(indptr, indices, weights, multiplicity, k, 0, 1, out)
    return out


def knn_rows(indptr, indices, weights, multiplicity, k: int) -> np.ndarray:
    """``(n, k)`` distances from every node to its k nearest other points (see landmarks).

    Parallel over nodes on numba's threads; in a thread limited to one numba thread
    (``numba.set_num_threads(1)``, as the pipeline's window tasks are), serial and
    without the GIL, so that tasks run side by side in threads."""
    if get_num_threads() == 1:
        return _knn_rows_serial(indptr, indices, weights, multiplicity, k)
    return _knn_rows_parallel(indptr, indices, weights, multiplicity, k, get_num_threads())


# -- landmark-to-landmark rows: a bucket queue where the weights allow it -------------
BUCKET_SPREAD = 32.0
"""Largest mean / least edge weight for which the searches use buckets: each search
steps through about (eccentricity / bucket width) buckets, so the ratio bounds the
empty buckets it scans per settled hop."""
MAX_BUCKETS = 1 << 20
"""Most buckets of the circular bucket array (the longest edge over the bucket width)."""


def bucket_layout(weights: np.ndarray) -> tuple[float, int]:
    """(bucket width, number of buckets) of :func:`settle_buckets` on these edge weights
    (all > 0), or (0, 0) when the heap search is the better choice.

    The width is half the least weight: a node settled at d relaxes its neighbours to
    at least d + 2 x width, at least one whole bucket on even after rounding, so every
    node left in the lowest non-empty bucket is already final.  The live entries then
    span at most ceil(longest / width) + 2 consecutive buckets; the circular array holds
    one more than that, rounded up to a power of two (its index is a bit mask)."""
    if not len(weights):
        return 0.0, 0
    least, longest = float(weights.min()), float(weights.max())
    if not float(weights.mean()) <= BUCKET_SPREAD * least:  # also catches overflow to inf
        return 0.0, 0
    width = least / 2
    needed = math.ceil(longest / width) + 3
    if needed > MAX_BUCKETS:
        return 0.0, 0
    return width, 1 << (needed - 1).bit_length()


@njit(cache=True, nogil=True)
def settle_buckets(indptr, indices, weights, source, is_target, n_targets, width, n_buckets,
                   dist, touched, head, entry_next, entry_node, entry_key, found_node, found_dist):
    """Dijkstra from ``source`` until the ``n_targets`` nodes with ``is_target`` are settled,
    with a circular bucket queue (Dial's) of ``n_buckets`` buckets ``width`` wide
    (:func:`bucket_layout`: a power of two) instead of a heap.

    Each bucket is a linked list of (node, key) entries, one per strict improvement (a
    lazy queue, as :func:`settle`'s heap).  Every node in the lowest non-empty bucket
    is final (no edge is shorter than two widths), so a bucket's nodes are settled in
    any order.  Each final distance is the least of fl(d(u) + w(u, v)) over the final
    distances of its neighbours, as in any label-setting search, so the distances are
    bit for bit those of :func:`settle`; the found nodes come in bucket order, not in
    distance order.  Scratch as in :func:`settle`, plus ``head`` (n_buckets,) all -1 on
    entry and exit and entries of length nnz + 1.  Returns the number of found nodes.
    """
    n_found = 0
    inverse = 1.0 / width
    mask = n_buckets - 1
    dist[source] = 0.0
    touched[0] = source
    n_touched = 1
    entry_node[0] = source
    entry_key[0] = 0.0
    entry_next[0] = -1
    head[0] = 0
    n_entries = 1
    live = 1
    bucket = 0
    while live > 0:
        slot = bucket & mask
        e = head[slot]
        if e < 0:
            bucket += 1
            continue
        head[slot] = entry_next[e]
        live -= 1
        u = entry_node[e]
        d = entry_key[e]
        if d > dist[u]:
            continue  # stale entry
        if is_target[u]:
            found_node[n_found] = u
            found_dist[n_found] = d
            n_found += 1
            if n_found == n_targets:
                break
        for k in range(indptr[u], indptr[u + 1]):
            v = indices[k]
            nd = d + weights[k]
            if nd < dist[v]:
                if dist[v] == np.inf:
                    touched[n_touched] = v
                    n_touched += 1
                dist[v] = nd
                b = np.int64(nd * inverse) & mask
                entry_node[n_entries] = v
                entry_key[n_entries] = nd
                entry_next[n_entries] = head[b]
                head[b] = n_entries
                n_entries += 1
                live += 1
    _restore(dist, touched, n_touched)
    for i in range(n_buckets):
        head[i] = -1
    return n_found


@njit(cache=True, nogil=True)
def _rows_block(indptr, indices, weights, sources, targets, is_target, column, width, n_buckets,
                block, n_blocks, out):
    """Rows block, block + n_blocks, ... of :func:`rows_to_targets` into ``out``."""
    n = len(indptr) - 1
    n_targets = len(targets)
    dist = np.full(n, np.inf)
    touched = np.empty(n, np.int64)
    found_node = np.empty(n_targets, np.int64)
    found_dist = np.empty(n_targets)
    m = len(weights) + 1
    if n_buckets > 0:
        head = np.full(n_buckets, -1, np.int64)
        entry_next = np.empty(m, np.int64)
        entry_node = np.empty(m, np.int64)
        entry_key = np.empty(m)
    else:
        heap_keys = np.empty(m)
        heap_nodes = np.empty(m, np.int64)
    for i in range(block, len(sources), n_blocks):
        if n_buckets > 0:
            n_found = settle_buckets(indptr, indices, weights, sources[i], is_target, n_targets, width, n_buckets,
                                     dist, touched, head, entry_next, entry_node, entry_key, found_node, found_dist)
        else:
            n_found = settle(indptr, indices, weights, sources[i], is_target, n_targets,
                             dist, touched, heap_keys, heap_nodes, found_node, found_dist)
        for j in range(n_found):
            out[i, column[found_node[j]]] = found_dist[j]


@njit(cache=True, nogil=True)
def _target_columns(n, targets):
    column = np.full(n, -1, np.int64)
    is_target = np.zeros(n, np.int64)
    for j in range(len(targets)):
        column[targets[j]] = j
        is_target[targets[j]] = 1
    return column, is_target


@njit(cache=True, parallel=True)
def _rows_parallel(indptr, indices, weights, sources, targets, width, n_buckets, n_blocks):
    column, is_target = _target_columns(len(indptr) - 1, targets)
    out = np.full((len(sources), len(targets)), np.inf)
    for block in prange(n_blocks):
        _rows_block(indptr, indices, weights, sources, targets, is_target, column, width, n_buckets,
                    block, n_blocks, out)
    return out


@njit(cache=True, nogil=True)
def _rows_serial(indptr, indices, weights, sources, targets, width, n_buckets):
    column, is_target = _target_columns(len(indptr) - 1, targets)
    out = np.full((len(sources), len(targets)), np.inf)
    _rows_block(indptr, indices, weights, sources, targets, is_target, column, width, n_buckets, 0, 1, out)
    return out


@njit(cache=True, nogil=True)
def symmetrize_min(matrix):
    """In place: matrix[i, j] = matrix[j, i] = min of the two; zero diagonal."""
    for i in range(matrix.shape[0]):
        matrix[i, i] = 0.0
        for j in range(i + 1, matrix.shape[0]):
            low = min(matrix[i, j], matrix[j, i])
            matrix[i, j] = low
            matrix[j, i] = low
    return matrix


def rows_to_targets(indptr, indices, weights, sources, targets, *, buckets: bool = True) -> np.ndarray:
    """``(len(sources), len(targets))`` exact distances; each search stops at the last target.

    ``targets`` must be distinct.  Searches use a bucket queue when the weights suit
    one (:func:`bucket_layout`; ``buckets=False``: always the heap), with the same
    distances bit for bit.  Parallel over sources on numba's threads; serial and
    without the GIL in a thread limited to one numba thread (see :func:`knn_rows`).
    """
    width, n_buckets = bucket_layout(weights) if buckets else (0.0, 0)
    if get_num_threads() == 1:
        return _rows_serial(indptr, indices, weights, sources, targets, width, n_buckets)
    return _rows_parallel(indptr, indices, weights, sources, targets, width, n_buckets, get_num_threads())
