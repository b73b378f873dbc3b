"""Islands grouped into partitions balanced by contact count (NumPy only).

The grouping decides only which worker solves which islands: every island is
solved whole, its contacts in the scene's solve order, so the result does
not depend on it (docs/distributed.md). It is deterministic, so that a run
can be repeated and explained:

1. Large islands (more than an eighth of the mean partition) first, largest
   first (ties: the lower label), each onto the least loaded partition (ties:
   the lower partition): the classic greedy for uneven sizes.
2. The small islands, in label order (the order of their first contacts),
   fill each partition up to the mean, partition after partition. Consecutive
   islands stay together, so a partition's contacts are runs of the scene's
   own order (a scene of independent pairs splits into contiguous ranges),
   which keeps a worker's reads of a mapped file sequential.

Every partition then holds at most the mean plus one small island, unless a
single island is larger than the mean: that island is one partition's
contacts, and nothing can split it.
"""

from __future__ import annotations

import heapq

import numpy as np

#: Islands above this fraction of the mean partition are placed one by one.
LARGE_FRACTION = 1 / 8


def partition_islands(sizes, partitions):
    """The partition of each island: an int array the length of ``sizes``
    (the contacts of each island, ``collide.islands(...).sizes``), values in
    ``[0, partitions)``. At most ``partitions`` are used, and no more than
    there are islands; some may stay empty when a few large islands hold
    everything. Deterministic: the same sizes give the same partitions."""
    sizes = np.asarray(sizes)
    if sizes.ndim != 1:
        raise ValueError(f"partition_islands: sizes must be 1-D, got shape {sizes.shape}")
    if int(partitions) < 1:
        raise ValueError(f"partition_islands: partitions must be >= 1, got {partitions}")
    count = len(sizes)
    parts = np.zeros(count, dtype=np.int64)
    p = max(1, min(int(partitions), count))
    if count == 0 or p == 1:
        return parts
    target = int(sizes.sum(dtype=np.int64)) / p
    large_ids = np.flatnonzero(sizes > target * LARGE_FRACTION)
    load = np.zeros(p, dtype=np.float64)
    if len(large_ids):
        # Largest first; a stable sort keeps the lower label first among equals.
        order = large_ids[np.argsort(-sizes[large_ids].astype(np.int64), kind="stable")]
        heap = [(0, k) for k in range(p)]
        for island in order:
            contacts, k = heapq.heappop(heap)
            parts[island] = k
            contacts += int(sizes[island])
            load[k] = contacts
            heapq.heappush(heap, (contacts, k))
    # The small islands (all of them, in a scene of many: no copy then).
    small_ids = slice(None) if len(large_ids) == 0 else np.flatnonzero(sizes <= target * LARGE_FRACTION)
    small = sizes[small_ids]
    if len(small):
        # Partition k takes the small islands whose first contact, counted
        # through the small islands in label order, falls in its share of
        # the room left below the mean: island i goes to the number of
        # shares that end at or before its start. The starts ascend, so
        # each share's first island is one binary search.
        room = np.maximum(target - load, 0.0)
        ends = np.cumsum(room)
        starts = np.cumsum(small, dtype=np.int64)
        starts -= small
        firsts = np.searchsorted(starts, ends[:p - 1], side="left")
        small_parts = np.repeat(np.arange(p, dtype=np.int64), np.diff(firsts, prepend=0, append=len(small)))
        parts[small_ids] = small_parts
    return parts


def single_contact_ends(count, partitions):
    """Where each partition's contacts end when every one of ``count``
    contacts is an island of its own (independent pairs: the islands'
    labels are then the contact rows), as :func:`partition_islands` groups
    them: equal shares of consecutive contacts, found in O(partitions)
    instead of arrays the length of the scene. None with fewer than eight
    contacts per partition, where every island counts as a large one and
    partition_islands deals them round the partitions."""
    p = max(1, min(int(partitions), count))
    if count == 0 or p == 1:
        return np.array([count], dtype=np.int64)
    target = count / p
    if 1 > target * LARGE_FRACTION:
        return None
    # partition_islands' shares: room ``target`` each, and island i (its
    # start i) goes to the number of shares ending at or before it, so share
    # k starts at the first integer not below its running end (searchsorted
    # of the ends among 0, 1, ..., count - 1).
    ends = np.cumsum(np.full(p, target))
    firsts = np.minimum(np.ceil(ends[:p - 1]), count).astype(np.int64)
    return np.append(firsts, np.int64(count))
