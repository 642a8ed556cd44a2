"""The crater measure: the exact disk–square test against the seed study's own construction
(its Figure 1), empty and full beds, the calibrated grid spacing; and the scale invariance
that figure 10 rests on."""

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.analysis.crater import (
    CraterGeometry,
    area,
    calibrated_spacing,
    crater_area,
    occupied_cells,
    require_stop,
)
from sim.analysis.datasets import open_run
from sim.engine import Engine
from sim.pipeline.initial import hexagonal_lattice
from sim.pipeline.run_cache import compose_config
from sim.pipeline.runner import run


def overlaps_by_figure_1(cx, cy, radius, x0, y0, x1, y1):
    """The study's Figure 1: the centre lies in the square [x0, x1] × [y0, y1] grown by R on
    each side, but not in its corners — unless within R of a corner of the square."""
    in_cross = ((x0 - radius < cx < x1 + radius and y0 <= cy <= y1)
                or (x0 <= cx <= x1 and y0 - radius < cy < y1 + radius))
    corners = ((x0, y0), (x1, y0), (x0, y1), (x1, y1))
    near_corner = any((cx - a) ** 2 + (cy - b) ** 2 < radius**2 for a, b in corners)
    return in_cross or near_corner


@settings(max_examples=200, deadline=None)
@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(0.001, 0.2),
       st.sampled_from([0.05, 0.1, 0.125, 0.2]))
def test_disk_square_test_matches_the_study_construction(cx, cy, radius, dx):
    occupied = occupied_cells(np.array([[cx, cy]]), radius, dx, (1.0, 1.0))
    for a in range(occupied.shape[0]):
        for b in range(occupied.shape[1]):
            gap = np.hypot(cx - np.clip(cx, a * dx, (a + 1) * dx),
                           cy - np.clip(cy, b * dx, (b + 1) * dx))
            if abs(gap - radius) < 1e-12:
                continue  # tangent to the cell to round-off: either answer is right
            assert occupied[a, b] == overlaps_by_figure_1(cx, cy, radius, a * dx, b * dx,
                                                          (a + 1) * dx, (b + 1) * dx)


def test_a_disk_touching_a_corner_occupies_only_when_it_overlaps():
    dx, radius = 0.1, 0.03
    corner = np.array([0.3, 0.3])
    direction = np.array([1.0, 1.0]) / np.sqrt(2.0)
    outside = occupied_cells([corner + (radius + 1e-12) * direction], radius, dx, (1, 1))
    inside = occupied_cells([corner + (radius - 1e-12) * direction], radius, dx, (1, 1))
    assert not outside[2, 2] and inside[2, 2]
    # plus the cell holding the centre and the two sharing its sides with the corner cell
    assert outside.sum() == 3 and inside.sum() == 4


def test_empty_and_full_beds():
    area, _ = crater_area(np.empty((0, 2)), np.empty(0), 0.1, 1.0, 0.5)
    assert area == pytest.approx(0.5, rel=1e-12)  # every cell of the bed empty
    lattice = hexagonal_lattice(800, 0.01, box=(1.0, 0.5), seed=1)
    dx = calibrated_spacing(lattice, 0.01, 1.0, 0.5)
    assert 0.02 <= dx < 0.05
    assert crater_area(lattice, 0.01, dx, 1.0, 0.5)[0] == 0.0
    # removing the disks of a disk-shaped hole of radius 0.1 leaves about its area empty
    kept = np.hypot(lattice[:, 0] - 0.5, lattice[:, 1] - 0.25) > 0.1
    area, _ = crater_area(lattice[kept], 0.01, dx, 1.0, 0.5)
    hole = np.pi * (0.1 - 0.01) ** 2  # the disks at the rim reach 0.01 into the hole
    assert 0.5 * hole < area < 1.2 * hole


def test_a_crater_at_twice_the_speed_is_the_same_crater_in_half_the_time():
    """Hard disks have no energy scale (figure 10): doubling every velocity and halving t_c
    gives the same collisions at half the times — to the bit, as ×2 is exact in float64. The
    crater scene's effects: ξ, ξ_w, t_c; bed and projectile of their own species."""
    bed = hexagonal_lattice(300, 0.012, region=((0, 1), (0, 0.5)), seed=3)
    n = len(bed)
    position = np.vstack([bed, [[0.5, 0.75]]])
    radius = np.append(np.full(n, 0.012), 0.05)
    mass = np.append(np.ones(n), (0.05 / 0.012) ** 2)
    species = np.append(np.zeros(n, dtype=int), 1)
    runs = []
    for speed in (5.0, 10.0):
        velocity = np.zeros((n + 1, 2))
        velocity[-1] = [0.0, -speed]
        engine = Engine(position, velocity, radius, mass, species, restitution=0.5,
                        wall_restitution=0.5, tc=5e-8 / speed)
        engine.run(collisions=20_000)
        runs.append(engine)
    slow, fast = runs
    assert slow.time == 2.0 * fast.time
    np.testing.assert_array_equal(slow.positions(), fast.positions())
    np.testing.assert_array_equal(2.0 * slow.velocities(), fast.velocities())
    assert fast.dissipated_energy == 4.0 * slow.dissipated_energy


def test_the_area_of_a_run_in_one_call(tmp_path):
    """sim.analysis.crater.area(path) is the area of the last snapshot on the grid calibrated on the
    first, and the same from an open Dataset; the first snapshot's bed has no crater."""
    cfg = compose_config(["scenario=crater", "bed.n=300", "bed.radius=0.016",
                          "stop.collisions=3000", "output.every_collisions=1000",
                          "output.progress=false"])
    path = run(cfg, tmp_path)
    with open_run(path) as ds:
        geometry = CraterGeometry.of_run(ds)
        last = ds["position"].isel(time=-1).values
        assert area(ds) == geometry.area(last) > 0.0
        assert area(ds, snapshot=0) == 0.0
        assert "melted" in ds.attrs["preparation"]
    assert area(path) == geometry.area(last)
    assert area(path, dx=geometry.dx / 2) == geometry.area(last, geometry.dx / 2)


@pytest.mark.parametrize("order", [("projectile_speed", "seed"), ("seed", "projectile_speed")])
def test_a_run_stopped_otherwise_names_its_swept_value_over_every_seed(order):
    reasons = np.array([["at_rest", "at_rest"], ["at_rest", "time"], ["at_rest", "at_rest"]])
    sweep = xr.Dataset({"stop_reason": (("projectile_speed", "seed"), reasons)},
                       coords={"projectile_speed": [1.0, 2.0, 4.0], "seed": [0, 1]})
    sweep = sweep.transpose(*order)
    with pytest.raises(ValueError, match=r"projectile_speed = \[2\.0\] stopped otherwise"):
        require_stop(sweep, "projectile_speed", "at_rest", "raise stop.time")
    require_stop(sweep.sel(projectile_speed=[1.0, 4.0]), "projectile_speed", "at_rest", "")
