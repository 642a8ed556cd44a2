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
E = m v₀²/2 + m g (y₀ − R − surface). A power law A ∝ E^β is fitted in log–log over the
runs whose cavity covers at least one grid cell, and again over those whose cavity is larger
than the projectile's own area πR² (smaller ones are shaped by the projectile's size and the
grid more than by the energy). In 2D the gravity regime with energy scaling
(the cavity's mass lifted by its own depth, E ~ ρ g R³) gives β = 2/3 (docs/physics.md,
"Cratering"); momentum scaling gives smaller exponents.
"""

import numpy as np
import yaml
from matplotlib.ticker import NullFormatter
from scipy import stats

from sim.analysis.crater import calibrated_spacing, crater_area, preparation_of, require_stop
from sim.analysis.datasets import open_sweep
from sim.figures.style import figure, save

NAME = "fig11_crater_gravity"
SURFACE_PERCENTILE = 97.0


def speeds(quick):
    return (1.0, 2.0, 4.0, 8.0) if quick else (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)


def sweeps(quick):
    bed = ["bed.n=600", "bed.radius=0.011"] if quick else []
    return {"energy": ["scenario=crater_gravity", *bed,
                       "projectile.speed=" + ",".join(map(str, speeds(quick)))]}


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
    cavities = [cavity_of_run(ds.isel(projectile_speed=k)) for k in range(speed.size)]
    energy = np.array([c[0] for c in cavities])
    area = np.array([c[1].max() for c in cavities])
    final = np.array([c[1][-1] for c in cavities])
    opened = area > 0.0  # a cavity below one grid cell is not resolved
    fit = stats.linregress(np.log(energy[opened]), np.log(area[opened]))
    projectile_area = np.pi * float(ds["radius"].values[-1]) ** 2
    large = area > projectile_area
    large_fit = stats.linregress(np.log(energy[large]), np.log(area[large]))
    fig, (left, right) = figure(width=10)
    fig.suptitle(preparation_of(ds), fontsize=9)
    curve = np.geomspace(energy.min(), energy.max(), 100)
    left.loglog(energy[opened], area[opened], "o", color="C0", label="largest cavity")
    left.loglog(curve, np.exp(fit.intercept) * curve**fit.slope, "-", color="C0", lw=1,
                label=f"fit A ∝ E^{fit.slope:.2f} (β = {fit.slope:.2f} ± {fit.stderr:.2f})")
    left.loglog(energy[large], np.exp(large_fit.intercept) * energy[large] ** large_fit.slope,
                "--", color="C3", lw=1, label=f"fit over A > πR²: β = {large_fit.slope:.2f} ± "
                                             f"{large_fit.stderr:.2f}")
    middle = (np.exp(np.mean(np.log(area[opened])))
              * (curve / np.exp(np.mean(np.log(energy[opened])))) ** (2 / 3))
    left.loglog(curve, middle, "k:", lw=1, label="β = 2/3 (2D gravity, energy scaling)")
    left.set(xlabel="impact energy E (bed-disk mass × g × box length)",
             ylabel="crater area A (box units²)", title="transient crater under gravity")
    left.legend(fontsize=8)
    ticks = [e for e in (20, 50, 100, 200, 500, 1000, 2000, 5000, 10000)
             if energy[opened].min() / 1.5 <= e <= 1.5 * energy[opened].max()]
    left.set_xticks(ticks, labels=[f"{e:g}" for e in ticks])
    left.xaxis.set_minor_formatter(NullFormatter())
    for k, (_, cavity, time, _) in enumerate(cavities):
        right.plot(time, cavity, color=f"C{k}", lw=1, label=f"v₀ = {speed[k]:g}")
    right.set(xlabel="time (√(L/g))", ylabel="empty area under the surface (box units²)",
              title=f"the cavity opens and closes (Δx = {cavities[0][3]:.3g})")
    right.legend(fontsize=7)
    np.savetxt(out_dir / f"{NAME}.csv", np.column_stack([speed, energy, area, final]),
               delimiter=",", fmt="%.6g",
               header=f"projectile_speed,impact_energy,largest_cavity_area,final_cavity_area  "
                      f"(fit: exponent {fit.slope:.4f} +- {fit.stderr:.4f}; over cavities "
                      f"larger than the projectile: {large_fit.slope:.4f} +- "
                      f"{large_fit.stderr:.4f}; dx {cavities[0][3]:.6g})", comments="")
    return save(fig, out_dir, NAME)
