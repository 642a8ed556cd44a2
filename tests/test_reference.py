"""The engine against the textbook reference engine (every pair, one heap of all events).

Two independent algorithms agree event by event until round-off, amplified by the chaos of
colliding disks (about ×10 per 100 events for 50 disks at φ ≈ 0.6), separates them. So:
  * in a gas, the same event sequence for 1000 events and the same state to 1e-9 while
    round-off is still small (300 events);
  * in rows of disks moving along x, where head-on collisions do not amplify errors, the same
    state to 1e-9 for 1500 events;
  * in random small mixtures of radii and masses, the same event sequence for 3 events per
    disk and the same state to 1e-9 for 1 per disk (round-off, amplified by chaos, parts
    small dilute ones after about 4 per disk).
"""

import math

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from conftest import assert_no_overlap, engine_examples
from sim.checks.reference import ReferenceEngine
from sim.engine import Boundary, Engine
from sim.pipeline.initial import fixed_speed, hexagonal_lattice, radius_for_packing

BOUNDARIES = [(False, False), (True, True), (True, False)]


def compare(position, velocity, radius, periodic, events, strict_events, tolerance=1e-9,
            mass=1.0):
    """Step the reference; after each event run the engine to the midpoint before the next
    one and compare. Returns the largest state difference within ``strict_events``."""
    reference = ReferenceEngine(position, velocity, radius, mass=mass, periodic=periodic)
    # unequal masses as two species (species change nothing here): the mixture scene's
    # compiled variant (variants.py)
    species = np.arange(len(position)) % 2 if np.ptp(mass) > 0 else None
    engine = Engine(position, velocity, radius, mass=mass, species=species,
                    boundary=Boundary(periodic=periodic))
    worst = 0.0
    for k in range(events):
        t, _, _ = reference.step()
        t_next = reference.next_event_time()
        if t_next <= t:
            continue  # simultaneous events: compare after the last of them
        t_mid = 0.5 * (t + min(t_next, t + 1.0))
        engine.run(time=t_mid)
        np.testing.assert_array_equal(engine.contacts_by_disk(), reference.count,
                                      err_msg=f"event sequences differ at event {k}")
        if k < strict_events:
            d = engine.positions(t_mid) - reference.positions(t_mid)
            d -= np.where(periodic, np.round(d), 0.0)
            dv = engine.velocities() - reference.velocity
            worst = max(worst, np.abs(d).max(), np.abs(dv).max())
    assert worst < tolerance
    assert engine.collisions == reference.collisions
    assert engine.wall_contacts == reference.wall_contacts
    assert_no_overlap(engine)
    return worst


@pytest.mark.parametrize("periodic", BOUNDARIES)
def test_same_events_as_reference_in_a_dense_gas(periodic):
    n, radius = 50, 0.062
    position = hexagonal_lattice(n, radius, periodic=periodic, seed=3)
    compare(position, fixed_speed(n, 1.0, seed=4), radius, periodic, 1000, 300)


@pytest.mark.parametrize("periodic", BOUNDARIES)
def test_same_states_as_reference_in_rows_of_head_on_collisions(periodic):
    n_row, rows, radius = 10, 5, 0.02
    x = (np.arange(n_row) + 0.5) / n_row
    y = (np.arange(rows) + 0.5) / rows
    position = np.stack(np.meshgrid(x, y), axis=-1).reshape(-1, 2)
    rng = np.random.default_rng(5)
    velocity = np.stack([rng.uniform(-1, 1, n_row * rows), np.zeros(n_row * rows)], axis=1)
    worst = compare(position, velocity, radius, periodic, 1500, 1500)
    assert math.isfinite(worst)


def compare_random_mixture(n, phi, smallest, heaviest, periodic, seed):
    """Radii between ``smallest`` × R and R on a lattice spaced for R, masses between 1 and
    ``heaviest``, compared with the reference."""
    largest = radius_for_packing(n, phi)
    rng = np.random.default_rng(seed)
    radius = largest * rng.uniform(smallest, 1.0, n)
    mass = rng.uniform(1.0, heaviest, n)
    position = hexagonal_lattice(n, largest, periodic=periodic, seed=seed)
    compare(position, fixed_speed(n, 1.0, seed=seed + 1), radius, periodic, 3 * n, n,
            mass=mass)


@engine_examples(60)
@given(n=st.integers(8, 40), phi=st.floats(0.2, 0.6), smallest=st.floats(0.5, 1.0),
       heaviest=st.floats(1.0, 10.0), periodic=st.sampled_from(BOUNDARIES),
       seed=st.integers(0, 10_000))
# found by this test: a pair reaching contact through an image other than the one nearest
# at its prediction, missed by the engine (151) and by the reference (92)
@example(n=8, phi=0.25, smallest=0.6875, heaviest=1.0, periodic=(True, True), seed=151)
@example(n=8, phi=0.25, smallest=0.5, heaviest=1.0, periodic=(True, True), seed=92)
def test_same_events_as_reference_in_random_mixtures(n, phi, smallest, heaviest, periodic,
                                                      seed):
    """A disk schedules a contact only if it comes no later than its partner's own next event
    (the partner predicts it otherwise), and no contact is lost or doubled. Radii of at least
    R/2: none more than twice the median (``BIG_RADIUS_RATIO``), so every neighbour list has
    the one capacity of the mixture scene's compiled variant."""
    compare_random_mixture(n, phi, smallest, heaviest, periodic, seed)


@pytest.mark.slow  # a disk twice the median radius has a list capacity of its own
@engine_examples(60)
@given(n=st.integers(8, 40), phi=st.floats(0.2, 0.6), smallest=st.floats(0.3, 0.5),
       heaviest=st.floats(1.0, 10.0), periodic=st.sampled_from(BOUNDARIES),
       seed=st.integers(0, 10_000))
def test_same_events_as_reference_in_random_mixtures_of_disparate_radii(n, phi, smallest,
                                                                        heaviest, periodic,
                                                                        seed):
    """As above, radii down to 0.3 R: some disks more than twice the median."""
    compare_random_mixture(n, phi, smallest, heaviest, periodic, seed)
