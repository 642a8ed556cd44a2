"""Memory and snapshot stalls of a long run of a large scene.

Runs the gas scene through the runner (the path a user's run takes: chunks, snapshots, H5MD
file, checkpoints) and samples the resident set size (VmRSS) every second in a thread. Prints
the RSS from the second snapshot on (the engine compiled and running: its smallest, largest
and last value), and for every snapshot the
seconds spent in the writer (position and velocity of every disk, observables, checkpoint) —
the engine stands still only for that long.

    python benchmarks/memory_scale.py --n 1000000 --collisions 1e8 --every 1e7
    python benchmarks/memory_scale.py --json ...    # one JSON object
"""

import argparse
import json
import tempfile
import threading
import time

from sim.pipeline import runner
from sim.pipeline.run_cache import compose_config
from sim.storage.h5md import RunWriter


def rss_bytes():
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    return 0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000)
    parser.add_argument("--phi", type=float, default=0.5)
    parser.add_argument("--collisions", type=float, default=1e8)
    parser.add_argument("--every", type=float, default=1e7, help="collisions between snapshots")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    samples = []  # (seconds since start, RSS bytes)
    writes = []  # (seconds since start, seconds in the writer)
    started = time.perf_counter()
    done = threading.Event()

    def sample():
        while not done.wait(1.0):
            samples.append((time.perf_counter() - started, rss_bytes()))

    original = RunWriter.snapshot

    def timed_snapshot(self, *a, **k):
        begin = time.perf_counter()
        original(self, *a, **k)
        writes.append((begin - started, time.perf_counter() - begin))

    RunWriter.snapshot = timed_snapshot
    threading.Thread(target=sample, daemon=True).start()
    cfg = compose_config(["box.boundary=periodic", f"disks.n={args.n}",
                          f"disks.packing_fraction={args.phi}",
                          f"stop.collisions={int(args.collisions)}",
                          f"output.every_collisions={int(args.every)}", "output.progress=false"])
    with tempfile.TemporaryDirectory() as folder:
        runner.run(cfg, folder)
    done.set()
    running = writes[1][0] + writes[1][1]
    after = [rss for t, rss in samples if t > running]
    row = {"n": args.n, "collisions": int(args.collisions),
           "seconds": round(time.perf_counter() - started, 1),
           "rss_least_mb": round(min(after) / 2**20, 1) if after else None,
           "rss_peak_mb": round(max(after) / 2**20, 1) if after else None,
           "rss_last_mb": round(after[-1] / 2**20, 1) if after else None,
           "snapshot_write_seconds": [round(w, 3) for _, w in writes],
           "rss_samples_mb": [round(rss / 2**20, 1) for _, rss in samples[::10]]}
    if args.json:
        print(json.dumps(row))
    else:
        for key, value in row.items():
            print(f"{key}: {value}")


if __name__ == "__main__":
    main()
