"""Figure 9: crater area against projectile radius R (the seed study's Figure 11): ten radii
from 0.01 to 0.10, mass ∝ R² (the bed's areal density), one Hydra multirun read with
open_sweep, each run stopped at 10 % of its kinetic energy as in the study and measured on
the grid of figure 8 (one Δx for all: the bed is the same). A power law A = c Rᵅ is fitted by
least squares in log–log (scipy.stats.linregress), its exponent given with its standard
error. Without gravity and with grains much smaller than the projectile, geometric
similarity gives α = 2 (area ∝ mass, as the study read its data; physics.md, "Cratering").
The largest projectiles reach the
floor of the half-filled box before 10 % of the energy is left, and their craters saturate:
one run per radius (one bed), so a single power law is a rough summary, not a law.
"""

import numpy as np
from scipy import stats

from sim.analysis import at_last_snapshot, open_sweep
from sim.figures.crater_runs import CraterGeometry, crater_overrides, require_stop
from sim.figures.style import figure, save

NAME = "fig09_crater_radius"


def radii(quick):
    return (0.02, 0.04, 0.06, 0.08) if quick else tuple(round(0.01 * k, 2) for k in range(1, 11))


def sweeps(quick):
    return {"radius": [*crater_overrides(quick),
                       "projectile.radius=" + ",".join(map(str, radii(quick)))]}


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["radius"])
    radius = ds["projectile_radius"].values
    require_stop(ds, "projectile_radius", "energy_fraction", "raise their stop.collisions")
    last = at_last_snapshot(ds, "position")
    geometry = CraterGeometry.of_run(ds.isel(projectile_radius=0))
    area = np.array([geometry.area(last.isel(projectile_radius=k).values)
                     for k in range(radius.size)])
    mass = ds["mass"].isel(disk=-1).values
    fit = stats.linregress(np.log(radius), np.log(area))
    fig, (left, right) = figure(width=10)
    curve = np.geomspace(radius.min(), radius.max(), 100)
    left.loglog(radius, area, "o", color="C0", label="simulated")
    left.loglog(curve, np.exp(fit.intercept) * curve**fit.slope, "-", color="C0", lw=1,
                label=f"fit A = {np.exp(fit.intercept):.3g} R^{fit.slope:.2f}"
                      f" (α = {fit.slope:.2f} ± {fit.stderr:.2f})")
    left.loglog(curve, np.pi * curve**2, "k:", lw=1, label="πR² (the projectile's own area)")
    left.set(xlabel="projectile radius R (box units)", ylabel="crater area A (box units²)",
             title=f"crater area at 10 % energy left, Δx = {geometry.dx:.4g}")
    left.legend(fontsize=8)
    right.plot(mass, area, "o-", color="C1")
    right.set(xlabel="projectile mass (bed-disk masses)", ylabel="crater area A (box units²)",
              title="the same against mass ∝ R²")
    np.savetxt(out_dir / f"{NAME}.csv", np.column_stack([radius, mass, area]), delimiter=",",
               fmt="%.6g", header=f"projectile_radius,projectile_mass,crater_area  (fit: "
                                  f"exponent {fit.slope:.4f} +- {fit.stderr:.4f}, prefactor "
                                  f"{np.exp(fit.intercept):.4g}, dx {geometry.dx:.6g})",
               comments="")
    return save(fig, out_dir, NAME)
