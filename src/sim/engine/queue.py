"""The event queue: a calendar queue holding exactly one entry per disk.

After Smallenburg, Eur. Phys. J. E 45, 22 (2022) (a variant of the O(1) queue of Paul,
J. Comput. Phys. 221, 615 (2007)). Time is cut into blocks of width ``w``; the event of disk i
lies in block ``k = floor(event_time[i] / w)``. With ``k0`` the current block and
``year_end`` the first block not covered by the buckets:

  * events with ``k ≤ k0`` sit in a small indexed binary min-heap, ordered by time;
  * events with ``k0 < k < year_end`` sit unsorted in bucket ``k mod B`` (B a power of two,
    ``year_end - B ≤ k0``, so each bucket holds one block): doubly linked lists threaded
    through disk ids, O(1) insertion and removal;
  * events with ``k ≥ year_end`` (and ``inf``) sit in the overflow list.

Every heap event precedes every listed one, so the heap top is the earliest event. When the
heap empties the next non-empty bucket becomes the current block and is heapified; when the
buckets are used up a new year of B blocks starts at the earliest overflow event and the
overflow list is filed anew. The queue is rebuilt (and ``w`` re-estimated) at every clock
rebase, so ``w`` follows a gas that cools or heats. With
``w`` a few mean times between events the heap stays small and a reschedule costs O(1) on
average instead of the O(log n) of a heap of all disks.

Arrays (n disks, B buckets):
  ``heap int32[n]`` — disk ids, the first ``calendar[HEAP_SIZE]`` form the heap;
  ``links int32[n, 3]`` — per disk: heap slot (``NOT_IN_HEAP`` when listed), next and previous
  disk of its list (``-1`` at the end; the previous of a list head is ``-1 - list``, the list
  being a bucket ``0 … B-1`` or the overflow list ``B``);
  ``list_head int32[B + 1]``;
  ``calendar int64[3]`` — heap size, current block ``k0``, ``year_end``;
  ``block_rate float64[1]`` — ``1 / w``.
"""

import numpy as np
from numba import njit

from sim.engine.prefetch import prefetch

# columns of ``links``
SLOT = 0
NEXT = 1
PREV = 2
NOT_IN_HEAP = -1

# entries of ``calendar``
HEAP_SIZE = 0
CURRENT_BLOCK = 1
YEAR_END = 2

#: Block width in mean times between events. With 8 instead of 4 the heap holds more of
#: the next events and is refilled half as often, which gives the prefetching of
#: :func:`sim.engine.lookahead.prefetch_upcoming` more to work ahead on: 1.09 at N = 1e5
#: (φ = 0.5, ``benchmarks/compare_builds.py``, 16 rounds), 16 gave 1.08; 0.99 at 1e4.
BLOCK_EVENTS = 8.0
#: Buckets per disk (rounded up to a power of two).
BUCKETS_PER_DISK = 1.0


@njit(cache=True, inline="always")
def _sift_up(heap, links, event_time, k):
    disk = heap[k]
    t = event_time[disk]
    while k > 0:
        parent = (k - 1) >> 1
        above = heap[parent]
        if event_time[above] <= t:
            break
        heap[k] = above
        links[above, SLOT] = k
        k = parent
    heap[k] = disk
    links[disk, SLOT] = k


@njit(cache=True, inline="always")
def _sift_down(heap, links, event_time, k, size):
    disk = heap[k]
    t = event_time[disk]
    while True:
        child = 2 * k + 1
        if child >= size:
            break
        right = child + 1
        if right < size and event_time[heap[right]] < event_time[heap[child]]:
            child = right
        below = heap[child]
        if event_time[below] >= t:
            break
        heap[k] = below
        links[below, SLOT] = k
        k = child
    heap[k] = disk
    links[disk, SLOT] = k


@njit(cache=True, inline="always")
def _heap_remove(heap, links, event_time, calendar, disk):
    k = links[disk, SLOT]
    size = calendar[HEAP_SIZE] - 1
    calendar[HEAP_SIZE] = size
    links[disk, SLOT] = NOT_IN_HEAP
    if k == size:
        return
    last = heap[size]
    heap[k] = last
    links[last, SLOT] = k
    if k > 0 and event_time[last] < event_time[heap[(k - 1) >> 1]]:
        _sift_up(heap, links, event_time, k)
    else:
        _sift_down(heap, links, event_time, k, size)


@njit(cache=True, inline="always")
def _list_push(links, list_head, disk, which):
    head = list_head[which]
    links[disk, NEXT] = head
    links[disk, PREV] = -1 - which
    if head >= 0:
        links[head, PREV] = disk
    list_head[which] = disk


@njit(cache=True, inline="always")
def _list_unlink(links, list_head, disk):
    nxt = links[disk, NEXT]
    prv = links[disk, PREV]
    if prv >= 0:
        links[prv, NEXT] = nxt
    else:
        list_head[-1 - prv] = nxt
    if nxt >= 0:
        links[nxt, PREV] = prv


@njit(cache=True, inline="always")
def _insert(heap, links, list_head, calendar, block_rate, event_time, disk):
    """File a disk that is in no structure according to its event time."""
    t = event_time[disk]
    block = t * block_rate[0]
    if block >= calendar[YEAR_END]:  # also inf
        _list_push(links, list_head, disk, list_head.shape[0] - 1)
        return
    k = np.int64(block)
    if k <= calendar[CURRENT_BLOCK]:
        size = calendar[HEAP_SIZE]
        heap[size] = disk
        calendar[HEAP_SIZE] = size + 1
        _sift_up(heap, links, event_time, size)
    else:
        links[disk, SLOT] = NOT_IN_HEAP
        _list_push(links, list_head, disk, k & (list_head.shape[0] - 2))


@njit(cache=True, inline="always")
def reschedule(heap, links, list_head, calendar, block_rate, event_time, disk):
    """Move the entry of ``disk`` after ``event_time[disk]`` changed; O(1) on average."""
    k = links[disk, SLOT]
    if k != NOT_IN_HEAP:
        t = event_time[disk]
        if t * block_rate[0] < calendar[CURRENT_BLOCK] + 1:  # still in the current block
            if k > 0 and t < event_time[heap[(k - 1) >> 1]]:
                _sift_up(heap, links, event_time, k)
            else:
                _sift_down(heap, links, event_time, k, calendar[HEAP_SIZE])
            return
        _heap_remove(heap, links, event_time, calendar, disk)
    else:
        _list_unlink(links, list_head, disk)
    _insert(heap, links, list_head, calendar, block_rate, event_time, disk)


@njit(cache=True, inline="always")
def prefetch_bucket(list_head, calendar, block_rate, t):
    """Hint the cache for the head of the bucket that filing an event at time t reads
    (:func:`reschedule`). A new event may fall in any of the B ≈ N buckets, whose heads
    (int32[B + 1]) are mostly out of cache at large N; events beyond the year are not hinted."""
    block = t * block_rate[0]
    if calendar[CURRENT_BLOCK] < block < calendar[YEAR_END]:
        prefetch(list_head, np.int64(block) & (list_head.shape[0] - 2))


@njit(cache=True, inline="always")
def prefetch_next_block(walker, walker_block, links, list_head, calendar, event_time):
    """Walk the bucket of the block after the current one, one disk per call, and hint the
    cache for the links and event time of each, so that they are at hand when that bucket
    becomes the heap (:func:`_refill_heap` walks the bucket and sifts by event time).

    ``walker`` is the disk reached (-1: none), ``walker_block`` the block walked; returns both
    updated. Each step reads the links the previous call asked for. A disk that leaves the
    bucket meanwhile leads the walk astray, which costs a useless hint and nothing else.
    """
    next_block = calendar[CURRENT_BLOCK] + 1
    if next_block != walker_block:
        walker_block = next_block
        walker = list_head[next_block & (list_head.shape[0] - 2)]
    elif walker >= 0:
        walker = links[walker, NEXT]
    if walker >= 0:
        prefetch(links, walker)
        prefetch(event_time, walker)
    return walker, walker_block


@njit(cache=True, _nrt=False, error_model="numpy")
def _next_year(heap, links, list_head, calendar, block_rate, event_time):
    """All buckets are empty: start the year at the earliest overflow event, file the
    overflow list anew. Returns False when every event is at infinity."""
    overflow = list_head.shape[0] - 1
    n_buckets = overflow
    earliest = np.inf
    disk = list_head[overflow]
    while disk >= 0:
        earliest = min(earliest, event_time[disk])
        disk = links[disk, NEXT]
    if earliest == np.inf:
        return False
    first = max(np.int64(min(earliest * block_rate[0], 2.0**62)), calendar[YEAR_END])
    calendar[CURRENT_BLOCK] = first - 1
    calendar[YEAR_END] = first + n_buckets
    disk = list_head[overflow]
    list_head[overflow] = -1
    while disk >= 0:
        nxt = links[disk, NEXT]
        _insert(heap, links, list_head, calendar, block_rate, event_time, disk)
        disk = nxt
    return True


@njit(cache=True, inline="always")
def earliest(heap, links, list_head, calendar, block_rate, event_time):
    """The disk with the earliest event (its entry stays queued); when every event is at
    infinity, some disk whose event time is ``inf``."""
    if calendar[HEAP_SIZE] == 0:
        _refill_heap(heap, links, list_head, calendar, block_rate, event_time)
    if calendar[HEAP_SIZE] == 0:
        return list_head[list_head.shape[0] - 1]
    return heap[0]


@njit(cache=True, _nrt=False, error_model="numpy")
def _refill_heap(heap, links, list_head, calendar, block_rate, event_time):
    """Make the next non-empty block the current one and heapify its events."""
    mask = list_head.shape[0] - 2
    while True:
        k = calendar[CURRENT_BLOCK] + 1
        year_end = calendar[YEAR_END]
        while k < year_end and list_head[k & mask] < 0:
            k += 1
        if k < year_end:
            break
        if not _next_year(heap, links, list_head, calendar, block_rate, event_time):
            return
    calendar[CURRENT_BLOCK] = k
    bucket = k & mask
    disk = list_head[bucket]
    list_head[bucket] = -1
    size = 0
    while disk >= 0:
        heap[size] = disk
        links[disk, SLOT] = size
        size += 1
        disk = links[disk, NEXT]
    calendar[HEAP_SIZE] = size
    for s in range(size // 2 - 1, -1, -1):
        _sift_down(heap, links, event_time, s, size)


@njit(cache=True, _nrt=False, error_model="numpy")
def build_queue(heap, links, list_head, calendar, block_rate, event_time, t_now):
    """File every disk anew, with the block width set to ``BLOCK_EVENTS`` mean times between
    events, estimated as the mean finite delay ``event_time - t_now`` over n; O(n).

    A queue built at the same times holds the same events as before, so this also serves
    after the clock rebase (all event times shifted)."""
    n = event_time.shape[0]
    total = 0.0
    finite = 0
    for i in range(n):
        if event_time[i] < np.inf:
            total += event_time[i] - t_now
            finite += 1
    mean_delay = total / finite if finite > 0 and total > 0.0 else 1.0
    block_rate[0] = n / (BLOCK_EVENTS * mean_delay)
    list_head[:] = -1
    k0 = np.int64(t_now * block_rate[0])
    calendar[HEAP_SIZE] = 0
    calendar[CURRENT_BLOCK] = k0
    calendar[YEAR_END] = k0 + list_head.shape[0] - 1
    for i in range(n):
        links[i, SLOT] = NOT_IN_HEAP
        _insert(heap, links, list_head, calendar, block_rate, event_time, i)


def empty_queue(n):
    """Allocate the calendar arrays for ``n`` disks: heap, links, list_head, calendar,
    block_rate."""
    n_buckets = 1 << max(6, int(np.ceil(np.log2(BUCKETS_PER_DISK * n))))
    return (np.zeros(n, dtype=np.int32), np.zeros((n, 3), dtype=np.int32),
            np.full(n_buckets + 1, -1, dtype=np.int32), np.zeros(3, dtype=np.int64),
            np.ones(1))
