"""Gravity: parabolic flights, exact bounces, conserved mechanical energy, no collapse on the
floor with the TC model, and a clear error without it."""

import math

import numpy as np
import pytest

from conftest import assert_no_overlap
from sim.engine import Boundary, Engine, InelasticCollapseError, StalledError
from sim.pipeline.initial import hexagonal_lattice, radius_for_packing, random_sequential

G = 9.81


def test_free_flight_is_a_parabola():
    """A disk thrown across the box: r(t) = r0 + v0 t + g t²/2 and v(t) = v0 + g t."""
    r0, v0, g = np.array([0.1, 0.2]), np.array([0.3, 2.0]), np.array([0.0, -G])
    # no contact: restitution and TC model on only to share the settling bed's compiled variant
    engine = Engine([r0], [v0], 0.01, gravity=g, restitution=0.9, wall_restitution=0.9,
                    tc=1e-4)
    for t in np.linspace(0.0, 0.38, 20):
        np.testing.assert_allclose(engine.positions(t)[0], r0 + v0 * t + 0.5 * g * t * t,
                                   rtol=0, atol=1e-15)
        np.testing.assert_allclose(engine.velocities(t)[0], v0 + g * t, rtol=0, atol=1e-15)
    assert engine.run(time=0.38) == "time" and engine.wall_contacts == 0


def test_dropped_ball_bounces_to_the_exact_heights():
    """Dropped from rest at height h0 above contact onto a floor with restitution ξ_w: the k-th
    bounce leaves at v_k = ξ_w^k √(2 g h0), reaches h_k = ξ_w^(2k) h0, and lands at
    t_k = √(2h0/g) (1 + 2 Σ_{i=1}^{k-1} ξ_w^i) (Luding et al., Phys. Rev. E 50, 4113 (1994))."""
    radius, h0, xi = 0.05, 0.5, 0.8
    # one ball: no disk contact for ξ; t_c far below the shortest flight here (1e-3), so every
    # bounce dissipates (the settling bed's compiled variant)
    engine = Engine([[0.5, radius + h0]], [[0.0, 0.0]], radius, wall_restitution=xi,
                    gravity=[0.0, -G], restitution=xi, tc=1e-6)
    fall = math.sqrt(2.0 * h0 / G)
    landing = fall
    for k in range(1, 31):
        engine.run(contacts=k)
        v_k = xi**k * math.sqrt(2.0 * G * h0)
        assert engine.time == pytest.approx(landing, rel=1e-12)
        assert engine.velocities()[0, 1] == pytest.approx(v_k, rel=1e-12)
        apex = engine.positions(engine.time + v_k / G)[0, 1] - radius
        assert apex == pytest.approx(xi ** (2 * k) * h0, rel=1e-11)
        landing += 2.0 * v_k / G
    assert engine.dissipated_energy == pytest.approx(G * h0 * (1.0 - xi**60), rel=1e-12)


@pytest.mark.slow  # needs restitution without the TC model under gravity: no quick variant
def test_bouncing_ball_without_tc_is_reported_as_collapse():
    """The bounces of an inelastic ball accumulate at t∞ = √(2h0/g)(1 + ξ)/(1 − ξ): without the
    TC model the run ends there with an error that names the disk."""
    engine = Engine([[0.5, 0.3]], [[0.0, 0.0]], 0.05, wall_restitution=0.8,
                    gravity=[0.0, -G])
    with pytest.raises(InelasticCollapseError, match="TC model") as error:
        engine.run(time=10.0)
    assert error.value.disks == [0]
    t_infinity = math.sqrt(2.0 * 0.25 / G) * 1.8 / 0.2
    assert error.value.time == pytest.approx(t_infinity, rel=1e-3)


def test_bouncing_ball_with_tc_keeps_bouncing_without_collapse():
    """With the TC model, bounces closer than t_c after the previous one are elastic: the last
    dissipative bounce shortens the interval from at least t_c to at least ξ_w t_c, and the
    ball bounces at that interval for as long as asked."""
    tc = 1e-4
    # one ball: no disk contact for ξ (the settling bed's compiled variant)
    engine = Engine([[0.5, 0.3]], [[0.0, 0.0]], 0.05, wall_restitution=0.8,
                    gravity=[0.0, -G], tc=tc, restitution=0.8)
    engine.run(time=5.0)
    assert engine.time > 4.99
    interval = 2.0 * engine.velocities()[0, 1] / G
    assert 0.8 * tc * (1 - 1e-9) <= interval < tc
    assert engine.positions()[0, 1] >= 0.05


@pytest.mark.slow  # elastic disks under gravity: no quick variant
@pytest.mark.parametrize("periodic_x", [False, True])
def test_elastic_gas_under_gravity_conserves_mechanical_energy(periodic_x):
    n = 1000
    radius = radius_for_packing(n, 0.2)
    position = random_sequential(np.full(n, radius), periodic=(periodic_x, False), seed=3)
    velocity = np.random.default_rng(4).normal(size=(n, 2))
    engine = Engine(position, velocity, radius, gravity=[0.0, -2.0],
                    boundary=Boundary(periodic=(periodic_x, False)))
    energy = engine.kinetic_energy() + engine.potential_energy()
    for _ in range(4):
        engine.run(collisions=engine.collisions + 50_000)
        assert_no_overlap(engine)
        drift = engine.kinetic_energy() + engine.potential_energy() - energy
        assert abs(drift) <= 1e-12 * engine.kinetic_energy()


def test_tilted_gravity_keeps_disks_in_the_box():
    """Gravity along a diagonal presses a dense gas into a corner."""
    n = 500
    radius = radius_for_packing(n, 0.4)
    position = random_sequential(np.full(n, radius), seed=8)
    engine = Engine(position, np.zeros((n, 2)), radius, gravity=[-3.0, -4.0],
                    restitution=0.9, wall_restitution=0.9, tc=1e-3)
    for _ in range(5):
        engine.run(time=engine.time + 0.4)
        assert_no_overlap(engine)
    assert np.mean(engine.positions()[:, 0]) < 0.45


def test_gravity_along_a_periodic_axis_is_refused():
    with pytest.raises(ValueError, match="periodic axis"):
        Engine([[0.5, 0.5]], [[0.0, 0.0]], 0.01, gravity=[0.0, -1.0],
               boundary=Boundary(periodic=(True, True)))


def bed_at_rest_on_the_floor():
    """200 disks on a lattice whose bottom row touches the floor, at rest."""
    n, radius = 200, 0.01
    position = hexagonal_lattice(n, radius, region=((0.0, 1.0), (0.0, 0.2)), seed=1)
    assert np.isclose(position[:, 1].min(), radius, rtol=0, atol=1e-15)
    return position, radius


def test_disks_placed_at_rest_on_the_floor_leave_it_under_the_tc_model():
    """Under the TC model the disks of the bottom row leave with the bounce that lasts t_c and
    the bed runs, energy booked as the floor's work."""
    position, radius = bed_at_rest_on_the_floor()
    engine = Engine(position, np.zeros_like(position), radius, gravity=[0.0, -1.0],
                    restitution=0.8, wall_restitution=0.8, tc=1e-3)
    energy = engine.potential_energy()
    engine.run(time=1.0)
    assert_no_overlap(engine)
    balance = (engine.kinetic_energy() + engine.potential_energy() + engine.dissipated_energy
               - engine.wall_work - energy)
    assert abs(balance) <= 1e-12 * engine.dissipated_energy


@pytest.mark.slow  # elastic disks under gravity: no quick variant
def test_disks_placed_at_rest_on_the_floor_without_the_tc_model_stop_the_run():
    """Without the TC model the floor would hold the bottom row through infinitely many
    contacts at one instant: the run stops with a clear error."""
    position, radius = bed_at_rest_on_the_floor()
    elastic = Engine(position, np.zeros_like(position), radius, gravity=[0.0, -1.0])
    with pytest.raises(StalledError, match="resting on a wall under gravity"):
        elastic.run(time=1.0)
