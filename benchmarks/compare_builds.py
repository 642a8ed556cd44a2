"""Rank two or more source trees of sim by their collision rate, as ratios measured together.

On a shared machine the rate of one build swings by up to 2x within an hour at N >= 1e5, and
one process can be a few percent faster than another of the same build (its memory placement),
so rates measured apart cannot rank builds. Here every build runs in ``--processes`` worker
processes, each equilibrated once (10 collisions per disk from the same lattice); then, round
after round, every worker runs one chunk of collisions, in a shuffled order. A round's ratio
is the mean rate of a build's workers over that of the first build's workers; the median and
quartiles over rounds are printed.

A source tree is a directory with ``src/sim`` and ``benchmarks/engine_rate.py`` (a clone or
``git worktree add "$BASE" <commit>``), optionally followed by ``:<shell diameter r_n/σ>``:

    python benchmarks/compare_builds.py "$BASE" . --n 1000000 --chunk 400000 --rounds 16
    python benchmarks/compare_builds.py . .:2.2 --n 1000000   # one build, two shells
"""

import argparse
import random
import statistics
import subprocess
import sys
import time
from pathlib import Path


def worker(source, n, phi):
    """Serve chunks: read a number of collisions per line, answer with the rate."""
    tree, _, shell = source.partition(":")
    tree = Path(tree).resolve()
    sys.path[:0] = [str(tree / "src"), str(tree / "benchmarks")]
    from engine_rate import equal_disks
    from sim.engine import Boundary, Engine

    position, velocity, radius = equal_disks(n, phi)
    engine = Engine(position, velocity, radius, boundary=Boundary(periodic=(True, True)),
                    shell=float(shell) if shell else None)
    engine.run(collisions=10 * n)
    print("ready", flush=True)
    for line in sys.stdin:
        c0 = engine.collisions
        started = time.perf_counter()
        engine.run(collisions=c0 + int(line))
        print((engine.collisions - c0) / (time.perf_counter() - started), flush=True)


def compare(sources, n, phi, chunk, rounds, processes, seed=0):
    """Rates per worker per round, and per build the median and quartiles of round ratios."""
    workers = [(build, subprocess.Popen(
        [sys.executable, __file__, "--worker", source, "--n", str(n), "--phi", str(phi)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True))
        for build, source in enumerate(sources) for _ in range(processes)]
    for _, process in workers:
        if process.stdout.readline().strip() != "ready":
            raise RuntimeError("a worker failed to start (its error is printed above)")
    rates = [[] for _ in workers]
    shuffle = random.Random(seed)
    for _ in range(rounds):
        order = list(range(len(workers)))
        shuffle.shuffle(order)
        for k in order:
            workers[k][1].stdin.write(f"{chunk}\n")
            workers[k][1].stdin.flush()
            rates[k].append(float(workers[k][1].stdout.readline()))
    for _, process in workers:
        process.stdin.close()
        process.wait()

    def build_rate(build, r):
        return statistics.mean(rates[k][r] for k, (b, _) in enumerate(workers) if b == build)

    rows = []
    for build, source in enumerate(sources):
        ratios = [build_rate(build, r) / build_rate(0, r) for r in range(rounds)]
        quartiles = statistics.quantiles(ratios, n=4) if rounds > 1 else [ratios[0]] * 3
        rows.append({"source": source, "median_rate": statistics.median(
            [build_rate(build, r) for r in range(rounds)]),
            "ratio_median": statistics.median(ratios),
            "ratio_q1": quartiles[0], "ratio_q3": quartiles[2]})
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sources", nargs="+", help="source trees, the first is the baseline")
    parser.add_argument("--n", type=int, default=1_000_000)
    parser.add_argument("--phi", type=float, default=0.5)
    parser.add_argument("--chunk", type=int, default=400_000, help="collisions per round")
    parser.add_argument("--rounds", type=int, default=16)
    parser.add_argument("--processes", type=int, default=2, help="worker processes per build")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker(args.sources[0], args.n, args.phi)
        return
    print(f"N = {args.n}, phi = {args.phi}, {args.rounds} rounds of {args.chunk} collisions, "
          f"{args.processes} processes per build")
    print("source | median rate | ratio to the first (median) | quartiles")
    print("--- | --- | --- | ---")
    for row in compare(args.sources, args.n, args.phi, args.chunk, args.rounds,
                       args.processes):
        print(f"{row['source']} | {row['median_rate'] / 1e6:.3f} M | {row['ratio_median']:.3f} "
              f"| {row['ratio_q1']:.3f}–{row['ratio_q3']:.3f}")


if __name__ == "__main__":
    main()
