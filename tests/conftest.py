"""Shared, seeded state factories, the overlap audit every dynamics test ends with, and the
validation table the slow studies fill."""

from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

from sim.checks.audit import outside_box, overlapping_pairs
from sim.checks.rows import table
from sim.engine import Boundary, Engine
from sim.pipeline.initial import (
    fixed_speed,
    hexagonal_lattice,
    radius_for_packing,
    random_sequential,
)

#: Tests never depend on the clock: no example has a deadline (the first example of a test
#: compiles numba code, and a loaded machine runs anything slowly).
settings.register_profile("sim", deadline=None)
settings.load_profile("sim")


def gas(n, phi, periodic=(False, False), seed=0, speed=1.0, **engine_options):
    """An engine with n equal disks at packing fraction phi in the unit box, equal speeds."""
    radius = radius_for_packing(n, phi)
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
    escaped = outside_box(position, engine.radius, engine.box, engine.periodic, tolerance,
                          engine.wall_positions())
    assert escaped.size == 0, f"disks outside the box: {escaped[:5].tolist()}"


@pytest.fixture
def make_gas():
    return gas


VALIDATION_TABLE = Path("outputs") / "validation" / "table.md"
_validation_rows = []


@pytest.fixture
def validation_rows():
    """Rows of the validation table (sim.checks.validation.Check), collected over the session."""
    return _validation_rows


def pytest_terminal_summary(terminalreporter):
    """Write and show the validation table when validation studies ran."""
    if not _validation_rows:
        return
    VALIDATION_TABLE.parent.mkdir(parents=True, exist_ok=True)
    text = table(_validation_rows)
    VALIDATION_TABLE.write_text(text)
    terminalreporter.write_sep("=", f"validation table ({VALIDATION_TABLE})")
    terminalreporter.write(text)
