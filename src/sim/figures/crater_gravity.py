"""Figure 11 (beyond the study): crater size against impact energy under gravity.

The ``crater_gravity`` scene (g = 1, box units, time unit √(L/g)): the bed settles alone,
then a projectile (mass ∝ area) falls into it at a range of speeds, and each run ends once
everything is at rest (``stop.at_rest``).

Frictionless disks make a bed without shear strength: under gravity it behaves like a heavy
liquid, and the cavity the projectile opens closes again over it (right panel: the empty
area under the surface against time). The crater that scales is the transient one, the
largest cavity, as for impacts into water. Measure: the bed's surface is read from the
settled bed before impact (the 97th percentile of the bed disks' tops), the grid is
calibrated on the settled bed under that surface (:func:`sim.analysis.crater.calibrated_spacing`),
the cavity is the area under the surface that no disk (projectile included) overlaps, less
that area before impact, and its largest value over the snapshots is the crater. The impact
energy is the projectile's kinetic energy when it reaches the surface,
E = m v₀²/2 + m g (y₀ − R − surface). Each speed runs on ``seeds`` beds (each seed settles
its own); the figure gives the mean largest cavity over the beds with its standard error.

The points curve in log–log (cavities near the projectile's own area πR² are shaped by its size
and the grid more than by the energy, the largest ones feel the box), so no single power law
is fitted (the numbers file's header gives the χ² of the best single one through the means,
:func:`sim.analysis.scaling.single_power_law`): the middle panel gives the local exponent
d ln A / d ln E between neighbouring energies (the standard errors of the two means in
quadrature; the beds of one seed are the same at every speed, so neighbouring energies are
not independent and that error is an estimate), beside β = 2/3 of the 2D gravity regime with
energy scaling (the cavity's mass lifted by its own depth, E ~ ρ g R³; docs/physics.md,
"Cratering"; momentum scaling gives smaller exponents).
"""

import numpy as np
import yaml
from matplotlib.ticker import NullFormatter

from sim.analysis.crater import calibrated_spacing, crater_area, preparation_of, require_stop
from sim.analysis.datasets import open_sweep
from sim.analysis.scaling import local_exponents, single_power_law
from sim.figures.style import figure, save

NAME = "fig11_crater_gravity"
SURFACE_PERCENTILE = 97.0


def speeds(quick):
    return (1.0, 2.0, 4.0, 8.0) if quick else (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)


def seeds(quick):
    return 2 if quick else 5


def sweeps(quick):
    bed = ["bed.n=600", "bed.radius=0.011"] if quick else []
    return {"energy": ["scenario=crater_gravity", *bed,
                       "projectile.speed=" + ",".join(map(str, speeds(quick))),
                       f"seed=range(0,{seeds(quick)})"]}


def cavity_of_run(run):
    """(impact energy, cavity area per snapshot float64[T], time float64[T], Δx) of one run
    of the sweep."""
    config = yaml.safe_load(run["config"].item())
    bed = np.asarray(run["species_id"].values == 0)
    radius = np.asarray(run["radius"].values)
    mass = float(run["mass"].values[~bed][0])
    g = -float(config["gravity"][1])
    snapshots = int(run["kinetic_energy"].notnull().sum())
    position = np.asarray(run["position"].isel(snapshot=slice(0, snapshots)).values)
    width = float(run.attrs["box"][0])
    surface = float(np.percentile(position[0, bed, 1] + radius[bed], SURFACE_PERCENTILE))
    dx = calibrated_spacing(position[0, bed], radius[bed], width, surface)
    empty = np.array([crater_area(p, radius, dx, width, surface)[0] for p in position])
    speed = float(config["projectile"]["speed"])
    drop = position[0, ~bed, 1][0] - radius[~bed][0] - surface
    energy = 0.5 * mass * speed**2 + mass * g * drop
    return energy, empty - empty[0], np.asarray(run["time"].values[:snapshots]), dx


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["energy"])
    speed = ds["projectile_speed"].values
    require_stop(ds, "projectile_speed", "at_rest", "raise their stop.time")
    beds = ds.sizes["seed"]
    cavities = [[cavity_of_run(ds.isel(projectile_speed=k, seed=j)) for j in range(beds)]
                for k in range(speed.size)]
    energy = np.array([[c[0] for c in row] for row in cavities])  # [speed, bed]
    largest = np.array([[c[1].max() for c in row] for row in cavities])
    final = np.array([[c[1][-1] for c in row] for row in cavities])
    mean_energy = energy.mean(axis=1)
    area, area_error = largest.mean(axis=1), largest.std(axis=1, ddof=1) / np.sqrt(beds)
    final_area = final.mean(axis=1)
    middle_energy, local, local_error = local_exponents(mean_energy, area, area_error)
    slope, slope_error, chi_square, freedom, p_value = single_power_law(mean_energy, area,
                                                                        area_error)
    projectile_area = np.pi * float(ds["radius"].values.flat[-1]) ** 2
    fig, (left, middle, right) = figure(ncols=3, width=14)
    fig.suptitle(preparation_of(ds), fontsize=9)
    left.errorbar(mean_energy, area, yerr=area_error, fmt="s", color="C0", capsize=3,
                  label=f"largest cavity, mean of {beds} beds ± standard error")
    left.axhline(projectile_area, color="k", ls=":", lw=1, label="πR², the projectile's area")
    left.set(xscale="log", yscale="log",
             xlabel="impact energy E (bed-disk mass × g × box length)",
             ylabel="crater area A (box units²)", title="transient crater under gravity")
    left.legend(fontsize=8)
    middle.errorbar(middle_energy, local, yerr=local_error, fmt="o-", color="C1", capsize=3,
                    label=f"between neighbouring energies (one power law: χ² = "
                          f"{chi_square:.0f} for {freedom})")
    middle.axhline(2.0 / 3.0, color="k", ls=":", lw=1, label="2/3: 2D gravity, energy scaling")
    middle.set(xscale="log", xlabel="impact energy E", ylabel="local exponent d ln A / d ln E",
               title="the slope of the left panel")
    middle.legend(fontsize=8)
    ticks = [e for e in (20, 50, 100, 200, 500, 1000, 2000, 5000, 10000)
             if mean_energy.min() / 1.5 <= e <= 1.5 * mean_energy.max()]
    for axis in (left, middle):
        axis.set_xticks(ticks, labels=[f"{e:g}" for e in ticks])
        axis.xaxis.set_minor_formatter(NullFormatter())
    for k in range(speed.size):
        _, cavity, time, _ = cavities[k][0]
        right.plot(time, cavity, color=f"C{k}", lw=1, label=f"v₀ = {speed[k]:g}")
    right.set(xlabel="time  [√(L/g)]", ylabel="empty area under the surface (box units²)",
              title=f"it opens and closes (bed 0, Δx = {cavities[0][0][3]:.3g})")
    right.legend(fontsize=7)
    np.savetxt(out_dir / f"{NAME}.csv",
               np.column_stack([speed, mean_energy, area, area_error, final_area,
                                np.full(speed.size, beds), np.append(local, np.nan),
                                np.append(local_error, np.nan)]),
               delimiter=",", fmt="%.6g",
               header=f"projectile_speed,impact_energy,largest_cavity_area,its_error,"
                      f"final_cavity_area,beds,local_exponent_to_next,its_error  (means over "
                      f"the beds; no power law fitted: the best single one through the means "
                      f"has chi2 = {chi_square:.3g} for {freedom} degrees of freedom, p = "
                      f"{p_value:.2g}, exponent {slope:.3f} +- {slope_error:.3f}; projectile "
                      f"area {projectile_area:.6g})", comments="")
    return save(fig, out_dir, NAME)
