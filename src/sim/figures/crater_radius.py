"""Figure 9: crater area against projectile radius R (the seed study's Figure 11): radii from
0.01 to 0.10, mass ∝ R² (the bed's areal density), three beds per radius (each seed melts
its own bed), one Hydra multirun read with open_sweep. Each run stops at 10 % of its kinetic
energy, as in the study, and is measured on the grid of figure 8 (sim.analysis.crater), Δx
calibrated on its own untouched bed.

Floor-limited runs: a projectile whose lowest point comes within ``FLOOR_GAP`` bed-disk
diameters of the floor before the stop (seen at the snapshots, every 20 000 collisions, in
which it moves a small fraction of its radius) has dug through the bed; its crater is set
by the box, not by the impact. Those runs are drawn as open symbols and left out of the means (and
may stop by their collision budget instead, bouncing on the floor).

What the data show is not one power law, so none is fitted: the local exponent
d ln A / d ln R between neighbouring radii (right panel, over the beds not floor-limited) falls
as R grows, from above 2 for projectiles a few bed disks wide to near 1 for larger ones, before
any reaches the floor. A single exponent through these points would be an average over the
range, not a scaling law; geometric similarity (α = 2, area ∝ mass) would need grains much
smaller than the projectile and a bed much deeper than the crater. The beds of one seed are the
same at every radius, so neighbouring radii are not independent, and the errors of the local
exponent (the standard errors of the two means, added in quadrature) and the χ² of the best
single power law through the means (in the numbers file's header and the legend) are
estimates. The numbers file gives, per radius, the mean area over the beds not
floor-limited, its standard error, the number of floor-limited beds, and the local exponent
to the next radius.
"""

import numpy as np

from sim.analysis.crater import CraterGeometry, crater_overrides, preparation_of
from sim.analysis.datasets import at_last_snapshot, open_sweep
from sim.analysis.scaling import local_exponents, single_power_law
from sim.figures.style import figure, save

NAME = "fig09_crater_radius"
#: a projectile closer than this many bed-disk diameters to the floor has reached it
FLOOR_GAP = 2.0


def radii(quick):
    return (0.02, 0.04, 0.06, 0.08) if quick else tuple(round(0.01 * k, 2) for k in range(1, 11))


def seeds(quick):
    return 2 if quick else 3


def sweeps(quick):
    return {"radius": [*crater_overrides(quick),
                       "projectile.radius=" + ",".join(map(str, radii(quick))),
                       f"seed=range(0,{seeds(quick)})"]}


def floor_limited(run):
    """Whether the projectile (the last disk) of one run came within ``FLOOR_GAP`` bed-disk
    diameters of the floor at any snapshot."""
    y = run["position"].isel(disk=-1, axis=1).values
    radius = run["radius"].values
    lowest = np.nanmin(y) - radius[-1]
    return bool(lowest < FLOOR_GAP * 2.0 * radius[0])


def to_next(values, measured):
    """``values`` between neighbouring measured radii as a column over all radii: each at the
    first radius of its pair, NaN elsewhere."""
    column = np.full(measured.size, np.nan)
    column[np.flatnonzero(measured)[:-1]] = values
    return column


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["radius"])
    radius = ds["projectile_radius"].values
    seed = ds["seed"].values
    last = at_last_snapshot(ds, "position")
    area = np.empty((radius.size, seed.size))
    floor = np.empty_like(area, dtype=bool)
    for i in range(radius.size):
        for j in range(seed.size):
            one = ds.isel(projectile_radius=i, seed=j)
            floor[i, j] = floor_limited(one)
            stop = str(one["stop_reason"].item())
            if stop != "energy_fraction" and not floor[i, j]:
                raise ValueError(f"the run at R = {radius[i]}, seed {seed[j]} stopped by {stop} "
                                 f"before 10 % of its energy was left: raise stop.collisions")
            area[i, j] = CraterGeometry.of_run(one).area(
                last.isel(projectile_radius=i, seed=j).values)
    mass = ds["mass"].isel(disk=-1).values
    if mass.ndim > 1:
        mass = mass[:, 0]
    free = ~floor
    radius_of_run = np.broadcast_to(radius[:, None], area.shape)
    beds = free.sum(axis=1)  # beds not floor-limited, per radius
    mean = np.array([area[i, free[i]].mean() if beds[i] else np.nan for i in range(radius.size)])
    error = np.array([area[i, free[i]].std(ddof=1) / np.sqrt(beds[i]) if beds[i] > 1 else np.nan
                      for i in range(radius.size)])
    measured = beds > 1  # radii with a mean and its error
    middle, local, local_error = local_exponents(radius[measured], mean[measured],
                                                 error[measured])
    slope, slope_error, chi_square, freedom, p_value = single_power_law(
        radius[measured], mean[measured], error[measured])
    fig, (left, right) = figure(width=10)
    curve = np.geomspace(radius.min(), radius.max(), 100)
    left.loglog(radius_of_run[free], area[free], "o", color="C0", ms=3, alpha=0.4, label="one bed")
    left.errorbar(radius, mean, yerr=error, fmt="s", color="C0", ms=5, capsize=3,
                  label="mean of the beds ± standard error")
    if floor.any():
        left.loglog(radius_of_run[floor], area[floor], "o", mfc="none", color="C3", ms=5,
                    label="floor-limited (left out of the means)")
    left.loglog(curve, np.pi * curve**2, "k:", lw=1, label="πR² (the projectile's own area)")
    left.set(xlabel="projectile radius R (box units)", ylabel="crater area A (box units²)",
             title=f"area at 10 % energy left, {seed.size} beds per radius")
    left.legend(fontsize=8)
    right.errorbar(middle, local, yerr=local_error, fmt="o-", color="C1", capsize=3,
                   label=f"between neighbouring radii (one power law: χ² = {chi_square:.0f} "
                         f"for {freedom})")
    right.set_xscale("log")
    right.axhline(2.0, color="k", ls=":", lw=1, label="2: geometric similarity (A ∝ mass)")
    right.set(xlabel="projectile radius R (box units)", ylabel="local exponent d ln A / d ln R",
              title="the slope of the left panel, beds not floor-limited")
    right.legend(fontsize=8)
    fig.suptitle(preparation_of(ds), fontsize=9)
    header = (f"projectile_radius,projectile_mass,crater_area_mean,crater_area_error,"
              f"floor_limited_beds,local_exponent_to_next,its_error  (means over the "
              f"{int(free.sum())} beds not floor-limited of {free.size}; no power law fitted: "
              f"the best single one through the means has chi2 = {chi_square:.3g} for "
              f"{freedom} degrees of freedom, p = {p_value:.2g}, exponent {slope:.3f} +- "
              f"{slope_error:.3f})")
    np.savetxt(out_dir / f"{NAME}.csv",
               np.column_stack([radius, mass, mean, error, floor.sum(axis=1),
                                to_next(local, measured), to_next(local_error, measured)]),
               delimiter=",", fmt="%.6g", header=header, comments="")
    return save(fig, out_dir, NAME)
