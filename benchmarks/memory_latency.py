"""The machine's memory latency by working-set size: what a cache miss costs the event loop.

A chain of dependent loads visits one 8-byte word in every 64-byte line of a buffer in a
random cyclic order, so that each load must wait for the one before it and no prefetcher can
guess the next address: the time per load is the latency of the level the buffer fits in
(L1, L2, L3, memory). The event engine's state is about 290 bytes per disk, so N disks need
about 0.3 N kB; beyond the last cache level each access to a disk the loop has not asked for
in advance (``sim.engine.lookahead.prefetch_upcoming``) costs the time printed for the largest
sizes.

    python benchmarks/memory_latency.py
    python benchmarks/memory_latency.py --mib 1 8 64 512 --json
"""

import argparse
import time

import numpy as np
from numba import njit

from engine_rate import emit

LINE_WORDS = 8  # int64 words per 64-byte cache line


@njit(cache=True)
def follow_chain(successor, steps):
    """Follow ``k -> successor[k]`` from 0 for ``steps`` loads; returns where it ends."""
    k = 0
    for _ in range(steps):
        k = successor[k]
    return k


def random_cycle(mib, seed):
    """int64 buffer of ``mib`` MiB whose line starts hold a single random cycle through all
    lines (as word indices); the other words are never read."""
    lines = int(mib * 2**20) // 64
    order = np.random.default_rng(seed).permutation(lines)
    buffer = np.zeros(lines * LINE_WORDS, dtype=np.int64)
    buffer[order * LINE_WORDS] = np.roll(order, -1) * LINE_WORDS
    return buffer


def latency_ns(mib, steps, seed=1):
    buffer = random_cycle(mib, seed)
    follow_chain(buffer, min(steps, buffer.size))  # compile, and bring the buffer in
    started = time.perf_counter()
    follow_chain(buffer, steps)
    return (time.perf_counter() - started) / steps * 1e9


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mib", type=float, nargs="+",
                        default=[0.5, 1, 2, 4, 8, 16, 32, 64, 256, 1024],
                        help="working-set sizes in MiB")
    parser.add_argument("--steps", type=int, default=2_000_000, help="dependent loads timed")
    parser.add_argument("--json", action="store_true", help="one JSON object per row")
    args = parser.parse_args(argv)
    for k, mib in enumerate(args.mib):
        emit({"mib": mib, "ns_per_load": round(latency_ns(mib, args.steps), 1)}, args.json,
             header=k == 0)


if __name__ == "__main__":
    main()
