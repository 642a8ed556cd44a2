"""The crater scene as figures 8–10 run and measure it: the seed study's bed of 4000 disks
(R = 0.0045, φ ≈ 0.51 in the lower half) or, quick, 1000 disks of twice the radius (the same
packing fraction)."""

from dataclasses import dataclass

import numpy as np
import yaml

from sim.crater import calibrated_spacing, crater_area


def crater_overrides(quick):
    bed = ["bed.n=1000", "bed.radius=0.009", "output.every_collisions=5000"] if quick else []
    return ["scenario=crater", *bed]


def require_stop(sweep, swept, reason, remedy):
    """Raise when a run of ``sweep`` (over the dimension ``swept``) stopped otherwise than by
    ``reason``: its crater would be read at another stage than the others'."""
    values = sweep[swept].values
    unfinished = values[sweep["stop_reason"].values != reason]
    if unfinished.size:
        raise ValueError(f"runs at {swept} = {unfinished.tolist()} stopped otherwise than by "
                         f"{reason}: {remedy}")


@dataclass
class CraterGeometry:
    """What the crater measure needs from a run: the bed disks, the bed region and the grid
    spacing calibrated on the untouched bed (sim.crater.calibrated_spacing)."""

    bed: np.ndarray  # bool[n], True for bed disks
    radius: np.ndarray  # radii of the bed disks
    width: float
    height: float
    dx: float

    @classmethod
    def of_run(cls, ds):
        """From one run's Dataset: open_run's, or one run selected from open_sweep's."""
        bed = np.asarray(ds["species_id"].values == 0)
        radius = np.asarray(ds["radius"].values[bed])
        config = ds["config"].item() if "config" in ds else ds.attrs["config"]
        height = float(yaml.safe_load(config)["bed"]["height"])
        width = float(ds.attrs["box"][0])
        snapshot_dim = "snapshot" if "snapshot" in ds.dims else "time"
        first = np.asarray(ds["position"].isel({snapshot_dim: 0}).values)[bed]
        return cls(bed, radius, width, height, calibrated_spacing(first, radius, width, height))

    def area(self, position, dx=None):
        """Crater area (box units²) of one snapshot's positions float64[n, 2]."""
        return crater_area(position[self.bed], self.radius, dx or self.dx, self.width,
                           self.height)[0]
