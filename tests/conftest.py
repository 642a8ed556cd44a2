"""Shared, seeded state factories and the overlap audit every dynamics test ends with."""

import numpy as np
import pytest

from sim.audit import outside_box, overlapping_pairs
from sim.engine import Boundary, Engine
from sim.initial import fixed_speed, hexagonal_lattice, random_sequential


def gas(n, phi, periodic=(False, False), seed=0, speed=1.0, **engine_options):
    """An engine with n equal disks at packing fraction phi in the unit box, equal speeds."""
    radius = np.sqrt(phi / (n * np.pi))
    if phi <= 0.4:
        position = random_sequential(np.full(n, radius), periodic=periodic, seed=seed)
    else:
        position = hexagonal_lattice(n, radius, periodic=periodic, seed=seed)
    velocity = fixed_speed(n, speed, seed=seed + 1)
    return Engine(position, velocity, radius, boundary=Boundary(periodic=periodic),
                  **engine_options)


def assert_no_overlap(engine, tolerance=1e-9):
    """Independent all-pairs audit (k-d tree) at the engine's current time."""
    position = engine.positions()
    pairs, overlap = overlapping_pairs(position, engine.radius, engine.box, engine.periodic,
                                       tolerance)
    assert pairs.size == 0, f"overlapping pairs {pairs[:5].tolist()}, overlaps {overlap[:5]}"
    escaped = outside_box(position, engine.radius, engine.box, engine.periodic, tolerance)
    assert escaped.size == 0, f"disks outside the box: {escaped[:5].tolist()}"


@pytest.fixture
def make_gas():
    return gas
