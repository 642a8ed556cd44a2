"""Figure 13: craters in smooth and in rough beds. The crater scene of figure 9 (stop at 10 % of
the kinetic energy, the area measured on the grid of figure 8, sim.analysis.crater) run twice
on the same beds: smooth disks (β = −1, today's default), and rough disks with Coulomb
friction (Walton's model, β₀ = ``ROUGH_BETA``, μ_f = ``ROUGH_MU``, at disk and wall contacts;
:mod:`sim.effects.rotation`). A rough contact also loses energy to the sliding of the
touching surfaces and turns some of it into spin; the figure measures what that does to the
crater at the same stop.

Each bed is settled smooth before the impact (the scene's preparation); roughness acts from the
impact on. The numbers file gives, per radius and bed kind, the mean area over the beds and
its standard error; floor-limited runs (figure 9's test) are not excluded here: they are
circled, and counted in the file.
"""

import numpy as np

from sim.analysis.crater import CraterGeometry, crater_overrides
from sim.analysis.datasets import at_last_snapshot, open_sweep
from sim.figures.crater_radius import floor_limited
from sim.figures.style import figure, save

NAME = "fig13_crater_rough"
ROUGH_BETA, ROUGH_MU = 0.5, 0.5
BEDS = {"smooth": [],
        "rough": [f"restitution.tangential={ROUGH_BETA}", f"friction.mu={ROUGH_MU}",
                  f"restitution.wall_tangential={ROUGH_BETA}", f"friction.wall_mu={ROUGH_MU}"]}


def radii(quick):
    return (0.02, 0.04, 0.06) if quick else (0.02, 0.04, 0.06, 0.08)


def sweeps(quick):
    seeds = 2 if quick else 3
    return {kind: [*crater_overrides(quick), *options,
                   "projectile.radius=" + ",".join(map(str, radii(quick))),
                   f"seed=range(0,{seeds})"]
            for kind, options in BEDS.items()}


def areas(ds):
    """(crater area float64[radius, seed], floor-limited bool[radius, seed]) of one sweep."""
    last = at_last_snapshot(ds, "position")
    shape = (ds.sizes["projectile_radius"], ds.sizes["seed"])
    area, floor = np.empty(shape), np.empty(shape, dtype=bool)
    for i in range(shape[0]):
        for j in range(shape[1]):
            one = ds.isel(projectile_radius=i, seed=j)
            stop = str(one["stop_reason"].item())
            floor[i, j] = floor_limited(one)
            if stop != "energy_fraction" and not floor[i, j]:
                raise ValueError(f"a run stopped by {stop} before 10 % of its energy was left: "
                                 f"raise stop.collisions")
            area[i, j] = CraterGeometry.of_run(one).area(
                last.isel(projectile_radius=i, seed=j).values)
    return area, floor


def draw(runs, sweeps, out_dir):
    fig, (left, right) = figure(width=10)
    rows, means = [], {}
    for k, kind in enumerate(BEDS):
        ds = open_sweep(sweeps[kind])
        radius = ds["projectile_radius"].values
        area, floor = areas(ds)
        mean = area.mean(axis=1)
        error = area.std(axis=1, ddof=1) / np.sqrt(area.shape[1])
        means[kind] = mean
        rows += [(r, k, m, e, f) for r, m, e, f in zip(radius, mean, error, floor.sum(axis=1),
                                                         strict=True)]
        left.errorbar(radius, mean, yerr=error, fmt="s-", color=f"C{k}", capsize=3,
                      label=f"{kind} bed")
        reached = floor.any(axis=1)
        if reached.any():
            left.plot(radius[reached], mean[reached], "o", mfc="none", ms=11, color=f"C{k}",
                      label=f"{kind}: a bed dug through to the floor")
    left.set(xscale="log", yscale="log", xlabel="projectile radius R (box units)",
             ylabel="crater area A (box units²)",
             title=f"area at 10 % energy left, {area.shape[1]} beds per radius")
    left.legend(fontsize=8)
    right.plot(radius, means["rough"] / means["smooth"], "o-", color="C2")
    right.axhline(1.0, color="k", ls=":", lw=1)
    right.set(xscale="log", xlabel="projectile radius R (box units)",
              ylabel="A(rough) / A(smooth)",
              title=f"rough: β₀ = {ROUGH_BETA}, μ_f = {ROUGH_MU} (disks and walls)")
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",", fmt="%.6g",
               header="projectile_radius,rough,crater_area_mean,crater_area_error,"
                      "floor_limited_beds", comments="")
    return save(fig, out_dir, NAME)
