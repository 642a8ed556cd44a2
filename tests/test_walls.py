"""Thermal, moving and vibrating walls: the temperatures they impose, the work they do, the
energy balance of a driven gas, and contacts with a vibrating floor that never miss."""

import math

import numpy as np
import pytest
from scipy import stats

from conftest import assert_no_overlap
from sim.effects.walls import wall_state
from sim.engine import Boundary, ClosedBoxError, Engine, InelasticCollapseError
from sim.pipeline.initial import fixed_speed, radius_for_packing, random_sequential

ALL_THERMAL = {name: {"temperature": 2.0} for name in ("left", "right", "bottom", "top")}


def dilute_gas(n=200, phi=0.05, seed=1, **options):
    radius = radius_for_packing(n, phi)
    position = random_sequential(np.full(n, radius), seed=seed)
    return Engine(position, fixed_speed(n, 1.0, seed=seed + 1), radius, **options)


@pytest.mark.slow  # an elastic gas between thermal walls: no quick variant
def test_thermal_walls_bring_an_elastic_gas_to_their_temperature():
    """Elastic disks between walls at T_w reach equilibrium at T_w: energies m v²/2 are
    exponential with mean T_w (docs/physics.md, "Maxwell–Boltzmann in two dimensions")."""
    engine = dilute_gas(walls=ALL_THERMAL, seed=3)
    engine.run(collisions=20_000)
    energies = []
    for _ in range(40):
        engine.run(collisions=engine.collisions + 2_000)
        energies.append(0.5 * np.sum(engine.velocities() ** 2, axis=1))
    energies = np.concatenate(energies)
    assert energies.mean() == pytest.approx(2.0, rel=0.03)
    assert stats.kstest(energies[::40], "expon", args=(0.0, 2.0)).pvalue > 0.01
    assert engine.kinetic_energy() - engine.initial_energy == pytest.approx(
        engine.wall_work, rel=1e-12)


def test_driven_inelastic_gas_reaches_a_steady_state_where_input_balances_dissipation():
    """ξ = 0.9 disks between walls at T_w = 2: after a transient, what the walls put in equals
    what collisions dissipate, and at every moment E = E₀ + W − D to round-off."""
    engine = dilute_gas(n=400, phi=0.1, restitution=0.9, walls=ALL_THERMAL, seed=5)
    engine.run(collisions=100_000)
    work, lost = engine.wall_work, engine.dissipated_energy
    energy = engine.kinetic_energy()
    engine.run(collisions=engine.collisions + 400_000)
    put_in, dissipated = engine.wall_work - work, engine.dissipated_energy - lost
    assert put_in / dissipated == pytest.approx(1.0, abs=0.01)
    assert abs(engine.kinetic_energy() - energy) < 0.01 * dissipated
    balance = engine.initial_energy + engine.wall_work - engine.dissipated_energy
    # round-off of sums of 5e5 terms, against the largest energy summed (as sim.storage.inspect
    # does)
    scale = max(engine.kinetic_energy(), abs(engine.wall_work), engine.dissipated_energy)
    assert abs(engine.kinetic_energy() - balance) < 1e-12 * scale
    assert_no_overlap(engine)


def test_thermal_draws_are_reproducible_and_survive_a_restart():
    first = dilute_gas(n=100, walls={"bottom": {"temperature": 1.0}}, restitution=0.8)
    again = dilute_gas(n=100, walls={"bottom": {"temperature": 1.0}}, restitution=0.8)
    reseeded = Engine(first.positions(), first.velocities(), first.radius,
                      walls={"bottom": {"temperature": 1.0}}, restitution=0.8, seed=7)
    first.run(collisions=5_000)
    state = {k: np.array(v) for k, v in first.state_dict().items()}
    first.run(collisions=10_000)
    again.run(collisions=10_000)
    reseeded.run(collisions=10_000)
    assert np.array_equal(first.velocities(), again.velocities())
    assert not np.array_equal(first.velocities(), reseeded.velocities())
    restarted = dilute_gas(n=100, walls={"bottom": {"temperature": 1.0}}, restitution=0.8)
    restarted.load_state_dict(state)
    restarted.run(collisions=10_000)
    assert np.array_equal(first.velocities(), restarted.velocities())
    assert first.wall_work == restarted.wall_work


@pytest.mark.slow  # an elastic gas and a piston: no quick variant
def test_slow_piston_compresses_a_dilute_gas_adiabatically():
    """Quasi-static adiabatic compression: N dT = −P dA with P = N T Z/A gives
    d ln T = −Z d ln A; with the low-density Z = 1 + 2φ (docs/physics.md, the second virial
    coefficient) and the area open to disk centres, (Lx − 2R)(Ly − 2R), halving the box takes T to
    (A₀'/A₁') exp(2(φ₁ − φ₀)) T₀ = 2.106 T₀ here (2 for a point-particle ideal gas, γ = 2).
    The energy gained is the piston's work to round-off."""
    speed, n = -0.02, 200
    engine = dilute_gas(n=n, phi=0.02, seed=7, walls={"top": {"speed": speed}})
    t_half = 0.5 / -speed
    t0 = engine.kinetic_energy() / n
    engine.run(time=t_half)
    assert engine.wall_positions(t_half)[3] == pytest.approx(0.5, rel=1e-12)
    radius = engine.radius[0]
    adiabat = (1 - 2 * radius) / (0.5 - 2 * radius) * math.exp(2 * (0.04 - 0.02))
    assert engine.kinetic_energy(t_half) / n / t0 == pytest.approx(adiabat, rel=0.02)
    assert engine.kinetic_energy() - engine.initial_energy == pytest.approx(engine.wall_work,
                                                                            rel=1e-12)
    assert np.all(engine.positions()[:, 1] + engine.radius <= 0.5 + 1e-12)
    assert_no_overlap(engine)


@pytest.mark.slow  # an elastic gas and a piston: no quick variant
def test_piston_that_jams_the_disks_stops_the_run_with_an_error():
    """Driven at constant speed, a piston packs the disks until their collision rate and
    energy diverge (here near φ = 0.76, before the walls meet): a clear error, no hang."""
    engine = dilute_gas(n=50, phi=0.05, walls={"right": {"speed": -0.2}})
    with pytest.raises(ClosedBoxError, match="jammed"):
        engine.run(time=10.0)
    assert engine.time < engine.closing_time
    packing = float(np.sum(np.pi * engine.radius**2)) / engine.wall_positions()[1]
    assert 0.6 < packing < 0.8


@pytest.mark.slow  # an elastic disk and a piston: no quick variant
def test_a_lone_disk_squeezed_by_a_piston_is_stopped_before_the_walls_meet():
    """One disk between a wall and a piston: v L is an adiabatic invariant, so its energy
    diverges as the gap closes on its diameter at t = 9."""
    engine = Engine([[0.5, 0.5]], [[0.0, 0.0]], 0.05, walls={"right": {"speed": -0.1}})
    assert engine.closing_time == pytest.approx(9.0)
    with pytest.raises(ClosedBoxError, match="piston"):
        engine.run(time=10.0)
    assert engine.time < 9.0


def floor_gap(engine, t):
    """Gap between each disk and the floor at absolute time t."""
    floor = wall_state(engine.wall_motion, 2, t, engine.geometry)[0]
    return engine.positions(t)[:, 1] - engine.radius - floor


def ball_on_vibrating_floor(tc):
    """A ball (ξ_w = 0.7) dropped on a floor moving as A sin(ω t) under gravity, Γ = A ω²/g = 3.
    Its ξ acts on no contact of a lone ball (on for the vibrated bed's compiled variant)."""
    g, amplitude, omega = 1.0, 0.01, math.sqrt(3.0 / 0.01)
    return Engine([[0.5, 0.06]], [[0.0, 0.0]], 0.05, gravity=[0.0, -g], tc=tc,
                  restitution=0.7, wall_restitution=0.7,
                  walls={"bottom": {"amplitude": amplitude, "frequency": omega}})


def test_ball_on_a_vibrating_floor_meets_it_exactly_and_never_sinks_into_it():
    """For 100 periods of the floor: at every contact the gap is zero to round-off, in every
    free flight the floor stays below the ball, the ball keeps taking off (the TC model stops
    it from locking onto the floor), and kinetic + potential + dissipated − work is constant."""
    engine = ball_on_vibrating_floor(tc=1e-4)
    period = 2.0 * math.pi / engine.wall_motion[2, 2]
    energy = engine.kinetic_energy() + engine.potential_energy()
    heights = []
    while engine.time < 100 * period:
        flight = np.linspace(engine.time, engine.next_event_time(), 8)
        gaps = np.array([floor_gap(engine, t)[0] for t in flight])
        assert gaps.min() >= -1e-15
        heights.append((engine.time, gaps.max()))
        contacts = engine.wall_contacts
        engine.run(contacts=contacts + 1)
        if engine.wall_contacts > contacts:  # a contact, not a re-prediction
            assert abs(floor_gap(engine, engine.time)[0]) <= 1e-14
            floor_speed = wall_state(engine.wall_motion, 2, engine.time, engine.geometry)[1]
            assert engine.velocities()[0, 1] >= floor_speed
    late = [height for t, height in heights if t > 80 * period]
    assert max(late) > 0.01  # still flying higher than the floor's amplitude
    balance = (engine.kinetic_energy() + engine.potential_energy() + engine.dissipated_energy
               - engine.wall_work - energy)
    assert abs(balance) <= 1e-13 * engine.wall_work


@pytest.mark.slow  # restitution without the TC model on a vibrating floor: no quick variant
def test_ball_on_a_vibrating_floor_without_tc_locks_on_and_is_reported():
    """Without the TC model the ball comes to rest on the floor through ever faster bounces
    while the floor pushes it up: inelastic collapse, reported instead of hanging."""
    engine = ball_on_vibrating_floor(tc=None)
    with pytest.raises(InelasticCollapseError, match="TC model"):
        engine.run(time=100.0)


def vibrated_bed(tc, n=300, seed=2):
    radius = 0.01
    position = random_sequential(np.full(n, radius), box=(1.0, 1.0),
                                 region=((0.0, 1.0), (0.0, 0.35)), seed=seed)
    return Engine(position, np.zeros((n, 2)), radius, boundary=Boundary(size=(1.0, 1.0)),
                  gravity=[0.0, -1.0], restitution=0.8, wall_restitution=0.8, tc=tc,
                  walls={"bottom": {"amplitude": 0.01, "frequency": 20.0}})


def test_vibrated_bed_with_tc_runs_on_without_collapse_or_overlap():
    """A shaken bed (Γ = 4) of ξ = 0.8 disks rests on the floor part of every cycle, where the
    contacts of other event-driven codes collapse. Here it reaches a steady state for 30
    periods: kinetic energy of the order of the floor's, N m (A ω)²/2, and the floor's work
    balanced by dissipation."""
    engine = vibrated_bed(tc=1e-4)
    period = 2.0 * math.pi / 20.0
    floor_scale = 0.5 * engine.n * (0.01 * 20.0) ** 2
    energy0 = engine.kinetic_energy() + engine.potential_energy()
    kinetic = []
    for k in range(30):
        engine.run(time=(k + 1) * period)
        kinetic.append(engine.kinetic_energy())
        if k == 19:
            work, lost = engine.wall_work, engine.dissipated_energy
        if k % 5 == 4:
            assert_no_overlap(engine)
    assert min(kinetic[10:]) > 0.3 * floor_scale
    assert (engine.wall_work - work) / (engine.dissipated_energy - lost) == pytest.approx(
        1.0, abs=0.1)
    balance = (engine.kinetic_energy() + engine.potential_energy() + engine.dissipated_energy
               - engine.wall_work - energy0)
    assert abs(balance) <= 1e-12 * engine.dissipated_energy
