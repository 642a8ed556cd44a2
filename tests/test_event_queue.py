"""The calendar queue stays what :mod:`sim.engine.queue` says it is while the engine runs:
a valid heap of the current block's events, every other event in the bucket of its block or
in the overflow list, each disk queued exactly once, and no listed event before a heap event.
"""

import math

import numpy as np
import pytest

from sim.engine import Boundary, Engine
from sim.engine.queue import CURRENT_BLOCK, HEAP_SIZE, NEXT, NOT_IN_HEAP, PREV, SLOT, YEAR_END
from sim.pipeline.initial import fixed_speed, random_sequential


def assert_queue_consistent(disks):
    """Check the queue of an engine's state; returns the numbers of heap and overflow events."""
    heap, links, list_head, calendar, block_rate = disks.queue
    event_time = disks.event_time
    size = int(calendar[HEAP_SIZE])
    current_block = int(calendar[CURRENT_BLOCK])
    year_end = int(calendar[YEAR_END])
    n_buckets = list_head.shape[0] - 1  # also the index of the overflow list
    in_heap = heap[:size]
    for k in range(size):
        assert links[in_heap[k], SLOT] == k
        assert math.floor(event_time[in_heap[k]] * block_rate[0]) <= current_block
        if k > 0:
            assert event_time[in_heap[k]] >= event_time[in_heap[(k - 1) // 2]]
    listed = []
    in_overflow = 0
    for bucket in range(n_buckets + 1):
        disk, previous = list_head[bucket], -1 - bucket
        while disk >= 0:
            assert links[disk, SLOT] == NOT_IN_HEAP and links[disk, PREV] == previous
            block = event_time[disk] * block_rate[0]
            if bucket == n_buckets:
                assert block >= year_end
                in_overflow += 1
            else:
                assert current_block < math.floor(block) < year_end
                assert math.floor(block) % n_buckets == bucket
            listed.append(disk)
            disk, previous = links[disk, NEXT], disk
    queued = np.concatenate([in_heap, np.array(listed, dtype=in_heap.dtype)])
    assert np.array_equal(np.sort(queued), np.arange(event_time.shape[0]))
    if size and listed:
        assert event_time[in_heap].max() <= event_time[listed].min()
    return size, in_overflow


@pytest.mark.parametrize("periodic, lookahead", [
    ((True, True), False), ((False, False), False), ((True, False), True)])
def test_queue_stays_consistent(periodic, lookahead):
    """Checked after every chunk of a run of 500 equal disks at φ ≈ 0.23, a third of them
    fast (so that the heap, the buckets and the overflow list are all in use), with and without
    the look-ahead hints."""
    n = 500
    radius = np.full(n, 0.012)
    position = random_sequential(radius, periodic=periodic, seed=2)
    velocity = fixed_speed(n, 1.0, seed=3)
    velocity[::3] *= 20.0
    engine = Engine(position, velocity, radius, boundary=Boundary(periodic=periodic))
    engine.lookahead = lookahead
    used = []
    for chunk in range(1, 41):
        engine.run(contacts=chunk * 250)
        used.append(assert_queue_consistent(engine.disks))
    heap_sizes, overflow_sizes = np.array(used).T
    assert heap_sizes.max() > 1 and overflow_sizes.max() > 0
