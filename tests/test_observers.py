"""Observers chosen by the scene (sim.observers), written into the run file and read back."""

import numpy as np
import pytest

from sim.analysis import open_run
from sim.figures.runs import compose_config
from sim.runner import run
from sim.validation import kolafa_rottner_z


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
    """The packing fractions of the cells average to the gas's φ exactly, and the cells' heat
    adds up to the kinetic energy less the cells' flow, about one disk's share per cell."""
    cfg = compose_config(["disks.packing_fraction=0.3", "observe.local_fields.cells=8",
                          "stop.collisions=20000", "output.every_collisions=10000",
                          "output.progress=false"])
    with open_run(run(cfg, tmp_path)) as ds:
        fields = ds["local_fields"]
        assert fields.dims == ("time", "field", "y", "x") and fields.sizes["x"] == 8
        n = ds.sizes["disk"]
        position = ds["position"].isel(time=-1).values
        energy = float(ds["kinetic_energy"].values[-1])
        packing, temperature = fields.isel(time=-1).values
    assert packing.mean() == pytest.approx(0.3, rel=1e-12)
    counts = np.histogram2d(position[:, 1], position[:, 0], bins=8, range=[[0, 1], [0, 1]])[0]
    heat = np.nansum(counts * temperature)
    assert energy * (1.0 - 2.0 * 64 / n) < heat < energy
