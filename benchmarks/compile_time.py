"""Where the first compilation goes: seconds per compiled function and per numba pass.

Builds one engine (equal elastic disks in a periodic box) and runs one event with numba's
cache in a fresh temporary folder, so that everything the first use of sim compiles is
compiled here. Prints, for each compiled function, the seconds from the start to the end of
its compilation (numba's ``numba:compile`` events; a function's time includes the functions
it calls that were compiled on the way, shown indented beneath it), then the slowest passes
of the event loop's compilation (numba's pass timers, ``pipeline_times`` of its metadata).

    python benchmarks/compile_time.py
"""

import argparse
import os
import sys
import tempfile
import time


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--phi", type=float, default=0.5)
    parser.add_argument("--passes", type=int, default=8, help="slowest passes shown")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as cache:
        os.environ["NUMBA_CACHE_DIR"] = cache  # read by numba on import, below
        report(args.n, args.phi, args.passes)


def report(n, phi, passes):
    from numba.core import event

    from engine_rate import equal_disks
    from sim.engine import Boundary, Engine
    from sim.engine import loop as event_loop

    position, velocity, radius = equal_disks(n, phi)
    started = time.perf_counter()
    with event.install_recorder("numba:compile") as recorder:
        engine = Engine(position, velocity, radius, boundary=Boundary(periodic=(True, True)))
        engine.run(events=engine.events + 1)
    print(f"first engine built and run: {time.perf_counter() - started:.2f} s\n")
    print("seconds | function (indented: compiled while compiling the one above)")
    print("--- | ---")
    open_starts = []
    finished = []
    for timestamp, compile_event in recorder.buffer:
        function = compile_event.data["dispatcher"].py_func
        if compile_event.is_start:
            open_starts.append(timestamp)
        else:
            start = open_starts.pop()
            finished.append((start, timestamp - start, len(open_starts),
                             f"{function.__module__}.{function.__qualname__}"))
    for _, seconds, depth, name in sorted(finished):
        if seconds >= 0.1:
            print(f"{seconds:.2f} | {'  ' * depth}{name}")
    print(f"\nslowest passes of {event_loop.run_events.__name__} (s)")
    for compiled in event_loop.run_events.overloads.values():
        timings = compiled.metadata["pipeline_times"]["nopython"]
        slowest = sorted(((t.run, name) for name, t in timings.items()), reverse=True)
        for seconds, name in slowest[:passes]:
            print(f"{seconds:.2f} | {name}")
        for name, seconds in compiled.metadata["timers"].items():
            print(f"{seconds:.2f} | {name} (all of it)")


if __name__ == "__main__":
    sys.exit(main())
