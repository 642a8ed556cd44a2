"""The default scene until the Hydra runner lands: a gas of 2000 disks relaxing towards
Maxwell–Boltzmann in the unit box, with its collision rate and energy printed.

Run with ``python -m sim.demo`` (``make run``).
"""

import argparse
import time

import numpy as np

from sim.engine import Engine
from sim.initial import fixed_speed, random_sequential


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2000, help="number of disks")
    parser.add_argument("--phi", type=float, default=0.3, help="packing fraction")
    parser.add_argument("--collisions-per-disk", type=float, default=200.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)

    radius = np.sqrt(args.phi / (args.n * np.pi))
    position = random_sequential(np.full(args.n, radius), seed=args.seed)
    velocity = fixed_speed(args.n, 1.0, seed=args.seed + 1)
    started = time.perf_counter()
    engine = Engine(position, velocity, radius)
    engine.run(events=1)
    ready = time.perf_counter()
    target = int(args.collisions_per_disk * args.n)
    engine.run(collisions=target)
    elapsed = time.perf_counter() - ready
    speed = np.hypot(*engine.velocities().T)
    # 2D Maxwell–Boltzmann at T = E/N: mean speed sqrt(π T / 2) for unit mass
    temperature = engine.kinetic_energy() / args.n
    print(f"{args.n} disks, φ = {args.phi}, {engine.collisions} collisions in {elapsed:.2f} s "
          f"({engine.collisions / elapsed / 1e6:.2f} M collisions/s; set-up and compilation "
          f"{ready - started:.1f} s)")
    print(f"kinetic energy {engine.kinetic_energy():.15f} (initial {engine.initial_energy:.15f},"
          f" relative drift {engine.kinetic_energy() / engine.initial_energy - 1:.1e})")
    print(f"mean speed {speed.mean():.4f}; Maxwell–Boltzmann at T = E/N predicts "
          f"{np.sqrt(np.pi * temperature / 2):.4f} (all disks started at speed 1)")


if __name__ == "__main__":
    main()
