"""The event queue: an indexed binary min-heap holding exactly one entry per disk.

Each disk owns one scheduled event (``event_time[i]``); the heap orders disk ids by that time.
A disk's entry is moved in place when its prediction changes, so the queue never grows beyond
N entries and never needs the rebuild that a heap of all predicted pairs needs.

Arrays: ``heap: int32[n]`` (disk id in each slot), ``slot: int32[n]`` (slot of each disk),
``event_time: float64[n]``.
"""

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _sift_up(heap, slot, event_time, k):
    disk = heap[k]
    t = event_time[disk]
    while k > 0:
        parent = (k - 1) >> 1
        above = heap[parent]
        if event_time[above] <= t:
            break
        heap[k] = above
        slot[above] = k
        k = parent
    heap[k] = disk
    slot[disk] = k


@njit(cache=True, inline="always")
def _sift_down(heap, slot, event_time, k):
    n = heap.shape[0]
    disk = heap[k]
    t = event_time[disk]
    while True:
        child = 2 * k + 1
        if child >= n:
            break
        right = child + 1
        if right < n and event_time[heap[right]] < event_time[heap[child]]:
            child = right
        below = heap[child]
        if event_time[below] >= t:
            break
        heap[k] = below
        slot[below] = k
        k = child
    heap[k] = disk
    slot[disk] = k


@njit(cache=True, inline="always")
def reschedule(heap, slot, event_time, disk):
    """Restore heap order after ``event_time[disk]`` changed; O(log n)."""
    k = slot[disk]
    if k > 0 and event_time[disk] < event_time[heap[(k - 1) >> 1]]:
        _sift_up(heap, slot, event_time, k)
    else:
        _sift_down(heap, slot, event_time, k)


@njit(cache=True)
def build_heap(heap, slot, event_time):
    """Fill the heap with every disk and heapify in O(n)."""
    n = heap.shape[0]
    for i in range(n):
        heap[i] = i
        slot[i] = i
    for k in range(n // 2 - 1, -1, -1):
        _sift_down(heap, slot, event_time, k)


def empty_queue(n):
    """Allocate the heap arrays for ``n`` disks."""
    return np.zeros(n, dtype=np.int32), np.zeros(n, dtype=np.int32)
