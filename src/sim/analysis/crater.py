"""Crater measure of the seed study: a grid of square cells of side Δx over the bed; a cell is
occupied when any bed disk overlaps it; the crater area is the number of empty cells inside
the bed times Δx².

The disk–square test (the study's Figure 1): a disk of centre c and radius R overlaps the
square [x₀, x₀ + Δx] × [y₀, y₀ + Δx] exactly when c lies in the square grown by R with
rounded corners, i.e. when the distance from c to the nearest point of the square,
|c − clamp(c, square)|, is below R. Touching (distance = R) does not occupy.

Positions, radii and Δx in box units; the grid starts at the box origin, so a bed height
that is a multiple of Δx is a grid line.

From a run in one call: ``sim.analysis.crater.area("run.h5")`` (the area at the last snapshot, Δx
calibrated on the untouched bed); :class:`CraterGeometry` for more snapshots or spacings.
The crater runs of the figures and the experiments: :func:`crater_overrides`.
"""

from dataclasses import dataclass

import numpy as np
import yaml


def occupied_cells(position, radius, dx, extent):
    """Which cells of a grid of side ``dx`` over [0, extent[0]] × [0, extent[1]] any disk
    overlaps. ``position`` float64[n, 2], ``radius`` float64[n] or scalar.

    Returns bool[nx, ny], cell (a, b) being [a Δx, (a + 1) Δx] × [b Δx, (b + 1) Δx]; the last
    row and column may reach past ``extent``.
    """
    position = np.asarray(position, dtype=np.float64)
    radius = np.broadcast_to(np.asarray(radius, dtype=np.float64), (position.shape[0],))
    nx, ny = (int(np.ceil(extent[a] / dx - 1e-9)) for a in (0, 1))
    occupied = np.zeros((nx, ny), dtype=bool)
    reach = int(np.ceil(radius.max() / dx)) if radius.size else 0
    first = np.floor(position / dx).astype(np.int64)  # cell holding each centre
    for ox in range(-reach, reach + 1):
        for oy in range(-reach, reach + 1):
            a = first[:, 0] + ox
            b = first[:, 1] + oy
            inside = (a >= 0) & (a < nx) & (b >= 0) & (b < ny)
            nearest_x = np.clip(position[:, 0], a * dx, (a + 1) * dx)
            nearest_y = np.clip(position[:, 1], b * dx, (b + 1) * dx)
            d2 = (position[:, 0] - nearest_x) ** 2 + (position[:, 1] - nearest_y) ** 2
            hit = inside & (d2 < radius**2)
            occupied[a[hit], b[hit]] = True
    return occupied


def crater_area(position, radius, dx, width, bed_height):
    """Empty-cell area Δx² · #(empty cells) of the grid over the bed [0, width] × [0,
    bed_height], cells reaching past ``width`` or above ``bed_height`` left out. Returns
    (area, occupied grid bool[nx, ny])."""
    nx, ny = (int(np.floor(length / dx + 1e-9)) for length in (width, bed_height))
    occupied = occupied_cells(position, radius, dx, (nx * dx, ny * dx))
    return float(np.count_nonzero(~occupied)) * dx * dx, occupied


def calibrated_spacing(position, radius, width, bed_height):
    """The finest spacing Δx = bed_height / k (k = 1, 2, …; Δx ≥ the largest disk diameter)
    such that the untouched bed — its disks' ``position`` before the impact — has no empty
    cell at Δx nor at any coarser spacing of the ladder: the study's rule that the gaps between
    resting disks must not count as crater."""
    radius = np.broadcast_to(np.asarray(radius, dtype=np.float64), (len(position),))
    finest = max(int(bed_height / (2.0 * radius.max())), 1)
    k = 1
    while k < finest and crater_area(position, radius, bed_height / (k + 1), width,
                                     bed_height)[0] == 0:
        k += 1
    return bed_height / k


@dataclass
class CraterGeometry:
    """What the crater measure needs from a run: the bed disks, the bed region and the grid
    spacing calibrated on the untouched bed (:func:`calibrated_spacing`)."""

    bed: np.ndarray  # bool[n], True for bed disks (species 0)
    radius: np.ndarray  # radii of the bed disks
    width: float
    height: float
    dx: float

    @classmethod
    def of_run(cls, ds):
        """From one run's Dataset: :func:`sim.analysis.datasets.open_run`'s, or one run selected
        from
        :func:`sim.analysis.datasets.open_sweep`'s."""
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


def area(run, snapshot=-1, dx=None):
    """Crater area (box units²) of a crater run at ``snapshot`` (default the last): ``run`` a
    run-file path, an :func:`sim.analysis.datasets.open_run` Dataset or one run selected from
    :func:`sim.analysis.datasets.open_sweep`'s (whose shorter runs end in NaN: give their last
    snapshot); Δx calibrated on the run's untouched bed unless given."""
    from sim.analysis.datasets import open_run  # the measure itself needs no run file

    if not hasattr(run, "attrs"):
        with open_run(run) as ds:
            return area(ds, snapshot, dx)
    geometry = CraterGeometry.of_run(run)
    snapshot_dim = "snapshot" if "snapshot" in run.dims else "time"
    return geometry.area(np.asarray(run["position"].isel({snapshot_dim: snapshot}).values), dx)


def crater_overrides(quick):
    """The Hydra overrides of the crater scene as figures 8–10 and the accuracy study run it:
    the seed study's bed of 4000 disks (R = 0.0045, φ ≈ 0.51 in the lower half) or, quick,
    1000 disks of twice the radius (the same packing fraction)."""
    bed = ["bed.n=1000", "bed.radius=0.009", "output.every_collisions=5000"] if quick else []
    return ["scenario=crater", *bed]


def require_stop(sweep, swept, reason, remedy):
    """Raise when a run of ``sweep`` (over the dimension ``swept``) stopped otherwise than by
    ``reason``: its crater would be read at another stage than the others' (over the other
    swept dimensions, such as seeds, any run)."""
    stopped = sweep["stop_reason"] != reason
    unfinished = sweep[swept].values[stopped.any([d for d in stopped.dims if d != swept]).values]
    if unfinished.size:
        raise ValueError(f"runs at {swept} = {unfinished.tolist()} stopped otherwise than by "
                         f"{reason}: {remedy}")


def preparation_of(ds):
    """How the runs of ``ds`` (open_run's or open_sweep's) made their initial state, in words:
    one text for all, or each distinct one."""
    if "preparation" in ds:
        texts = dict.fromkeys(str(t) for t in np.ravel(ds["preparation"].values))
    else:
        texts = [ds.attrs.get("preparation", "")]
    return "; ".join(t for t in texts if t) or "preparation not recorded (an older run file)"
