"""What each effect costs: the collision rate of one gas with the effect absent, neutral, on.

*Absent*: the scene does not name the effect. *Neutral*: the scene switches it on with a value
that changes nothing (ξ = 1, t_c = 0, every mass or species alike): sim must notice and run
the absent code, so neutral must cost nothing. *On*: a value that acts.

Every measurement starts from the same equilibrated elastic state (N disks at φ in the unit
box with walls, two labelled halves for the species rows, a periodic box for the unwrapping
row) and runs ``--collisions`` per disk; the event log is drained as a run would drain it;
engines are built outside the timing, and the three variants alternate in rounds in one
process so that a busy machine slows all alike. Rates are the best round; the slowdown
``off_over_absent_slowdown`` is the median over rounds of neutral time over absent time in
the same round (1.0 = free).

    python benchmarks/effects_cost.py              # the table
    python benchmarks/effects_cost.py --json       # one JSON object per effect
"""

import argparse
import json
import math
import statistics
import time

import numpy as np

from sim.engine import Boundary, Engine
from sim.pipeline.initial import fixed_speed, hexagonal_lattice, radius_for_packing

#: effect: (options of the base scene, absent, neutral, on); the species rows label half the
#: disks 1 (see ``scene``).
EFFECTS = {
    "restitution": ({}, {}, {"restitution": 1.0}, {"restitution": 0.9}),
    "wall_restitution": ({}, {}, {"wall_restitution": 1.0}, {"wall_restitution": 0.9}),
    "tc": ({"restitution": 0.9}, {}, {"tc": 0.0}, {"tc": 1e-6}),
    "mass": ({}, {}, {"mass": "equal"}, {"mass": "1 and 4"}),
    "species": ({}, {}, {"species": "all 0"}, {"species": "two"}),
    "pair_restitution": ({"species": "two"}, {"restitution": 0.9},
                         {"restitution": [[0.9, 0.9], [0.9, 0.9]]},
                         {"restitution": [[0.9, 0.8], [0.8, 0.7]]}),
    "gravity": ({}, {}, {"gravity": [0.0, 0.0]}, {"gravity": [0.0, -1.0]}),
    "thermal_walls": ({}, {}, {"walls": {"left": {"temperature": None}}},
                      {"walls": {name: {"temperature": 0.5}
                                 for name in ("left", "right", "bottom", "top")}}),
    "moving_walls": ({}, {}, {"walls": {"bottom": {"speed": 0.0, "amplitude": 0.0}}},
                     {"walls": {"bottom": {"amplitude": 0.002, "frequency": 50.0}}}),
    "unwrap": ({"periodic": True}, {}, {"unwrap": False}, {"unwrap": True}),
    "pressure_tensor": ({}, {}, {"pressure_tensor": False}, {"pressure_tensor": True}),
    "event_log": ({}, {}, {"event_log": None}, {"event_log": 1 << 16}),
    "rotation": ({}, {}, {"tangential_restitution": -1.0}, {"tangential_restitution": 0.5}),
    "growth": ({}, {}, {"growth_rate": 0.0}, {"growth_rate": 0.01}),
    "friction": ({"tangential_restitution": 0.5}, {}, {"friction": math.inf},
                 {"friction": 0.3}),
    "square_well": ({}, {}, {"potential_steps": []},
                    {"potential_steps": [1.5], "potential_energies": [-1.0]}),
}


def scene(state, options):
    """Engine keyword arguments for ``options``, with masses and species spelled out."""
    n = state["position"].shape[0]
    half = np.arange(n) % 2
    kwargs = dict(options)
    mass = kwargs.pop("mass", None)
    if mass == "equal":
        kwargs["mass"] = np.full(n, 1.0)
    elif mass == "1 and 4":
        kwargs["mass"] = np.where(half == 1, 4.0, 1.0)
    species = kwargs.pop("species", None)
    if species == "all 0":
        kwargs["species"] = np.zeros(n, dtype=int)
    elif species == "two":
        kwargs["species"] = half
    periodic = kwargs.pop("periodic", False)
    kwargs["boundary"] = Boundary(periodic=(periodic, periodic))
    return kwargs


def equilibrated(n, phi, seed=1):
    """Equal disks in the unit box with walls, 10 collisions per disk from a lattice."""
    radius = radius_for_packing(n, phi)
    engine = Engine(hexagonal_lattice(n, radius, seed=seed), fixed_speed(n, 1.0, seed=seed + 1),
                    radius)
    engine.run(collisions=10 * n)
    return {"position": engine.positions(), "velocity": engine.velocities(), "radius": radius}


def timed(state, options, collisions):
    engine = Engine(state["position"], state["velocity"], state["radius"],
                    **scene(state, options))
    started = time.perf_counter()
    engine.run(collisions=collisions)
    return engine.collisions / (time.perf_counter() - started)


def measure(effect, state, collisions, rounds):
    base, *variants = EFFECTS[effect]
    options = [{**base, **v} for v in variants]
    for o in options:  # compile (or load) each variant outside the timing
        timed(state, o, 1000)
    rates = [[], [], []]
    for _ in range(rounds):
        for k, o in enumerate(options):
            rates[k].append(timed(state, o, collisions))
    slowdowns = [a / b for a, b in zip(rates[0], rates[1], strict=True)]
    return {"effect": effect,
            "absent_collisions_per_s": round(max(rates[0])),
            "neutral_collisions_per_s": round(max(rates[1])),
            "on_collisions_per_s": round(max(rates[2])),
            "off_over_absent_slowdown": round(statistics.median(slowdowns), 3)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--phi", type=float, default=0.5)
    parser.add_argument("--collisions", type=float, default=10.0, help="per disk and round")
    parser.add_argument("--rounds", type=int, default=11)
    parser.add_argument("--effects", nargs="+", default=list(EFFECTS), choices=list(EFFECTS))
    parser.add_argument("--json", action="store_true", help="one JSON object per effect")
    args = parser.parse_args(argv)
    state = equilibrated(args.n, args.phi)
    collisions = int(args.collisions * args.n)
    if not args.json:
        print("effect | absent | neutral | on | neutral time / absent time")
        print("--- | --- | --- | --- | ---")
    for effect in args.effects:
        row = measure(effect, state, collisions, args.rounds)
        print(json.dumps(row) if args.json else " | ".join(str(v) for v in row.values()),
              flush=True)


if __name__ == "__main__":
    main()
