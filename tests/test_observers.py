"""Observers chosen by the scene (sim.analysis.observers), written into the run file and read
back."""

import numpy as np
import pytest

from sim.analysis.datasets import contacts, granular_temperatures, open_run, pressure_tensor
from sim.analysis.theory import kolafa_rottner_z
from sim.pipeline.run_cache import compose_config
from sim.pipeline.runner import run
from variants import RECORDER_KEYWORDS, RECORDERS


def test_radial_distribution_of_a_dense_gas(tmp_path):
    """g(r) at φ = 0.5 in a periodic box: its value at contact, extrapolated from the first
    bins above it, is the contact value (Z − 1)/(2φ) of the equation of state, and g → 1 far
    from a disk."""
    phi = 0.5
    cfg = compose_config(["box.boundary=periodic", f"disks.packing_fraction={phi}",
                          "observe.radial_distribution.bins=400",
                          "observe.radial_distribution.r_max=10", "stop.collisions=400000",
                          "output.every_collisions=10000", "output.progress=false"])
    with open_run(run(cfg, tmp_path)) as ds:
        assert ds["radial_distribution"].dims == ("time", "r")
        g = ds["radial_distribution"].isel(time=slice(10, None)).mean("time")
    above = g.sel(r=slice(1.0, 1.2))  # bin centres above contact, the first one fully
    slope, contact = np.polyfit(above.r.values[:4] - 1.0, above.values[:4], 1)
    assert contact == pytest.approx((kolafa_rottner_z(phi) - 1.0) / (2.0 * phi), rel=0.05)
    assert slope < 0.0
    assert g.sel(r=slice(0.0, 0.98)).max() == 0.0  # no pair closer than contact
    assert g.sel(r=slice(8.0, 10.0)).mean() == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize(("overrides", "largest"), [
    (["disks.packing_fraction=0.8"], (0.99, 1.0)),  # a solid: one cluster of every disk
    (["disks.packing_fraction=0.05"], (0.0, 0.05)),  # a dilute gas: pairs and loners
])
def test_clusters_of_a_solid_and_of_a_dilute_gas(overrides, largest, tmp_path):
    cfg = compose_config([*overrides, "observe.clusters.gap=0.1", "stop.collisions=20000",
                          "output.every_collisions=10000", "output.progress=false"])
    with open_run(run(cfg, tmp_path)) as ds:
        labels = ds["clusters"].values
        assert ds["clusters"].dims == ("time", "disk")
    sizes = [np.bincount(frame) for frame in labels]
    for size in sizes:
        assert np.all(np.diff(size) <= 0)  # numbered by decreasing size
        assert largest[0] <= size[0] / labels.shape[1] <= largest[1]


def test_local_fields_add_up_to_the_whole_gas(tmp_path):
    """The packing fractions of the cells average to the gas's φ exactly; the temperature of
    a cell (row = y cell, column = x cell) is Σ m |v − u|² / (2 (N_c − 1)) of its disks, and
    the cells' heat adds up to the kinetic energy less the cells' flow, about one disk's share
    per cell; pooled over the cells it is the temperature of granular_temperatures."""
    cfg = compose_config(["disks.packing_fraction=0.3", "observe.local_fields.cells=8",
                          "stop.collisions=20000", "output.every_collisions=10000",
                          "output.progress=false"])
    with open_run(run(cfg, tmp_path)) as ds:
        fields = ds["local_fields"]
        assert fields.dims == ("time", "field", "y", "x") and fields.sizes["x"] == 8
        assert fields["field"].values.tolist() == ["packing_fraction", "temperature"]
        n = ds.sizes["disk"]
        position = ds["position"].isel(time=-1).values
        velocity = ds["velocity"].isel(time=-1).values
        mass = ds["mass"].values
        energy = float(ds["kinetic_energy"].values[-1])
        packing, temperature = fields.isel(time=-1).values
    assert packing.mean() == pytest.approx(0.3, rel=1e-12)
    counts = np.histogram2d(position[:, 1], position[:, 0], bins=8, range=[[0, 1], [0, 1]])[0]
    iy, ix = np.unravel_index(np.argmax(counts), counts.shape)
    inside = (np.floor(position[:, 1] * 8) == iy) & (np.floor(position[:, 0] * 8) == ix)
    m, v = mass[inside], velocity[inside]
    u = m @ v / m.sum()
    assert temperature[iy, ix] == pytest.approx(
        np.sum(m * np.sum((v - u) ** 2, axis=1)) / (2.0 * (inside.sum() - 1)), rel=1e-12)
    heat = np.nansum((counts - 1.0) * temperature)
    assert energy * (1.0 - 2.0 * 64 / n) < heat < energy
    pooled = granular_temperatures(position[None], velocity[None], mass, np.zeros(n, int),
                                   (1.0, 1.0))[0, 0]
    assert pooled == pytest.approx(heat / np.sum(counts[counts > 1] - 1.0), rel=1e-12)


def periodic_gas(tmp_path, *overrides):
    """A periodic gas at φ = 0.3, T = 1, with every recorder on."""
    cfg = compose_config(["box.boundary=periodic", "disks.packing_fraction=0.3",
                          "disks.temperature=1.0", "disks.speed=null", *RECORDERS, *overrides,
                          "output.progress=false"])
    return open_run(run(cfg, tmp_path))


def test_unwrapped_positions_agree_with_unwrapping_frequent_snapshots():
    """The windings the loop counts agree with unwrapping snapshots so close in time that no
    disk moves half a box between them; a lone disk is ballistic across many box lengths."""
    from sim.engine import Boundary, Engine
    from sim.pipeline.initial import radius_for_packing, random_sequential

    n = 200
    radius = radius_for_packing(n, 0.2)
    position = random_sequential(np.full(n, radius), periodic=(True, True), seed=4)
    velocity = np.random.default_rng(5).normal(size=(n, 2)) * 10.0
    # every recorder on: the unwrapped positions are the test's, the others share the loop
    engine = Engine(position, velocity, radius, boundary=Boundary(periodic=(True, True)),
                    **RECORDER_KEYWORDS)
    unwrapped = engine.positions(0.0)
    previous = unwrapped.copy()
    for t in np.arange(1, 400) * 2e-3:  # at most 0.02 × 10 × a few σ < L/2 per step
        engine.run(time=t)
        now = engine.positions(t)
        unwrapped += (now - previous + 0.5) % 1.0 - 0.5
        previous = now
    np.testing.assert_allclose(engine.unwrapped_positions(t), unwrapped, rtol=0, atol=1e-9)
    assert np.abs(unwrapped - position).max() > 2.0  # disks crossed the box several times

    lone = Engine([[0.5, 0.5]], [[3.0, -4.0]], 0.01, boundary=Boundary(periodic=(True, True)),
                  **RECORDER_KEYWORDS)
    lone.run(time=10.0)
    np.testing.assert_allclose(lone.unwrapped_positions(10.0), [[30.5, -39.5]], rtol=1e-14)


def test_mean_squared_displacement_and_velocity_autocorrelation(tmp_path):
    """Equilibrium gas at T = 1, φ = 0.3: the displacement is ballistic, ⟨v²⟩ t², well within
    a mean free time and diffusive, 4 D t, after many; the velocity autocorrelation starts at
    ⟨v²⟩ = 2T/m and has decayed to a few per cent after 10 mean free times; and its time
    integral up to there (Green–Kubo, 2D: D = ½ ∫ ⟨v(t)·v(0)⟩ dt) gives D within 10 % of the
    MSD slope. (Single time origin: the late values scatter by about ⟨v²⟩/√N.)"""
    with periodic_gas(tmp_path, "observe.mean_squared_displacement=true",
                      "observe.velocity_autocorrelation=true", "stop.collisions=null",
                      "stop.time=0.4", "output.every_collisions=null",
                      "output.every_time=0.0005") as ds:
        msd = ds["mean_squared_displacement"].sel(species=0).values
        vacf = ds["velocity_autocorrelation"].sel(species=0).values
        time = ds["time"].values
        v = ds["velocity"].values
        v0_squared = float(np.mean(np.sum(v[0] ** 2, axis=1)))
        # a mean of terms of either sign: round-off is relative to the terms, ⟨v²⟩
        np.testing.assert_allclose(vacf, np.mean(np.sum(v * v[0], axis=2), axis=1),
                                   rtol=0, atol=1e-12 * v0_squared)
        collisions = ds["collisions"].values
    mean_free_time = 2000 * time[-1] / (2 * collisions[-1])
    assert time[1] < 0.1 * mean_free_time
    assert msd[1] / (v0_squared * time[1] ** 2) == pytest.approx(1.0, rel=0.03)
    assert vacf[0] == pytest.approx(2.0, rel=0.05)
    late = time > 10 * mean_free_time
    assert abs(vacf[late].mean()) < 0.02 * vacf[0]
    slope = np.polyfit(time[late], msd[late], 1)[0]
    green_kubo = 0.5 * np.trapezoid(vacf[~late], time[~late])
    assert slope / 4.0 == pytest.approx(green_kubo, rel=0.1)


def test_pressure_tensor_is_isotropic_and_its_trace_is_the_pressure(tmp_path):
    """In an equilibrium gas P_xx = P_yy, P_xy = 0, and ½ (P_xx + P_yy) A/(N T) is Z from the
    scalar collision virial (the trace of Σ r_a Δp_b is Σ r·Δp, to round-off)."""
    with periodic_gas(tmp_path, "observe.pressure_tensor=true", "stop.collisions=400000",
                      "output.every_collisions=20000") as ds:
        tensor = ds["collision_virial_tensor"].values
        assert ds["collision_virial_tensor"]["a"].values.tolist() == ["x", "y"]
        np.testing.assert_allclose(tensor[:, 0, 0] + tensor[:, 1, 1], ds["collision_virial"],
                                   rtol=1e-12)
        pressure = pressure_tensor(ds).isel(time=slice(2, None)).mean("time").values
        temperature = float(ds["kinetic_energy"].mean()) / ds.sizes["disk"]
        virial = ds["collision_virial"].values
        elapsed = ds["time"].values[-1] - ds["time"].values[2]
        z_scalar = 1.0 + (virial[-1] - virial[2]) / (2.0 * ds.sizes["disk"] * temperature
                                                     * elapsed)
    z_tensor = 0.5 * (pressure[0, 0] + pressure[1, 1]) / (ds.sizes["disk"] * temperature)
    assert z_tensor == pytest.approx(z_scalar, rel=0.01)
    assert pressure[0, 0] == pytest.approx(pressure[1, 1], rel=0.03)
    assert abs(pressure[0, 1]) < 0.03 * pressure[0, 0]


@pytest.mark.parametrize("effects", [
    # every recorder on (the quick suite's compiled loop): nothing is dissipated
    pytest.param(RECORDERS, id="elastic"),
    # inelastic disks and walls with the log alone: a loop of its own
    pytest.param(("restitution.disk=0.8", "restitution.wall=0.9", "tc.time=1e-7",
                  "observe.event_log=true"), id="inelastic", marks=pytest.mark.slow),
])
def test_event_log_holds_every_contact(effects, tmp_path):
    """The log has one row per contact, in order; its dissipated energies add up to the
    run's, and for equal disks Σ |Δp| σ over disk contacts is the collision virial."""
    cfg = compose_config(["disks.n=500", *effects, "stop.collisions=100000",
                          "output.every_collisions=10000", "output.progress=false"])
    path = run(cfg, tmp_path)
    log = contacts(path)
    with open_run(path) as ds:
        events = int(ds["collisions"][-1] + ds["wall_contacts"][-1])
        dissipated = float(ds["dissipated_energy"][-1])
        virial = float(ds["collision_virial"][-1])
        sigma = 2.0 * float(ds["radius"][0])
    assert log.sizes["contact"] == events
    np.testing.assert_array_equal(log["contact"], np.arange(1, events + 1))
    assert np.all(np.diff(log["time"]) >= 0.0)
    assert float(log["dissipated"].sum()) == pytest.approx(dissipated, rel=1e-12)
    disk_contacts = log["partner"] >= 0
    assert float((log["impulse"] * sigma).where(disk_contacts).sum()) == pytest.approx(
        virial, rel=1e-9)
    assert set(np.unique(log["partner"].where(~disk_contacts, drop=True))) <= {-1, -2, -3, -4}
    assert int(log["disk"].max()) < 500


def test_event_log_streams_to_the_file_between_snapshots(tmp_path):
    """A run that logs much between snapshots does not hold the log in memory: each full
    buffer of the loop goes to the writer, which writes it once it holds buffer_bytes."""
    from sim.engine import Engine
    from sim.pipeline.initial import fixed_speed, radius_for_packing, random_sequential
    from sim.storage.h5md import RunWriter

    n = 300
    radius = radius_for_packing(n, 0.2)
    # with the other recorders on: the compiled loop of the quick tests of any of them
    engine = Engine(random_sequential(np.full(n, radius), seed=1), fixed_speed(n, 1.0, seed=2),
                    radius, **RECORDER_KEYWORDS)
    writer = RunWriter(tmp_path / "run.h5", engine, {"config": "scene: gas\n", "seed": 0},
                       buffer_bytes=48 * 2000)
    writer.snapshot(engine, 0.0)
    engine.run(collisions=10_000)
    written = writer.file["events/contacts"].shape[0]
    assert 8_000 <= written <= engine.contacts
    writer.snapshot(engine)
    writer.flush()
    assert writer.file["events/contacts"].shape[0] == engine.contacts
    writer.close()
