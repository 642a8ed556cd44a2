"""Configurations that break naive event-driven codes. Each runs 10⁶ collisions or to its
natural end and finishes with the independent all-pairs overlap audit; where physics breaks
down (inelastic collapse) the run ends with a clear error instead."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import assert_no_overlap, engine_examples, gas
from sim.checks.audit import overlapping_pairs
from sim.engine import Boundary, Engine, InelasticCollapseError
from sim.pipeline.initial import (
    fixed_speed,
    hexagonal_lattice,
    radius_for_packing,
    random_sequential,
)

MILLION = 1_000_000
#: collisions after a hard start (disks in contact, contacts at one instant) of a few disks:
#: the hard case is the first events; what follows is a dilute gas of ten events per
#: collision, whose energy, overlaps and bits 10⁵ collisions test as well as 10⁶
AFTER_A_HARD_START = 100_000


def conserves_energy(engine, e0, rel=1e-10):
    assert engine.kinetic_energy() == pytest.approx(e0, rel=rel)


def runs_clean(engine, collisions=MILLION):
    """Run an elastic engine for ``collisions``: it gets there, keeps its energy and leaves
    no pair overlapping."""
    e0 = engine.kinetic_energy()
    assert engine.run(collisions=collisions) == "collisions"
    conserves_energy(engine, e0)
    assert_no_overlap(engine)


@pytest.mark.parametrize("phi", [0.80, 0.71])
def test_dense_solid_and_coexistence(phi):
    engine = gas(1000, phi, (True, True), seed=51)
    runs_clean(engine)


def test_mass_ratios_of_a_million_both_ways_in_one_box():
    """One disk 10⁶ times heavier than the rest and one 10⁶ times lighter, each its own
    species (a mixture, as the mixture scene has)."""
    n, phi = 500, 0.3
    radius = radius_for_packing(n, phi)
    position = random_sequential(np.full(n, radius), seed=53)
    mass = np.ones(n)
    mass[0], mass[1] = 1e6, 1e-6
    species = np.zeros(n, dtype=int)
    species[0], species[1] = 1, 2
    engine = Engine(position, fixed_speed(n, 1.0, seed=54), radius, mass, species)
    runs_clean(engine)


@pytest.mark.slow  # an elastic gas with one big disk: no quick variant (tests/variants.py)
def test_one_disk_fifty_times_larger_than_the_rest():
    n, small = 2000, 0.004
    big_radius = 50 * small
    position = random_sequential(np.append(np.full(n, small), big_radius), seed=55)
    radius = np.append(np.full(n, small), big_radius)
    engine = Engine(position, fixed_speed(n + 1, 1.0, seed=56), radius)
    assert engine.disks.big.size == 1
    runs_clean(engine)


def test_one_fast_disk_in_a_nearly_frozen_gas():
    """Speed ratio 10⁸: the fast disk's energy spreads through the gas without a stall."""
    n, phi = 1000, 0.3
    radius = radius_for_packing(n, phi)
    velocity = fixed_speed(n, 1e-8, seed=58)
    velocity[0] = [1.0, 0.3]
    engine = Engine(random_sequential(np.full(n, radius), seed=57), velocity, radius)
    runs_clean(engine)


def test_disks_starting_in_contact_in_a_corner_and_along_a_wall():
    """A row of touching disks along the floor, one in the corner touching both walls, one
    pair in contact mid-box; launched at each other and at the walls."""
    r = 0.02
    row = [[r + 2 * r * k, r] for k in range(10)]  # touching each other and the floor
    corner = [[1.0 - r, 1.0 - r]]
    pair = [[0.5, 0.5], [0.5 + 2 * r, 0.5]]
    position = np.array(row + corner + pair)
    velocity = np.zeros_like(position)
    velocity[0] = [1.0, -1.0]  # into the corner at (0, 0)
    velocity[9] = [-1.0, 0.0]  # along the row
    velocity[10] = [1.0, 1.0]  # into its corner
    velocity[11], velocity[12] = [1.0, 0.2], [-1.0, 0.1]  # the touching pair, approaching
    engine = Engine(position, velocity, r)
    assert_no_overlap(engine)
    runs_clean(engine, AFTER_A_HARD_START)


def test_square_of_four_aimed_at_the_centre():
    """Four disks reach each other at one instant: four contacts at the same time. Hard-disk
    dynamics leaves the outcome of simultaneous contacts to the order they are applied in, so
    the fourfold symmetry is not kept; what must hold is momentum, energy, no overlap, no stall
    and the same bits on every run."""
    r, d = 0.05, 0.3
    position = 0.5 + np.array([[-d, 0.0], [d, 0.0], [0.0, -d], [0.0, d]])
    velocity = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    runs = [Engine(position, velocity, r, boundary=Boundary(periodic=(True, True)))
            for _ in range(2)]
    for engine in runs:
        runs_clean(engine, AFTER_A_HARD_START)
        np.testing.assert_allclose(engine.momentum(), 0.0, atol=1e-12)
    np.testing.assert_array_equal(runs[0].positions(), runs[1].positions())


def test_grazing_collisions_keep_disks_apart():
    """Pairs aimed to pass at contact distance σ(1 − ε) for ε down to 1e-15 (the first disk
    on the line y = 0 of the periodic box, so that the offset keeps every digit)."""
    r = 0.01
    for epsilon in (1e-3, 1e-6, 1e-9, 1e-12, 1e-15):
        offset = 2 * r * (1.0 - epsilon)
        engine = Engine([[0.2, 0.0], [0.8, offset]], [[1.0, 0.0], [-1.0, 0.0]], r,
                        boundary=Boundary(periodic=(True, True)))
        engine.run(time=2.0)
        assert engine.collisions >= 1
        conserves_energy(engine, 1.0, rel=1e-14)
        assert_no_overlap(engine)


@pytest.mark.slow  # ξ_w < 1 without gravity, with and without TC: no quick variant
def test_dense_inelastic_gas_collapses_without_tc_and_finishes_with_it():
    """ξ = 0.5 at φ = 0.6 in a box with walls: without the TC model clusters collapse and the
    run ends with the collapse error; with it the same gas runs to its energy stop."""
    with pytest.raises(InelasticCollapseError, match="TC model"):
        gas(1000, 0.6, seed=59, restitution=0.5, wall_restitution=0.5).run(collisions=MILLION)
    engine = gas(1000, 0.6, seed=59, restitution=0.5, wall_restitution=0.5, tc=1e-6)
    assert engine.run(collisions=MILLION, energy_fraction=1e-3) in {"collisions",
                                                                     "energy_fraction"}
    assert_no_overlap(engine)


@pytest.mark.slow
def test_a_hundred_million_collisions_of_a_thousand_disks():
    """Energy drift and positional round-off over 10⁸ collisions stay bounded: the energy to
    1e-10 relative, and the deepest overlap of any pair in the final state (the pair that
    just collided sits at contact, up to round-off) below 1e-12 of the contact distance."""
    engine = gas(1000, 0.5, (True, True), seed=61)
    e0 = engine.kinetic_energy()
    assert engine.run(collisions=100 * MILLION) == "collisions"
    drift = abs(engine.kinetic_energy() / e0 - 1.0)
    _, overlap = overlapping_pairs(engine.positions(), engine.radius, engine.box,
                                   engine.periodic, tolerance=0.0)
    deepest = float(overlap.max(initial=0.0))
    print(f"after 1e8 collisions: relative energy drift {drift:.2e}, deepest overlap "
          f"{deepest:.2e} of the contact distance")
    assert drift < 1e-10
    assert deepest < 1e-12
    assert_no_overlap(engine)


@engine_examples(25)
@given(n=st.integers(10, 60), phi=st.floats(0.05, 0.6), seed=st.integers(0, 10_000),
       periodic=st.booleans(), restitution=st.sampled_from([None, 1.0]))
def test_random_small_systems(n, phi, seed, periodic, restitution):
    """No overlap, energy kept (ξ = 1), momentum kept (periodic), time never runs back."""
    radius = radius_for_packing(n, phi)
    boundary = Boundary(periodic=(periodic, periodic))
    position = hexagonal_lattice(n, radius, periodic=boundary.periodic, seed=seed)
    engine = Engine(position, fixed_speed(n, 1.0, seed=seed), radius, boundary=boundary,
                    restitution=restitution)
    e0, p0 = engine.kinetic_energy(), engine.momentum()
    times = []
    for _ in range(5):
        engine.run(collisions=engine.collisions + 200)
        times.append(engine.time)
    assert np.all(np.diff(times) >= 0.0)
    conserves_energy(engine, e0, rel=1e-11)
    if periodic:
        np.testing.assert_allclose(engine.momentum(), p0, atol=1e-11 * math.sqrt(n))
    assert_no_overlap(engine)
