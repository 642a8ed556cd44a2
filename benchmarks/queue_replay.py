"""What the event queue alone costs, by N: a replay of the engine's queue operations.

Each step does what a disk–disk collision does to the queue (sim.engine.queue): the earliest
disk is taken, given a new event an exponential delay later and rescheduled, and a partner
near it in memory (within ±32 ids, as disks renumbered by cell are) is rescheduled too, to
an exponential delay after the current time. Mean delay 1 for n disks: the engine's rate of
n events per mean time between a disk's events. The random numbers are drawn beforehand and
read in turn, so what is printed is the queue's own time per collision. The engine spends
the rest of a collision on the disks themselves; set it beside ``collisions_per_s`` of
``benchmarks/engine_rate.py`` at the same N.

    python benchmarks/queue_replay.py --n 10000 100000 1000000
    python benchmarks/queue_replay.py --json ...    # one JSON object per N
"""

import argparse
import time

import numpy as np
from numba import njit

from engine_rate import emit
from sim.engine.queue import build_queue, earliest, empty_queue, reschedule

#: Partners are drawn within ±NEIGHBOUR_SPAN / 2 ids of the disk.
NEIGHBOUR_SPAN = 64


@njit(cache=True, _nrt=False, error_model="numpy")
def replay(steps, event_time, heap, links, list_head, calendar, block_rate, delays, offsets):
    """``steps`` collisions' worth of queue operations, the random delays and partner offsets
    read in turn from ``delays`` float64[2, m] and ``offsets`` int64[m]; returns a checksum of
    the order in which the disks came up."""
    n = event_time.shape[0]
    m = offsets.shape[0]
    checksum = 0
    for step in range(steps):
        k = step % m
        i = earliest(heap, links, list_head, calendar, block_rate, event_time)
        t = event_time[i]
        checksum = (checksum * 31 + i) % 1_000_000_007
        event_time[i] = t + delays[0, k]
        reschedule(heap, links, list_head, calendar, block_rate, event_time, i)
        j = (i + offsets[k] - NEIGHBOUR_SPAN // 2) % n
        if event_time[j] > t:
            event_time[j] = t + delays[1, k]
            reschedule(heap, links, list_head, calendar, block_rate, event_time, j)
    return checksum


def queue_row(n, steps, seed=1, draws=1 << 20):
    rng = np.random.default_rng(seed)
    event_time = rng.exponential(1.0, n)
    delays = rng.exponential(1.0, (2, draws))
    offsets = rng.integers(0, NEIGHBOUR_SPAN, draws)
    queue = empty_queue(n)
    build_queue(*queue, event_time, 0.0)
    replay(10 * n, event_time, *queue, delays, offsets)  # compile; reach the steady state
    started = time.perf_counter()
    replay(steps, event_time, *queue, delays, offsets)
    seconds = time.perf_counter() - started
    return {"n": n, "queue_ns_per_collision": round(seconds / steps * 1e9, 1)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--steps", type=int, default=5_000_000, help="collisions replayed")
    parser.add_argument("--json", action="store_true", help="one JSON object per N")
    args = parser.parse_args(argv)
    for k, n in enumerate(args.n):
        emit(queue_row(n, args.steps), args.json, header=k == 0)


if __name__ == "__main__":
    main()
