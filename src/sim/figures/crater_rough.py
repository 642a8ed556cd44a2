"""Figure 13: craters in smooth and in rough beds. The crater scene of figure 9 (the area
measured on the grid of figure 8, sim.analysis.crater) run twice on the same beds: smooth
disks (β = −1, today's default), and rough disks with Coulomb friction (Walton's model,
β₀ = ``ROUGH_BETA``, μ_f = ``ROUGH_MU``, at disk and wall contacts;
:mod:`sim.effects.rotation`). A rough contact also loses energy to the sliding of the touching
surfaces and turns some of it into spin; the figure measures what that does to the crater.

Each run stops at 10 % of its kinetic energy, as in figure 9; a rough bed gets there sooner,
so the stops are different stages of the impact. The two are therefore compared at the same
time after the launch (in 10 L/v₀, L the box side and v₀ = 10 the launch speed): snapshots
every ``SPACING``, and for each bed the last snapshot that both its smooth and its
rough run reached, within ``SPACING`` of the earlier stop (left panel: the area of each run
against time, the compared time marked). The ratio A(rough)/A(smooth) is taken bed by bed
(the same seed, the same bed) and averaged over the beds, with its standard error.
Projectiles that reach the floor in figure 9 (R ≥ 0.07) are not run: their crater is the
box's; a bed whose smooth or rough run still reaches the floor is left out of the ratio and
counted in the numbers file.

Each bed is settled smooth before the impact (the scene's preparation); roughness acts from the
impact on.
"""

import numpy as np

from sim.analysis.crater import CraterGeometry, crater_overrides
from sim.analysis.datasets import open_sweep
from sim.checks.rows import block_means
from sim.figures.crater_radius import floor_limited
from sim.figures.style import figure, save

NAME = "fig13_crater_rough"
ROUGH_BETA, ROUGH_MU = 0.5, 0.5
BEDS = {"smooth": [],
        "rough": [f"restitution.tangential={ROUGH_BETA}", f"friction.mu={ROUGH_MU}",
                  f"restitution.wall_tangential={ROUGH_BETA}", f"friction.wall_mu={ROUGH_MU}"]}
#: time between snapshots, in which the projectile at its launch speed moves 2 % of the box
SPACING = 0.002


def radii(quick):
    return (0.02, 0.04) if quick else (0.02, 0.04, 0.06)


def seeds(quick):
    return 2 if quick else 5


def sweeps(quick):
    bed = [o for o in crater_overrides(quick) if not o.startswith("output.")]
    return {kind: [*bed, *options, "output.every_collisions=null",
                   f"output.every_time={SPACING}",
                   "projectile.radius=" + ",".join(map(str, radii(quick))),
                   f"seed=range(0,{seeds(quick)})"]
            for kind, options in BEDS.items()}


def crater_in_time(run):
    """(time float64[T], crater area float64[T], floor-limited) of one run of a sweep, over
    its own snapshots; stopped otherwise than at 10 % of the energy is a ValueError."""
    stop = str(run["stop_reason"].item())
    floor = floor_limited(run)
    if stop != "energy_fraction" and not floor:
        raise ValueError(f"a run stopped by {stop} before 10 % of its energy was left: "
                         f"raise stop.collisions")
    snapshots = int(run["kinetic_energy"].notnull().sum())
    geometry = CraterGeometry.of_run(run)
    position = run["position"].isel(snapshot=slice(0, snapshots)).values
    return (run["time"].values[:snapshots], np.array([geometry.area(p) for p in position]),
            floor)


def compared(smooth, rough):
    """The index of the last snapshot at the same time in both runs (each a pair of times and
    areas from :func:`crater_in_time`): the runs share their snapshot times up to the earlier
    stop, whose own snapshot lies off that grid. ValueError when they share only the start."""
    k = min(smooth[0].size, rough[0].size) - 1
    while k > 0 and smooth[0][k] != rough[0][k]:
        k -= 1
    if k == 0:
        raise ValueError("a smooth and a rough run share no snapshot time after the start: "
                         "run both with the same output.every_time")
    return k


def draw(runs, sweeps, out_dir):
    smooth_ds, rough_ds = (open_sweep(sweeps[kind]) for kind in BEDS)
    radius = smooth_ds["projectile_radius"].values
    beds = smooth_ds.sizes["seed"]
    fig, (left, right) = figure(width=10)
    rows = []
    for i, r in enumerate(radius):
        pairs, floors = [], 0
        for j in range(beds):
            smooth, rough = (crater_in_time(ds.isel(projectile_radius=i, seed=j))
                             for ds in (smooth_ds, rough_ds))
            k = compared(smooth, rough)
            if smooth[2] or rough[2]:
                floors += 1
            else:
                pairs.append((smooth[0][k], smooth[1][k], rough[1][k]))
            for kind, (time, area, _) in enumerate((smooth, rough)):
                left.plot(time, area, color=f"C{i}", ls=("-", "--")[kind], lw=0.8, alpha=0.6,
                          label=(f"R = {r:g}" if kind == 0 and j == 0 else None))
            left.plot(smooth[0][k], smooth[1][k], "o", color=f"C{i}", ms=3)
        if len(pairs) < 2:
            raise ValueError(f"at R = {r:g}, {floors} of {beds} beds reached the floor: too "
                             f"few left to compare")
        time, smooth_area, rough_area = np.array(pairs).T
        rows.append((r, time.mean(), *block_means(smooth_area), *block_means(rough_area),
                     *block_means(rough_area / smooth_area), len(pairs), floors))
    rows = np.array(rows)
    left.set(xlabel="time after launch  [10 L/v₀: box side L, launch speed v₀ = 10]",
             ylabel="crater area A (box units²)")
    left.set_title(f"each bed: smooth (solid) and rough (dashed) to 10 % energy left;\n"
                   f"dots: the time both reached, where they are compared ({beds} beds)",
                   fontsize=9)
    left.legend(fontsize=8)
    right.errorbar(rows[:, 0], rows[:, 6], yerr=rows[:, 7], fmt="o-", color="C2", capsize=3,
                   label="mean over the beds ± standard error")
    right.axhline(1.0, color="k", ls=":", lw=1)
    right.set(xscale="log", xlabel="projectile radius R (box units)",
              ylabel="A(rough) / A(smooth), same bed, same time")
    right.set_title(f"rough: β₀ = {ROUGH_BETA}, μ_f = {ROUGH_MU} (disks and walls)", fontsize=9)
    right.legend(fontsize=8)
    np.savetxt(out_dir / f"{NAME}.csv", rows, delimiter=",", fmt="%.6g",
               header="projectile_radius,compared_time,smooth_area,its_error,rough_area,"
                      "its_error,rough_over_smooth,its_error,beds,floor_limited_beds",
               comments="")
    return save(fig, out_dir, NAME)
