"""Event engine: exact paths, conservation laws, bookkeeping, stop conditions, determinism."""

import math

import numba
import numpy as np
import pytest

from conftest import assert_no_overlap, gas
from sim.checks.audit import overlapping_pairs
from sim.engine import Boundary, Engine, InelasticCollapseError
from sim.engine.codes import SHELL_EXITS, STALE_EVENTS
from sim.engine.groups import Box
from sim.engine.kinematics import DISK_COLUMNS, VX, VY, X, Y
from sim.engine.neighbours import shell_centre
from sim.engine.sizing import LIST_GROWTH, packing_fraction_around_disks, shell_ratio
from sim.pipeline.initial import PlacementError, hexagonal_lattice, random_sequential
from variants import UNREACHED_THERMAL_WALL


def triangle_wave(s, low, high):
    """Position of a point bouncing between low and high after travelling s from low."""
    span = high - low
    phase = np.mod(s, 2.0 * span)
    return low + np.where(phase < span, phase, 2.0 * span - phase)


def test_single_disk_traces_tilted_rectangle_for_10000_wall_events():
    """Launched at 45° from the middle of the left wall, the disk visits the middles of the
    four walls in turn: x and y are triangle waves of the distance travelled."""
    radius = 0.05
    v = np.array([1.0, 1.0]) / math.sqrt(2.0)
    engine = Engine([[radius, 0.5]], [v], radius)
    energy = engine.kinetic_energy()
    side = 1.0 - 2.0 * radius
    for t in np.linspace(0.0, 5_000 * side / v[0], 101)[1:]:
        engine.run(time=t)
        expected = [triangle_wave(v[0] * t, radius, 1 - radius),
                    triangle_wave(0.5 - radius + v[1] * t, radius, 1 - radius)]
        np.testing.assert_allclose(engine.positions(t)[0], expected, rtol=0, atol=1e-9)
    assert engine.wall_contacts == pytest.approx(10_000, abs=1)
    assert engine.kinetic_energy() == energy


@pytest.mark.parametrize("periodic", [(False, False), (True, True)])
def test_elastic_energy_drift_over_a_million_collisions(periodic):
    engine = gas(10_000, 0.5, periodic, seed=3)
    energy = engine.kinetic_energy()
    engine.run(collisions=1_000_000)
    assert abs(engine.kinetic_energy() / energy - 1.0) <= 1e-12
    assert_no_overlap(engine)


@pytest.mark.parametrize("phi", [0.3, 0.72, 0.85])
@pytest.mark.parametrize("periodic", [(False, False), (True, False), (True, True)])
def test_no_overlap_and_no_escape(phi, periodic):
    engine = gas(2000, phi, periodic, seed=5)
    for _ in range(5):
        engine.run(collisions=engine.collisions + 40_000)
        assert_no_overlap(engine)


def test_momentum_conserved_in_periodic_box():
    engine = gas(1000, 0.4, (True, True), seed=7, restitution=0.8, tc=1e-6)
    p0 = engine.momentum()
    engine.run(collisions=100_000)
    assert engine.momentum() == pytest.approx(p0, abs=1e-12 * engine.n)
    assert_no_overlap(engine)


def test_dissipation_bookkeeping_is_exact():
    """E0 + W − E = Σ (1 − ξ²) μ v_n²/2 over disk contacts + Σ (1 − ξ_w²) m v_n²/2 over walls,
    E the kinetic and potential energy of a gas falling under gravity onto a vibrating floor
    as it cools, W the work of the floor (the vibrated bed's variant: tests/variants.py)."""
    engine = gas(1000, 0.3, seed=11, restitution=0.8, wall_restitution=0.9, tc=1e-7,
                 gravity=[0.0, -1.0], walls={"bottom": {"amplitude": 0.01, "frequency": 20.0}})
    e0 = engine.kinetic_energy() + engine.potential_energy()
    engine.run(collisions=50_000)
    lost = e0 + engine.wall_work - engine.kinetic_energy() - engine.potential_energy()
    assert lost > 0.5 * e0
    assert engine.wall_work != 0.0
    assert engine.dissipated_energy == pytest.approx(lost, rel=1e-12)
    assert_no_overlap(engine)


def test_energy_fraction_stop_is_at_the_crossing_collision():
    engine = gas(500, 0.3, seed=2, restitution=0.7, tc=1e-7)
    e0 = engine.kinetic_energy()
    assert engine.run(energy_fraction=0.1) == "energy_fraction"
    assert engine.kinetic_energy() <= 0.1 * e0
    # the collision before the last one had not yet crossed
    last = engine.dissipated_energy
    assert e0 - last <= 0.1 * e0 < e0 - last + 0.5 * e0


def test_time_reversal_returns_to_the_start():
    """Round-off grows with the Lyapunov exponent; in a dense fluid (φ = 0.6, mean free path
    ≈ 0.1 σ) 1000 collisions of 100 disks there and back stay well inside 1e-8."""
    engine = gas(100, 0.6, (True, True), seed=13)
    start = engine.positions()
    engine.run(collisions=1000)
    t = engine.time
    back = Engine(engine.positions(), -engine.velocities(), engine.radius,
                  boundary=engine.boundary)
    back.run(time=t)
    d = back.positions(t) - start
    d -= np.round(d)
    assert np.abs(d).max() < 1e-8
    assert back.collisions == 1000


def test_construction_applies_no_event_even_at_a_contact_at_t0():
    """The first predictions run through the event loop at t = 0; a contact due at t = 0 is
    scheduled there and applied by run(), not by the constructor."""
    radius = 0.05
    position = np.array([[0.4, 0.5], [0.5, 0.5], [0.2, 0.2]])
    velocity = np.array([[1.0, 0.0], [-1.0, 0.0], [0.3, 0.1]])
    engine = Engine(position, velocity, radius)
    assert (engine.events, engine.collisions, engine.time) == (0, 0, 0.0)
    assert engine.next_event_time() == 0.0
    np.testing.assert_array_equal(engine.velocities(), velocity)
    engine.run(collisions=1)
    assert engine.time == 0.0
    np.testing.assert_array_equal(engine.velocities()[:2], velocity[[1, 0]])


def test_stop_exactly_at_requested_time_and_positions_there():
    engine = gas(400, 0.3, seed=17)
    assert engine.run(time=0.25) == "time"
    assert engine.time <= 0.25
    assert engine.next_event_time() > 0.25
    before = engine.positions()
    at = engine.positions(0.25)
    assert at == pytest.approx(before + engine.velocities() * (0.25 - engine.time), abs=1e-14)


def test_until_predicate_and_wall_clock_budget():
    engine = gas(400, 0.3, seed=19)
    reason = engine.run(until=lambda e: e.collisions >= 5000, chunk_events=1000)
    assert reason == "predicate" and 5000 <= engine.collisions < 5000 + 1000
    assert engine.run(wall_seconds=0.05, chunk_events=1000) == "wall_seconds"


def test_same_inputs_same_bits_whatever_the_chunking():
    a = gas(500, 0.5, (True, False), seed=23, restitution=0.9, tc=1e-6)
    b = gas(500, 0.5, (True, False), seed=23, restitution=0.9, tc=1e-6)
    a.run(collisions=30_000)
    b.run(collisions=30_000, chunk_events=777)
    np.testing.assert_array_equal(a.positions(), b.positions())
    np.testing.assert_array_equal(a.velocities(), b.velocities())
    assert a.time == b.time


def test_full_neighbour_lists_grow_without_changing_the_physics():
    roomy = gas(800, 0.6, (True, True), seed=37)
    tight = gas(800, 0.6, (True, True), seed=37, list_capacity=1)
    # grown while the lists were first built, all alike and by LIST_GROWTH entries at a time
    capacity = tight.disks.nb_cap
    assert capacity[0] > 1 and np.all(capacity == capacity[0])
    assert (capacity[0] - 1) % LIST_GROWTH == 0
    roomy.run(collisions=40_000)
    tight.run(collisions=40_000)
    assert tight.time == pytest.approx(roomy.time, rel=1e-12)
    np.testing.assert_allclose(tight.velocities(), roomy.velocities(), rtol=0, atol=1e-9)
    assert_no_overlap(tight)


def test_renumbering_disks_by_cell_leaves_the_physics_alone():
    a = gas(2000, 0.5, (True, False), seed=41)
    b = gas(2000, 0.5, (True, False), seed=41)
    b.reorder()
    assert not np.array_equal(b.disks.order, np.arange(2000))
    for _ in range(4):
        a.run(collisions=a.collisions + 10_000)
        b.run(collisions=b.collisions + 10_000)
        b.reorder()
    np.testing.assert_array_equal(a.positions(), b.positions())
    np.testing.assert_array_equal(a.velocities(), b.velocities())
    np.testing.assert_array_equal(a.contacts_by_disk(), b.contacts_by_disk())
    assert_no_overlap(b)


def test_large_systems_renumber_as_they_run():
    engine = gas(25_000, 0.5, (True, True), seed=43)
    energy = engine.kinetic_energy()
    engine.run(until=lambda e: e.events >= 3 * e.reorder_every, chunk_events=engine.reorder_every)
    assert engine.events == 3 * engine.reorder_every
    cells = engine.disks.cell_of
    assert np.mean(np.diff(cells[cells >= 0]) >= 0) > 0.9  # nearly sorted by cell
    assert engine.kinetic_energy() == pytest.approx(energy, rel=1e-12)
    assert_no_overlap(engine)


def state_buffer_span(disks):
    """(first byte, end byte) of the state's non-empty arrays, asserting each starts on a
    cache line."""
    spans = []
    for name, array in disks.arrays().items():
        if array.size == 0:
            continue
        start = array.__array_interface__["data"][0]
        assert start % 64 == 0, name
        spans.append((start, start + array.nbytes))
    return min(s for s, _ in spans), max(e for _, e in spans)


def test_state_stays_in_one_buffer_through_renumbering_and_list_growth():
    """One buffer, on a 2 MiB boundary, each array on a cache line (sim.engine.state.one_buffer),
    also after a renumbering and after the lists grow."""
    engine = gas(800, 0.6, (True, True), seed=37, list_capacity=1)
    for change in (lambda: None, engine.reorder, lambda: engine._grow_lists(0)):
        change()
        first, end = state_buffer_span(engine.disks)
        assert first % (2 << 20) == 0
        assert end - first < engine.disks.nbytes + 64 * len(engine.disks.arrays())
    engine.run(collisions=5_000)
    assert_no_overlap(engine)


def test_shells_follow_the_packing_fraction_around_the_disks():
    """A gas filling the box sees the box's φ; a bed filling its lower half sees twice that,
    and gets the shells of its own density (the crater bed); under 64 disks, the box's φ."""
    radius = 0.0045
    box = np.array([1.0, 1.0])
    gas_fill = random_sequential(np.full(4000, radius), seed=1)
    bed = random_sequential(np.full(4000, radius), region=((0, 1), (0, 0.5)), seed=1)
    phi_box = 4000 * np.pi * radius**2
    assert packing_fraction_around_disks(gas_fill, np.full(4000, radius), box) == pytest.approx(
        phi_box, rel=0.03)
    phi_bed = packing_fraction_around_disks(bed, np.full(4000, radius), box)
    assert phi_bed == pytest.approx(2 * phi_box, rel=0.05)
    few = gas_fill[:50]
    assert packing_fraction_around_disks(few, np.full(50, radius), box) == pytest.approx(
        50 * np.pi * radius**2, rel=1e-12)
    engine = Engine(bed, np.zeros((4000, 2)), radius)
    reach = radius + 0.5 * (shell_ratio(phi_bed) - 1.0) * 2.0 * radius
    assert engine.geometry[4] == pytest.approx(reach, rel=1e-12)


def test_shell_centre_leads_its_disk_by_a_fraction_of_the_shell():
    """λ δ ahead along the velocity, wrapped on a periodic axis; a disk at rest or too slow
    ever to reach its shell is centred on itself."""
    disks = np.zeros((4, DISK_COLUMNS))
    disks[:, X:Y + 1] = [[0.5, 0.5], [0.5, 0.5], [0.5, 0.5], [0.998, 0.5]]
    disks[:, VX:VY + 1] = [[3.0, -4.0], [1e-150, 0.0], [0.0, 0.0], [2.0, 0.0]]
    geometry = np.array([1.0, 1.0, 0.1, 0.1, 0.05, 0.8])
    grid = np.array([10, 10, 1, 0])
    delta = 0.01
    assert shell_centre(0, disks, delta, Box(geometry, grid)) == pytest.approx(
        (0.5 + 0.008 * 0.6, 0.5 - 0.008 * 0.8), abs=1e-15)
    assert shell_centre(1, disks, delta, Box(geometry, grid)) == (0.5, 0.5)
    assert shell_centre(2, disks, delta, Box(geometry, grid)) == (0.5, 0.5)
    assert shell_centre(3, disks, delta, Box(geometry, grid)) == pytest.approx((0.006, 0.5),
                                                                          abs=1e-15)


@pytest.mark.parametrize("periodic", [(True, True), (False, False)])
def test_shells_ahead_of_their_disks_save_exits_and_change_no_physics(periodic):
    """A new shell centred λ δ ahead of its disk (:func:`sim.engine.neighbours.shell_centre`): in a
    dilute gas fewer shell exits per collision than with shells centred on the disk (at
    φ = 0.1, N = 1e4: 2.09 against 1.47 for λ = 0.7 and 1.41 for 0.85), the same collisions
    at the same times, no overlap."""
    centred = gas(2000, 0.1, periodic, seed=3, shell_lead=0.0)
    ahead = gas(2000, 0.1, periodic, seed=3, shell_lead=0.8)
    for engine in (centred, ahead):
        engine.run(collisions=4000)
    assert ahead.counters[SHELL_EXITS] < 0.8 * centred.counters[SHELL_EXITS]
    assert ahead.time == pytest.approx(centred.time, rel=1e-12)
    assert ahead.wall_contacts == centred.wall_contacts
    d = ahead.positions(centred.time) - centred.positions(centred.time)
    assert np.abs(d - np.round(d) if periodic[0] else d).max() < 1e-9
    assert_no_overlap(ahead)
    with pytest.raises(ValueError, match="shell_lead"):
        gas(50, 0.1, periodic, shell_lead=1.0)


def test_contacts_are_left_to_partners_with_earlier_events():
    """A disk schedules its contact with j only if it comes no later than j's own next event
    (j, predicted again at that event, finds the contact itself if it still comes): far fewer
    of the events popped are stale (at φ = 0.5, 0.20 per collision without the rule, 0.08
    with it), no contact is lost (``tests/test_reference.py``) and nothing overlaps."""
    engine = gas(2000, 0.5, (True, True), seed=5)
    engine.run(collisions=20_000)
    stale, collisions = engine.counters[STALE_EVENTS], engine.collisions
    engine.run(collisions=collisions + 40_000)
    assert (engine.counters[STALE_EVENTS] - stale) / (engine.collisions - collisions) < 0.12
    assert_no_overlap(engine)


def test_rebased_clock_keeps_the_trajectory():
    """Restarting the clock every few events does not change the physics beyond round-off."""
    a = gas(300, 0.3, (True, True), seed=29)
    b = gas(300, 0.3, (True, True), seed=29)
    b.rebase_every = 100
    a.run(collisions=500)
    b.run(collisions=500)
    assert b.time == pytest.approx(a.time, rel=1e-13)
    assert b.accumulators[0] > 0.0  # b's clock was restarted (its origin moved)
    d = a.positions(a.time) - b.positions(a.time)
    assert np.abs(d - np.round(d)).max() < 1e-9


def test_inelastic_collapse_is_detected_and_tc_cures_it():
    """Three disks in a row at ξ = 0.05 < 7 − 4√3 collapse (McNamara & Young 1992). They move
    along y = 0.5 (every contact normal along x), so the thermal wall above is never reached.
    (A t_c > 0, however short, is no stand-in for the model off: the collapsing contacts come
    to coincide in float64 time, and contacts closer than t_c are elastic.)"""
    radius = 0.01
    x = np.array([0.4, 0.5, 0.6])
    position = np.stack([x, np.full(3, 0.5)], axis=1)
    velocity = [[1.0, 0.0], [0.0, 0.0], [-0.7, 0.0]]
    engine = Engine(position, velocity, radius, restitution=0.05,
                    walls=UNREACHED_THERMAL_WALL)
    with pytest.raises(InelasticCollapseError, match="TC model") as caught:
        engine.run(collisions=1_000_000)
    assert set(caught.value.disks) == {0, 1, 2}
    assert engine.wall_contacts == 0
    cured = Engine(position, velocity, radius, restitution=0.05, tc=1e-6)
    assert cured.run(collisions=100_000, time=10.0) in {"collisions", "time"}
    assert_no_overlap(cured)


def projectile_in_bed(n_bed, bed_radius, projectile_radius, seed, speed=10.0, **effects):
    """The crater scene: a bed of ``n_bed`` disks (species 0, mass 1) at rest in the lower
    half of the unit box and a projectile (species 1, mass ∝ area) falling into it at
    ``speed`` from (0.5, 0.75). With ξ, ξ_w and t_c it runs the crater's compiled loop."""
    bed = random_sequential(np.full(n_bed, bed_radius), region=((0, 1), (0, 0.5)), seed=seed)
    position = np.vstack([bed, [[0.5, 0.75]]])
    velocity = np.vstack([np.zeros((n_bed, 2)), [[0.0, -speed]]])
    radius = np.append(np.full(n_bed, bed_radius), projectile_radius)
    mass = np.append(np.ones(n_bed), (projectile_radius / bed_radius) ** 2)
    species = np.append(np.zeros(n_bed, dtype=int), 1)
    return Engine(position, velocity, radius, mass, species, **effects)


def test_heavy_big_projectile_in_a_bed_of_small_disks():
    engine = projectile_in_bed(3000, 0.0045, 0.05, seed=31, restitution=0.5,
                               wall_restitution=0.5, tc=1e-8)
    assert engine.disks.is_big.sum() == 1 and engine.disks.big.size == 1
    e0 = engine.kinetic_energy()
    engine.run(energy_fraction=0.1, collisions=3_000_000)
    assert engine.kinetic_energy() == pytest.approx(e0 - engine.dissipated_energy, rel=1e-10)
    assert engine.positions()[-1, 1] < 0.75
    assert_no_overlap(engine)


def test_random_placement_fails_clearly_beyond_its_reach():
    with pytest.raises(PlacementError, match=r"0\.547.*lattice"):
        random_sequential(np.full(1000, math.sqrt(0.7 / (1000 * math.pi))), seed=1)


def test_lattice_reaches_dense_packings_without_overlap():
    # 20 × 24 sites fit a periodic box of aspect 24 (√3/2) / 20 with perfect triangles
    n, box, periodic = 480, (1.0, 24 * math.sqrt(3.0) / 2.0 / 20), (True, True)
    radius = math.sqrt(0.9 * box[0] * box[1] / (n * math.pi))
    position = hexagonal_lattice(n, radius, box=box, periodic=periodic, seed=1)
    engine = Engine(position, np.zeros((n, 2)), radius,
                    boundary=Boundary(size=box, periodic=periodic))
    assert_no_overlap(engine)
    radius = math.sqrt(0.85 / (1000 * math.pi))
    for periodic in [(False, False), (True, True)]:
        square = hexagonal_lattice(1000, radius, periodic=periodic)
        assert overlapping_pairs(square, radius, periodic=periodic)[0].size == 0


def test_bad_input_is_rejected():
    with pytest.raises(ValueError, match="pokes through a wall"):
        Engine([[0.0, 0.5]], [[1.0, 0.0]], 0.1)
    with pytest.raises(ValueError, match="restitution"):
        Engine([[0.5, 0.5]], [[1.0, 0.0]], 0.1, restitution=1.5)
    with pytest.raises(ValueError, match="radius"):
        Engine([[0.5, 0.5]], [[1.0, 0.0]], -0.1)
    with pytest.raises(ValueError, match=r"must exceed 2 \(R_1 \+ R_2\) = 1.02"):
        Engine([[0.25, 0.25], [0.75, 0.75]], [[1.0, 0.0], [0.0, 1.0]], [0.26, 0.25],
               boundary=Boundary(periodic=(True, True)))


def test_neutral_effects_run_the_code_of_absent_ones():
    """ξ = 1, ξ_w = 1, t_c = 0, equal masses and one species switch nothing on: the engine
    passes the compiled loop what it passes when they are absent, so it runs the same
    specialisation (and the same bits)."""
    absent = gas(400, 0.4, seed=71)
    n = absent.n
    neutral = gas(400, 0.4, seed=71, restitution=1.0, wall_restitution=1.0, tc=0.0,
                  mass=np.full(n, 1.0), species=np.zeros(n, dtype=int))
    assert (neutral.restitution, neutral.wall_restitution, neutral.tc) == (None, None, None)
    assert neutral._per_disk_parameters() == absent._per_disk_parameters()
    assert neutral._list_layout() == absent._list_layout()
    absent.run(collisions=20_000)
    neutral.run(collisions=20_000)
    np.testing.assert_array_equal(neutral.positions(), absent.positions())
    species = np.arange(n) % 2
    mixture = gas(400, 0.4, seed=71, mass=1.0 + species, species=species)
    assert all(isinstance(value, np.ndarray) for value in mixture._per_disk_parameters()[1:])


@pytest.mark.parametrize("species", [1, 2])
def test_one_restitution_however_given_compiles_one_loop(species):
    """ξ given as a number or as the matrix it stands for reaches the compiled loop as the
    same numba type (a read-only view would be typed apart and compile the loop again)."""
    def restitution(xi):
        # scenes of other tests (a cooling gas; the crater's bed and projectile), so that no
        # variant of the loop is compiled for this one
        if species == 1:
            engine = gas(10, 0.2, seed=3, restitution=xi, tc=1e-6)
        else:
            engine = projectile_in_bed(10, 0.02, 0.1, seed=3, restitution=xi,
                                       wall_restitution=0.5, tc=1e-6)
        assert engine.n_species == species
        return engine.restitution

    s = species
    types = {numba.typeof(restitution(xi)) for xi in (0.9, np.full((s, s), 0.9),
                                                        [[0.9] * s] * s)}
    assert len(types) == 1, types
