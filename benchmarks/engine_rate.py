"""Collision rate of the event engine: a table (or JSON rows) over N and packing fraction.

Elastic disks in a periodic unit box, started from a lattice (or random placement when
dilute) and equilibrated for ``--warmup`` collisions per disk before timing; one thread.
Columns: collisions_per_s and events_per_s (every event the engine applies: disk and wall
contacts, neighbour-shell exits and a pair interaction's other events) over all timed
collisions, pair_events_per_s (the events of pairs: collisions, and a step's crossings and
bounces), best_chunk_collisions_per_s
(the fastest of ``--chunks`` equal parts: on a shared machine, the rate least disturbed),
bytes_per_disk (engine arrays) and rss_bytes_per_disk (peak resident-set growth),
compile_s (first engine built and run in this process: compilation or cache load), and
reference_ratio (this engine over the textbook reference engine, same N and φ, same process,
N ≤ 10⁴). Extra rows compare effects: ξ < 1 with TC; growing disks (reference_ratio: their
rate over that of the same gas not growing) and the compress scene of 10⁴ disks run to
jamming (its wall time in the scene's name); a square well (λ = 1.5, ε = 1) at N = 10⁴,
φ = 0.3 beside hard disks of the same state (reference_ratio: its pair events per second
over their collisions per second); and the crater bed with and without its projectile.

    python benchmarks/engine_rate.py                       # the full table
    python benchmarks/engine_rate.py --n 10000 --phi 0.5 --json
"""

import argparse
import json
import os
import platform
import resource
import time

import numpy as np

from sim.checks.reference import ReferenceEngine
from sim.engine import Boundary, Engine
from sim.engine.codes import SHELL_EXITS
from sim.pipeline.initial import (
    fixed_speed,
    hexagonal_lattice,
    radius_for_packing,
    random_sequential,
)

FIRST_CALL = {"seconds": None}


def equal_disks(n, phi, seed=1):
    radius = radius_for_packing(n, phi)
    if phi <= 0.3:
        position = random_sequential(np.full(n, radius), periodic=(True, True), seed=seed)
    else:
        position = hexagonal_lattice(n, radius, periodic=(True, True), seed=seed)
    return position, fixed_speed(n, 1.0, seed=seed + 1), radius


def engine_bytes(engine):
    return engine.disks.nbytes + sum(v.nbytes for v in vars(engine).values()
                                     if isinstance(v, np.ndarray))


def peak_rss_bytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def timed_rate(engine, collisions, chunks):
    """Collisions, events and pair events (collisions and a pair interaction's other events,
    such as a step's crossings: the events but shell exits and wall contacts) per second
    over ``collisions`` collisions, timed in ``chunks`` equal parts; also the rate of the
    fastest part, the engine's speed while the machine disturbed it least (timeit's minimum
    time)."""
    c0, e0 = engine.collisions, engine.events
    others0 = engine.counters[SHELL_EXITS] + engine.wall_contacts
    chunk_rates = []
    seconds = 0.0
    for k in range(1, chunks + 1):
        c_start = engine.collisions
        started = time.perf_counter()
        engine.run(collisions=c0 + collisions * k // chunks)
        elapsed = time.perf_counter() - started
        seconds += elapsed
        chunk_rates.append((engine.collisions - c_start) / elapsed)
    others = engine.counters[SHELL_EXITS] + engine.wall_contacts - others0
    return ((engine.collisions - c0) / seconds, (engine.events - e0) / seconds,
            (engine.events - e0 - others) / seconds, max(chunk_rates))


def build(*args, **kwargs):
    """Engine(*args, **kwargs); the first one in the process is timed together with its first
    compiled call: that is the compilation (or cache-loading) time of this process."""
    started = time.perf_counter()
    engine = Engine(*args, **kwargs)
    if FIRST_CALL["seconds"] is None:
        engine.run(events=engine.events + 1)
        FIRST_CALL["seconds"] = time.perf_counter() - started
    return engine


def reference_rate(position, velocity, radius, events):
    reference = ReferenceEngine(position, velocity, radius, periodic=(True, True))
    reference.run(10)
    c0 = reference.collisions
    started = time.perf_counter()
    reference.run(events)
    return (reference.collisions - c0) / (time.perf_counter() - started)


def gas_row(n, phi, collisions, warmup, reference_events, chunks, **effects):
    rss_before = peak_rss_bytes()
    position, velocity, radius = equal_disks(n, phi)
    engine = build(position, velocity, radius, boundary=Boundary(periodic=(True, True)),
                   **effects)
    compile_s = FIRST_CALL["seconds"]
    engine.run(collisions=engine.collisions + int(warmup * n))
    coll_rate, event_rate, pair_rate, best_chunk_rate = timed_rate(engine, collisions, chunks)
    row = {"scene": "gas" if not effects else "gas " + " ".join(
               f"{k}={v}" for k, v in effects.items()),
           "n": n, "phi": phi, "collisions_per_s": round(coll_rate),
           "best_chunk_collisions_per_s": round(best_chunk_rate),
           "events_per_s": round(event_rate), "pair_events_per_s": round(pair_rate),
           "bytes_per_disk": round(engine_bytes(engine) / n, 1),
           "rss_bytes_per_disk": round(max(peak_rss_bytes() - rss_before, 0) / n, 1),
           "compile_s": round(compile_s, 2), "reference_ratio": None}
    if n <= 10_000 and not effects and reference_events:
        # the reference needs O(N) per event: time it on the equilibrated state
        row["reference_ratio"] = round(coll_rate / reference_rate(
            engine.positions(), engine.velocities(), radius, reference_events), 1)
    return row


def crater_rows(collisions, seed=1):
    """The seed study's crater: 4000 bed disks (R = 0.0045) in the lower half, a projectile
    of radius 0.05 at (0.5, 0.75) falling at 10, ξ = 0.5, TC 1e-8; against the same bed
    with thermal motion and no projectile. Each scene runs twice and the second run is timed:
    the first compiles every variant of the loop the scene meets (the bed's lists grow, which
    changes their layout's type)."""
    n_bed, r_bed = 4000, 0.0045
    bed = random_sequential(np.full(n_bed, r_bed), region=((0, 1), (0, 0.5)), seed=seed)
    rows = []
    for with_projectile in (False, True):
        if with_projectile:
            position = np.vstack([bed, [[0.5, 0.75]]])
            velocity = np.vstack([np.zeros((n_bed, 2)), [[0.0, -10.0]]])
            radius = np.append(np.full(n_bed, r_bed), 0.05)
            mass = np.append(np.ones(n_bed), (0.05 / r_bed) ** 2)
        else:
            position, radius, mass = bed, r_bed, 1.0
            velocity = fixed_speed(n_bed, 1.0, seed=seed + 1)
        for _ in range(2):
            engine = build(position, velocity, radius, mass, restitution=0.5, tc=1e-8)
            started = time.perf_counter()
            engine.run(collisions=collisions, energy_fraction=0.1)
            seconds = time.perf_counter() - started
        rows.append({"scene": "crater" if with_projectile else "crater bed, no projectile",
                     "n": engine.n, "phi": round(engine.packing_fraction(), 3),
                     "collisions_per_s": round(engine.collisions / seconds),
                     "best_chunk_collisions_per_s": None,
                     "events_per_s": round(engine.events / seconds),
                     "bytes_per_disk": round(engine_bytes(engine) / engine.n, 1),
                     "rss_bytes_per_disk": None, "compile_s": None, "reference_ratio": None})
    return rows


def compress_row(n, seed=0):
    """The ``compress`` scene (the 50:50 mixture of radius ratio 1.4 grown from φ = 0.3 at its
    default rate, :mod:`sim.effects.growth`) with ``n`` disks, run to its jamming stop; the
    engine built (and its loop compiled) before the timing."""
    from hydra import compose, initialize_config_dir

    from sim.pipeline.config import register
    from sim.pipeline.overrides import CONF_DIR
    from sim.pipeline.runner import build_engine

    register()
    with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
        cfg = compose("config", overrides=["scenario=compress", f"disks.n={n}", f"seed={seed}"])
    engine = build_engine(cfg)
    started = time.perf_counter()
    reason = engine.run(jamming=cfg.stop.jamming)
    seconds = time.perf_counter() - started
    return {"scene": f"compress to {reason} (βP/ρ = {cfg.stop.jamming:g}) in "
                     f"{seconds:.1f} s, φ_J = {engine.packing_fraction():.4f}",
            "n": n, "phi": round(engine.packing_fraction(), 3),
            "collisions_per_s": round(engine.collisions / seconds),
            "best_chunk_collisions_per_s": None, "events_per_s": round(engine.events / seconds),
            "bytes_per_disk": round(engine_bytes(engine) / n, 1), "rss_bytes_per_disk": None,
            "compile_s": None, "reference_ratio": None}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[1000, 10_000, 100_000, 1_000_000])
    parser.add_argument("--phi", type=float, nargs="+", default=[0.1, 0.5, 0.7])
    parser.add_argument("--collisions", type=int, default=3_000_000,
                        help="timed collisions per row (at least 20 per disk)")
    parser.add_argument("--chunks", type=int, default=5,
                        help="parts the timed collisions are run in (best_chunk_collisions_per_s)")
    parser.add_argument("--warmup", type=float, default=10.0, help="collisions per disk")
    parser.add_argument("--reference-events", type=int, default=300)
    parser.add_argument("--no-effects", action="store_true", help="skip the effect rows")
    parser.add_argument("--json", action="store_true", help="one JSON object per row")
    args = parser.parse_args(argv)

    rows = []
    for n in sorted(args.n):
        for phi in args.phi:
            rows.append(gas_row(n, phi, max(args.collisions, 20 * n), args.warmup,
                                args.reference_events, args.chunks))
            emit(rows[-1], args.json, header=len(rows) == 1)
    if not args.no_effects:
        n = 10_000
        rows.append(gas_row(n, 0.5, max(args.collisions, 20 * n), args.warmup, 0, args.chunks,
                            restitution=0.9, tc=1e-6))
        emit(rows[-1], args.json)
        # growing disks at φ ≈ 0.5 (γ = 0.01: φ grows by about 1 % while timed) against the
        # first row of this n and φ, and the compress scene run to jamming
        rows.append(gas_row(n, 0.5, max(args.collisions, 20 * n), args.warmup, 0, args.chunks,
                            growth_rate=0.01))
        off = next((r for r in rows if r["scene"] == "gas" and r["n"] == n and r["phi"] == 0.5),
                   None)
        if off is not None:
            rows[-1]["reference_ratio"] = round(rows[-1]["collisions_per_s"]
                                                / off["collisions_per_s"], 3)
        emit(rows[-1], args.json)
        rows.append(compress_row(n))
        emit(rows[-1], args.json)
        # a square well (λ = 1.5, ε = 1 at T = 1) against hard disks of the same state: its
        # collisions and step crossings and bounces per second over their collisions per second
        hard = gas_row(n, 0.3, max(args.collisions, 20 * n), args.warmup, 0, args.chunks)
        rows.append(hard)
        emit(rows[-1], args.json)
        rows.append(gas_row(n, 0.3, max(args.collisions, 20 * n), args.warmup, 0, args.chunks,
                            potential_steps=[1.5], potential_energies=[-1.0]))
        rows[-1]["reference_ratio"] = round(rows[-1]["pair_events_per_s"]
                                            / hard["collisions_per_s"], 3)
        emit(rows[-1], args.json)
        for row in crater_rows(min(args.collisions, 2_000_000)):
            rows.append(row)
            emit(row, args.json)
    if not args.json:
        print(f"\nmachine: {platform.processor() or platform.machine()}, "
              f"{os.cpu_count()} cores, Python {platform.python_version()}, one thread")


def emit(row, as_json, header=False):
    """Print a row (a dict) as one JSON object, or as a line of a Markdown table whose header
    (the row's keys) comes first when ``header``; None prints as an empty cell."""
    if as_json:
        print(json.dumps(row), flush=True)
        return
    if header:
        print(" | ".join(row))
        print(" | ".join("---" for _ in row))
    print(" | ".join("" if v is None else str(v) for v in row.values()), flush=True)


if __name__ == "__main__":
    main()
