"""Rough disks in the engine (sim.effects.rotation): energy and momentum bookkeeping over many
contacts, smooth disks unchanged, spins renumbered with the disks and restored from a
checkpoint to the same bits, and the run file's spins (the config's one-line refusals are
test_hostile.py's)."""

import h5py
import numpy as np
import pytest

from conftest import assert_no_overlap, gas
from sim.analysis.datasets import open_run
from sim.effects import loop_values
from sim.pipeline import runner
from sim.pipeline.config import register
from sim.pipeline.overrides import compose_overrides
from sim.storage.inspect import summary

register()


def total_energy(engine):
    return engine.kinetic_energy() + engine.rotational_energy()


@pytest.mark.slow  # rough disks with elastic normal contacts: no quick variant
@pytest.mark.parametrize("beta, wall_beta", [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0)])
def test_elastic_rough_contacts_keep_the_energy(beta, wall_beta):
    engine = gas(300, 0.3, seed=1, tangential_restitution=beta,
                 wall_tangential_restitution=wall_beta, rotational_temperature=0.5)
    e0 = engine.initial_energy
    assert e0 == pytest.approx(total_energy(engine), rel=1e-15)
    engine.run(contacts=30_000)
    assert engine.wall_contacts > 0 and engine.rotational_energy() > 0.0
    assert total_energy(engine) == pytest.approx(e0, rel=1e-12)
    assert abs(engine.dissipated_energy) < 1e-12 * e0  # (1 − β²) m_t g_t²/2 to round-off
    assert_no_overlap(engine)


@pytest.mark.parametrize("options", [
    {},  # the rough cooling scene's compiled variant
    pytest.param({"wall_restitution": 0.8, "friction": 0.2, "wall_friction": 0.5},
                 marks=pytest.mark.slow),  # Coulomb friction: no quick variant
])
def test_inelastic_rough_disks_book_every_loss(options):
    """E_tr + E_rot + dissipated stays E₀ with normal and tangential losses (and Coulomb's,
    with friction), at disks and walls, and the TC model."""
    engine = gas(300, 0.3, periodic=(False, False), seed=2, restitution=0.9, tc=1e-5,
                 tangential_restitution=0.4, wall_tangential_restitution=0.2, **options)
    assert (engine.friction is not None) == ("friction" in options)
    engine.run(contacts=30_000)
    lost = engine.dissipated_energy
    assert lost > 0.1 * engine.initial_energy
    assert total_energy(engine) + lost == pytest.approx(engine.initial_energy, rel=1e-12)
    assert_no_overlap(engine)


@pytest.mark.slow  # species, friction, gravity and a vibrating floor: no quick variant
def test_rough_disks_under_gravity_on_a_vibrating_floor_book_every_energy():
    """Two species with their own β and μ, rough walls, gravity, the TC model and a
    vibrating floor: E_tr + E_rot + U + dissipated − work of the floor stays E₀ + U₀."""
    from sim.engine import Engine

    placed = gas(300, 0.3, seed=7)
    species = np.arange(300) % 2
    engine = Engine(placed.positions(), placed.velocities(), placed.radius, species=species,
                    restitution=[[0.9, 0.8], [0.8, 0.7]], wall_restitution=0.9, tc=1e-4,
                    gravity=[0.0, -1.0], walls={"bottom": {"amplitude": 0.005,
                                                           "frequency": 40.0}},
                    tangential_restitution=[[0.5, 0.0], [0.0, -0.5]], friction=[[0.2, 0.4],
                                                                                [0.4, 0.6]],
                    wall_tangential_restitution=[0.3, 0.3, 0.6, -1.0], wall_friction=0.5)
    u0 = engine.potential_energy()
    engine.run(contacts=30_000)
    assert engine.wall_work != 0.0 and engine.rotational_energy() > 0.0
    balance = (total_energy(engine) + engine.potential_energy() + engine.dissipated_energy
               - engine.wall_work)
    assert balance == pytest.approx(engine.initial_energy + u0, rel=1e-11)
    assert_no_overlap(engine)


def test_the_tc_model_holds_when_only_rough_contacts_dissipate():
    """Elastic normal contacts, β = 0: the effects the engine would take (decided before it
    compiles anything) have the collapse watch and t_c on."""
    n = 100
    scene = {"n": n, "n_species": 1, "box": np.ones(2), "periodic": np.zeros(2, dtype=bool),
             "radius": np.full(n, 0.01), "mass": np.ones(n), "initial_energy": 0.5 * n}
    values, _ = loop_values({"tangential_restitution": 0.0, "tc": 1e-4}, scene)
    assert values["restitution"] is None and values["roughness"] is not None
    assert values["tc"] == 1e-4 and values["collapse"] is not None


@pytest.mark.parametrize("options, match", [
    ({"friction": 0.3}, "sticking"),
    ({"tangential_restitution": 0.5, "wall_friction": 0.3, "periodic": (True, True)},
     "periodic box has no walls"),
    ({"tangential_restitution": 0.5, "pressure_tensor": True}, "pressure tensor"),
    ({"spin": [1.0, 2.0]}, "spin must be"),
])
def test_the_engine_refuses_what_it_would_ignore(options, match):
    with pytest.raises(ValueError, match=match):
        gas(50, 0.2, seed=9, **options)


@pytest.mark.parametrize("options", [
    {"tc": 1e-5},  # the rough cooling scene's compiled variant
    pytest.param({"friction": 0.1}, marks=pytest.mark.slow),  # friction: no quick variant
])
def test_periodic_rough_gas_keeps_its_momentum(options):
    engine = gas(300, 0.3, periodic=(True, True), seed=3, restitution=0.8,
                 tangential_restitution=0.0, **options)
    p0 = engine.momentum()
    engine.run(contacts=20_000)
    np.testing.assert_allclose(engine.momentum(), p0, atol=1e-12 * engine.n)


def test_smooth_disks_are_the_smooth_engine_to_the_bit():
    plain = gas(300, 0.3, seed=4, restitution=0.9, tc=1e-5)
    smooth = gas(300, 0.3, seed=4, restitution=0.9, tc=1e-5, tangential_restitution=-1.0,
                 wall_tangential_restitution=-1.0, inertia_factor=0.4)
    assert (smooth.roughness, smooth.friction, smooth.spinning) == (None, None, False)
    for engine in (plain, smooth):
        engine.run(contacts=10_000)
    np.testing.assert_array_equal(plain.positions(), smooth.positions())
    np.testing.assert_array_equal(plain.velocities(), smooth.velocities())


@pytest.mark.slow  # smooth spinning disks: no quick variant
def test_spins_of_smooth_disks_stay_and_follow_the_renumbering():
    """20 000 disks are renumbered by cell as they move; the spins go with them."""
    n = 20_000
    spin = np.linspace(-3.0, 3.0, n)
    engine = gas(n, 0.3, periodic=(True, True), seed=5, spin=spin)
    assert engine.spinning and engine.roughness is None
    engine.run(events=3 * engine.reorder_every)
    np.testing.assert_array_equal(engine.angular_velocities(), spin)


def test_spins_of_rough_disks_follow_the_renumbering_to_the_bit():
    """Renumbered by cell every 500 events (large gases only, by default), rough disks keep
    their spins: the run is the one without renumbering, to the bit."""
    def make():
        return gas(300, 0.3, periodic=(True, True), seed=5, restitution=0.9, tc=1e-5,
                   tangential_restitution=0.5, rotational_temperature=1.0)

    plain, renumbered = make(), make()
    renumbered.reorder_every = 500
    for engine in (plain, renumbered):
        engine.run(events=5_000)
    assert not np.array_equal(renumbered.disks.order, np.arange(renumbered.n))
    np.testing.assert_array_equal(renumbered.angular_velocities(), plain.angular_velocities())
    np.testing.assert_array_equal(renumbered.velocities(), plain.velocities())


def test_a_rough_run_restored_from_its_checkpoint_continues_to_the_same_bits():
    def make():
        return gas(300, 0.3, seed=6, restitution=0.9, tc=1e-5, tangential_restitution=0.5,
                   rotational_temperature=1.0)

    straight = make()
    straight.run(contacts=6_000)
    half = make()
    half.run(contacts=3_000)
    restored = make()
    restored.load_state_dict(half.state_dict())
    restored.run(contacts=6_000)
    np.testing.assert_array_equal(restored.angular_velocities(), straight.angular_velocities())
    np.testing.assert_array_equal(restored.velocities(), straight.velocities())


def test_the_run_file_holds_spins_and_their_energy(tmp_path):
    cfg = compose_overrides(["disks.n=300", "restitution.disk=0.9", "tc.time=1e-5",
                             "restitution.tangential=0.5", "disks.rotational_temperature=1",
                             "stop.collisions=3000", "output.progress=false"])
    path = runner.run(cfg, tmp_path)
    with h5py.File(path, "r") as f:
        assert f["particles/disks/angular_velocity/value"].shape[1:] == (300,)
    with open_run(path) as ds:
        assert ds["angular_velocity"].dims == ("time", "disk")
        assert float(ds["rotational_energy"][0]) > 0.0
    info = summary(path)
    assert info["energy_drift"] < 1e-12


def test_a_smooth_run_file_has_no_spins(tmp_path):
    cfg = compose_overrides(["disks.n=100", "stop.collisions=500", "output.progress=false"])
    with h5py.File(runner.run(cfg, tmp_path), "r") as f:
        assert "angular_velocity" not in f["particles/disks"]
        assert "rotational_energy" not in f["observables"]
