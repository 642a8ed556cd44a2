"""System events (:mod:`sim.engine.system`): a kind written here, in the test file alone, plugs
into the loop's slot. It reverses every velocity at a time (the gas then retraces its path),
or turns one disk's velocity by a right angle at regular times (a kick whose partners'
predictions go stale without a contact being counted).

One kind, so one compiled variant of the loop, outside the quick suite's canonical set: slow.
"""

from typing import NamedTuple

import numpy as np
import pytest
from numba import njit

from conftest import assert_no_overlap, gas
from sim.engine.flight import fly
from sim.engine.kinematics import VX, VY
from sim.engine.stamps import invalidate
from sim.engine.system import advance_all, handler, predict_all, repredict

pytestmark = pytest.mark.slow

REVERSE, TURN = 0, 1


class Toy(NamedTuple):
    mode: int  # REVERSE: every velocity reversed once, at ``at``; TURN: disk 0 turned every ``at``
    at: float  # absolute time
    applied: np.ndarray  # int64[1]: how many times the event changed the disks


@handler(Toy)
@njit
def toy(value, t, t_origin, disks, schedule, neighbours, box, effects):
    table = disks.table
    if value.mode == REVERSE:
        if t_origin + t < value.at:
            return value.at - t_origin
        advance_all(t, disks, box, effects)
        for i in range(table.shape[0]):
            table[i, VX] = -table[i, VX]
            table[i, VY] = -table[i, VY]
        predict_all(t, schedule)
        value.applied[0] += 1
        return np.inf
    if t > 0.0:
        fly(0, t, table, box, effects.gravity, effects.images)
        table[0, VX], table[0, VY] = -table[0, VY], table[0, VX]
        invalidate(0, disks)
        repredict(0, t, schedule)
        value.applied[0] += 1
    return t + value.at


def toy_gas(mode, at):
    """A periodic gas of 400 equal disks at φ = 0.3 with the toy system event."""
    return gas(400, 0.3, periodic=(True, True), seed=1,
               system_event=Toy(mode, at, np.zeros(1, np.int64)))


def test_a_reversed_gas_retraces_its_path():
    engine = toy_gas(REVERSE, at=0.1)
    start = engine.positions(0.0)
    engine.run(time=0.1)
    forward = engine.collisions
    engine.run(time=0.2)
    back = engine.positions(0.2) - start
    back -= np.round(back)  # box of side 1
    assert engine.system_event.applied[0] == 1 and 2 * forward > 5 * engine.n  # contacts per disk
    assert engine.collisions == 2 * forward
    assert np.abs(back).max() < 1e-9


def test_a_kicked_disk_is_never_counted_as_a_contact_and_never_overlaps():
    engine = toy_gas(TURN, at=0.01)
    energy = engine.kinetic_energy()
    for end in np.linspace(0.05, 0.5, 10):
        engine.run(time=end)
        assert_no_overlap(engine)
    assert engine.system_event.applied[0] == 49
    assert engine.contacts_by_disk().sum() == 2 * engine.collisions
    assert engine.kinetic_energy() == pytest.approx(energy, rel=1e-12)


def _fingerprint(engine):
    return engine.positions().tobytes() + engine.velocities().tobytes()


def test_system_events_keep_the_bits_across_chunks_and_checkpoints():
    whole = toy_gas(TURN, at=0.01)
    whole.run(time=0.3)
    chunked = toy_gas(TURN, at=0.01)
    chunked.run(time=0.3, chunk_events=97)
    half = toy_gas(TURN, at=0.01)
    half.run(time=0.15)
    resumed = toy_gas(TURN, at=0.01)
    resumed.load_state_dict(half.state_dict())
    resumed.run(time=0.3)
    assert _fingerprint(chunked) == _fingerprint(whole) == _fingerprint(resumed)
    assert chunked.collisions == whole.collisions == resumed.collisions
