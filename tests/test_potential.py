"""Stepped pair potentials (sim.effects.potential): square wells and shoulders around the hard
core. Every quick test here runs the quick suite's one compiled variant of them (the
square_well scene's: a stepped potential and thermal walls, every disk alike; a pair of disks
gets a thermal wall it never reaches); inelastic cores and mixtures are slow tests."""

import math

import numpy as np
import pytest

from conftest import assert_no_overlap, distances
from sim.checks.potential import second_virial_coefficient
from sim.effects.potential import loop_values
from sim.engine import Boundary, Engine
from sim.pipeline.initial import maxwellian, random_sequential, remove_drift
from sim.pipeline.runner import build_engine
from variants import UNREACHED_THERMAL_WALL, compose_scene


def _shells_by_distance(engine, steps, slack):
    """The shell of every pair (i < j, the user's numbering) by its distance over σ: the
    pairs surely in each shell (1 … K; 0 beyond) and those maybe in it, within ``slack``."""
    distance = distances(engine) / (2.0 * engine.radius[0])
    upper = np.triu(np.ones(distance.shape, bool), 1)
    edges = np.array([1.0, *steps, np.inf])
    surely, maybe = {}, {}
    for k in range(1, len(edges)):
        shell = k if k < len(edges) - 1 else 0
        surely[shell] = {tuple(p) for p in np.argwhere(
            upper & (distance > edges[k - 1] * (1 + slack)) & (distance < edges[k] * (1 - slack)))}
        maybe[shell] = {tuple(p) for p in np.argwhere(
            upper & (distance > edges[k - 1] * (1 - slack)) & (distance < edges[k] * (1 + slack)))}
    return surely, maybe


def _shells_by_state(engine):
    """{shell: pairs (i < j)} of the listed pairs, from their states (shell 0 not listed)."""
    d = engine.disks
    shells = {}
    for i in range(engine.n):
        for k in range(d.nb_start[i], d.nb_start[i] + d.nb_count[i]):
            a, b = int(d.order[i]), int(d.order[d.nb[k]])
            shells.setdefault(int(d.pair_state[k]), set()).add((min(a, b), max(a, b)))
    return shells


def test_a_square_well_gas_keeps_its_energy_and_its_pair_states():
    """The square_well scene (N = 300): kinetic plus potential energy less the work of the
    thermal walls constant to round-off, no overlap, and every pair's state the shell its
    distance puts it in, through many crossings of the well's edge, bounces off it and core
    contacts; and the gas condenses."""
    engine = build_engine(compose_scene("square_well"))
    steps = [1.5]
    total = engine.kinetic_energy() + engine.potential_energy()
    start = engine.potential_energy()
    assert start < 0.0
    for end in np.linspace(0.5, 5.0, 6):
        engine.run(time=end)
        assert_no_overlap(engine)
        assert engine.kinetic_energy() + engine.potential_energy() - engine.wall_work \
            == pytest.approx(total, rel=1e-12, abs=1e-12 * engine.kinetic_energy())
        surely, maybe = _shells_by_distance(engine, steps, 1e-9)
        by_state = _shells_by_state(engine)
        assert surely[1] <= by_state.get(1, set()) <= maybe[1]
    assert engine.collisions > 20 * engine.n
    assert engine.events > engine.collisions + engine.n  # crossings and bounces as well
    assert engine.potential_energy() < start - 0.5 * engine.n  # half a well per disk more


@pytest.mark.slow  # inelastic cores with a stepped potential: no quick variant
def test_cohesive_granular_disks_say_what_their_inelastic_cores_dissipated():
    """The square_well scene with inelastic cores (ξ = 0.8): kinetic plus potential energy
    plus what the cores dissipated, less the work of the thermal walls, constant to
    round-off; no overlap; the cores dissipate, and the steps, elastic, do not."""
    engine = build_engine(compose_scene("square_well", "restitution.disk=0.8"))
    total = engine.kinetic_energy() + engine.potential_energy()
    for end in np.linspace(0.5, 3.0, 4):
        engine.run(time=end)
        assert_no_overlap(engine)
        assert engine.kinetic_energy() + engine.potential_energy() \
            + engine.dissipated_energy - engine.wall_work \
            == pytest.approx(total, rel=1e-12, abs=1e-12 * engine.kinetic_energy())
    assert engine.dissipated_energy > 0.01 * engine.kinetic_energy()
    assert engine.events > engine.collisions + engine.n


def test_pair_states_and_energy_resume_to_the_same_bits():
    engine = build_engine(compose_scene("square_well"))
    engine.run(time=1.0)
    state = {key: np.array(value) for key, value in engine.state_dict().items()}
    engine.run(time=2.0)
    resumed = build_engine(compose_scene("square_well"))
    resumed.load_state_dict(state)
    resumed.run(time=2.0)
    assert resumed.positions().tobytes() == engine.positions().tobytes()
    assert resumed.disks.pair_state.tobytes() == engine.disks.pair_state.tobytes()
    assert resumed.potential_energy() == engine.potential_energy()


def _pair(separation, speed, energy, steps=(1.5,)):
    """Two disks of radius 0.01 and mass 1 on the x axis ``separation`` σ apart, each moving
    at ``speed``/2 towards the other (a negative ``speed``: apart), in a box with walls far
    away (a thermal one they never reach), with a potential of ``energy`` out to
    ``steps``."""
    sigma = 0.02
    x = 0.5 - 0.5 * separation * sigma, 0.5 + 0.5 * separation * sigma
    return Engine([[x[0], 0.5], [x[1], 0.5]], [[speed / 2, 0.0], [-speed / 2, 0.0]], 0.01,
                  boundary=Boundary(size=(1.0, 1.0)), potential_steps=list(steps),
                  potential_energies=[energy] * len(steps), walls=UNREACHED_THERMAL_WALL), sigma


def _relative_speed(engine, t):
    v = engine.velocities(t)
    return abs(v[0, 0] - v[1, 0])


@pytest.mark.parametrize("speed, energy, crosses", [(1.0, -1.0, True), (1.0, 1.0, False),
                                                    (3.0, 1.0, True), (2.0, 1.0, False)])
def test_a_pair_crosses_a_step_only_with_the_normal_kinetic_energy_to_pay_for_it(
        speed, energy, crosses):
    """Head on, with μ = 1/2: the pair crosses the step at 1.5 σ when μ v²/2 = v²/4 > ε, its
    relative speed then √(v² − 4 ε), and bounces off it otherwise; after the core contact
    it leaves at its first speed. Kinetic plus potential energy stays v²/4."""
    engine, sigma = _pair(2.0, speed, energy)
    flight = 0.5 * sigma / speed  # to the step, from 2 σ apart
    engine.run(time=1.01 * flight)
    inside = crosses and engine.potential_energy() == energy
    assert inside == crosses
    expected = math.sqrt(speed**2 - 4.0 * energy) if crosses else speed
    assert _relative_speed(engine, 1.01 * flight) == pytest.approx(expected, rel=1e-12)
    assert engine.kinetic_energy() + engine.potential_energy() == pytest.approx(
        speed**2 / 4, rel=1e-12)
    engine.run(time=0.3 / speed)  # apart again, before the walls
    assert _relative_speed(engine, 0.3 / speed) == pytest.approx(speed, rel=1e-12)
    assert engine.potential_energy() == 0.0
    assert engine.collisions == (1 if crosses else 0)


def test_a_pair_without_the_energy_to_leave_its_well_stays_bound():
    """Two disks 1.2 σ apart inside a well of depth 1, moving apart at relative speed 1
    (v²/4 < 1): they bounce off the well's edge and off each other's core for ever, at the
    same speed, never farther than 1.5 σ."""
    engine, sigma = _pair(1.2, -1.0, -1.0)
    for end in np.linspace(0.05, 1.0, 20):
        engine.run(time=end)
        gap = np.diff(engine.positions(end)[:, 0])[0]
        assert sigma <= gap <= 1.5 * sigma * (1 + 1e-12)
        assert _relative_speed(engine, end) == pytest.approx(1.0, rel=1e-12)
    assert engine.potential_energy() == -1.0
    assert engine.collisions > 10



def test_the_second_virial_coefficient_is_the_hard_cores_and_vanishes_at_boyles_temperature():
    """B₂/σ² = π/2 without steps or with zero energies; for a well of width λ it vanishes at
    kT_B/ε = 1/ln(λ²/(λ² − 1)), and a shoulder as high as the core is wide (ε → ∞) gives
    the hard disks of diameter λσ."""
    assert second_virial_coefficient(1.0, [], []) == pytest.approx(math.pi / 2)
    assert second_virial_coefficient(1.0, [1.5], [0.0]) == pytest.approx(math.pi / 2)
    boyle = 1.0 / math.log(1.5**2 / (1.5**2 - 1.0))
    assert second_virial_coefficient(boyle, [1.5], [-1.0]) == pytest.approx(0.0, abs=1e-12)
    assert second_virial_coefficient(1.0, [1.5], [1e3]) == pytest.approx(math.pi / 2 * 1.5**2)


def test_a_table_of_potentials_per_species_pair_is_built_and_an_asymmetric_one_refused():
    """Engine keywords: one potential per species pair, with as many steps as each has (none:
    hard disks); the table must be [s][s] and symmetric."""
    context = {"n_species": 2}
    table = [[[1.5], []], [[], [1.2, 1.4]]]
    energies = [[[-1.0], []], [[], [0.5, -0.5]]]
    value = loop_values({"potential_steps": table, "potential_energies": energies},
                        context)["pair_interaction"]
    assert value.count.tolist() == [[1, 0], [0, 2]]
    assert value.steps[1, 1].tolist() == [1.2, 1.4] and value.energies[0, 0, 0] == -1.0
    assert value.reach.tolist() == [1.5, 1.4]
    one = loop_values({"potential_steps": [1.5], "potential_energies": [-1.0]},
                      context)["pair_interaction"]
    assert one.count.tolist() == [[1, 1], [1, 1]]
    with pytest.raises(ValueError, match="symmetric"):
        loop_values({"potential_steps": [[[1.5], [1.3]], [[1.4], [1.5]]],
                     "potential_energies": [[[-1.0], [-1.0]], [[-1.0], [-1.0]]]}, context)
    with pytest.raises(ValueError, match="table"):
        loop_values({"potential_steps": [[[1.5]]], "potential_energies": [[[-1.0]]]},
                    context)


@pytest.mark.slow  # a mixture with a stepped potential: no quick variant
def test_a_mixture_keeps_the_potential_of_each_species_pair():
    """Two species (radii 1 : 1.4, masses 1 : 2) in a periodic box, a well between small
    disks, a shoulder of two steps between large ones and hard cores between the two: energy
    conserved to round-off, no overlap, and every listed pair's state the shell its distance
    over σ_ij puts it in, by its species pair's steps."""
    n, radius = 400, 0.01
    species = np.arange(n) % 2
    radii = np.where(species == 0, radius, 1.4 * radius)
    mass = np.where(species == 0, 1.0, 2.0)
    position = random_sequential(radii, periodic=(True, True), seed=3)
    velocity = remove_drift(maxwellian(mass, 1.0, seed=4), mass)
    table = [[[1.5], []], [[], [1.2, 1.4]]]
    energies = [[[-1.0], []], [[], [0.8, 0.3]]]
    engine = Engine(position, velocity, radii, mass, species,
                    boundary=Boundary(periodic=(True, True)), potential_steps=table,
                    potential_energies=energies)
    total = engine.kinetic_energy() + engine.potential_energy()
    edges = {(0, 0): [1.0, 1.5], (1, 1): [1.0, 1.2, 1.4]}
    for k in range(1, 6):
        engine.run(collisions=20 * n * k)
        assert_no_overlap(engine)
        assert engine.kinetic_energy() + engine.potential_energy() == pytest.approx(
            total, rel=1e-12)
        r = distances(engine) / (radii[:, None] + radii[None, :])
        for (i, j), shell in _pair_states(engine).items():
            edge = edges.get((int(species[i]), int(species[j])))
            if edge is None:  # hard cores: no shell but 0
                assert shell == 0
                continue
            outer = edge[shell] if shell > 0 else np.inf
            inner = edge[shell - 1] if shell > 0 else edge[-1]
            assert inner * (1 - 1e-9) < r[i, j] < outer * (1 + 1e-9)
    assert engine.potential_energy() != 0.0
    assert engine.events > engine.collisions + n


def _pair_states(engine):
    """{(i, j): shell} of every listed pair (user order, i < j)."""
    return {pair: shell for shell, pairs in _shells_by_state(engine).items() for pair in pairs}
