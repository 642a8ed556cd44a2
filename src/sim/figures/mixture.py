"""Figure 6: a mixture of masses 1 and 4 (ξ = 1) started at equal speeds: the speeds of each
species after equilibration against Maxwell–Boltzmann at the common temperature T = E/N, with
the Kolmogorov–Smirnov p-value of each species' speeds in the last snapshot of the first run,
and the ratio of the two species' temperatures, which equipartition makes 1 exactly (an
isolated gas of quadratic degrees of freedom, whatever the masses).

T_s is the mean kinetic energy of a disk of species s (2D: m v²/2 = T), each run's mean over
its snapshots after equilibration (once each species' mean energy over N collisions has
settled, :func:`sim.figures.maxwell_boltzmann.settled_index`; from equal speeds the heavy
species starts four times hotter). Those snapshots are correlated over many collisions per
disk (the slow collective modes of a walled box), so one run's scatter understates the error
of its mean: T₂/T₁ = 1.016 ± 0.006 read from one run's snapshots was a fluctuation of that
kind. The error is the standard error over ``RUNS`` independent runs (seeds), and the ratio
is drawn with it.
"""

import numpy as np
from scipy import stats

from sim.analysis.datasets import open_sweep
from sim.analysis.theory import maxwell_speed_cdf, maxwell_speed_pdf
from sim.checks.rows import block_means
from sim.figures.maxwell_boltzmann import settled_index
from sim.figures.style import figure, save

NAME = "fig06_mixture"


#: independent runs (seeds) of the full figure; the quick one has two
RUNS = 6


def mixture_overrides(quick, restitution=1.0):
    n = 1000 if quick else 4000
    collisions = 3 * n + (20_000 if quick else 200_000)
    return ["scenario=mixture", f"disks.n={n}", f"stop.collisions={collisions}",
            f"output.every_collisions={n // 10}", f"restitution.disk={restitution}"]


def sweeps(quick):
    return {"mixture": [*mixture_overrides(quick), f"seed=range(0,{2 if quick else RUNS})"]}


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["mixture"])
    n = ds.sizes["disk"]
    mass, kind = ds["mass"].values, ds["species_id"].values  # [run, disk]: each seed its own
    speed = np.hypot(ds["velocity"].values[..., 0], ds["velocity"].values[..., 1])
    energy = 0.5 * mass[:, None, :] * speed**2  # [run, snapshot, disk]
    temperature = float(ds["kinetic_energy"].values[0, -1]) / n
    every_n = max(1, int(round(n / np.diff(ds["collisions"].values[0]).mean())))
    ratios, starts = [], []
    for run in range(ds.sizes["seed"]):
        species = [kind[run] == s for s in (0, 1)]
        # equilibrated once each species' mean energy over N collisions has settled
        k0 = max(settled_index(energy[run][:, at].mean(axis=1), every_n) for at in species)
        ratios.append(energy[run, k0:][:, species[1]].mean()
                      / energy[run, k0:][:, species[0]].mean())
        starts.append(k0)
    ratio, error = block_means(ratios)
    fig, axes = figure()
    rows = []
    for ax, s in zip(axes, (0, 1), strict=True):
        m = float(mass[0][kind[0] == s][0])
        pooled = np.concatenate([speed[run, k0::10][:, kind[run] == s].ravel()
                                 for run, k0 in enumerate(starts)])
        p_value = stats.kstest(speed[0, -1, kind[0] == s],
                               lambda v, m=m: maxwell_speed_cdf(v, m, temperature)).pvalue
        v = np.linspace(0, pooled.max(), 300)
        ax.hist(pooled, bins=60, density=True, color=f"C{s}", alpha=0.6,
                label=f"m = {m:g}: {pooled.size} samples, {len(starts)} runs")
        ax.plot(v, maxwell_speed_pdf(v, m, temperature), "k",
                label=f"Maxwell–Boltzmann, T = {temperature:.3g}")
        ax.set(xlabel="speed v (box units / time)", ylabel="probability density",
               title=f"species m = {m:g}: KS p = {p_value:.2f} (last snapshot)")
        ax.legend(fontsize=8)
        rows.append((m, temperature, p_value, pooled.mean(), ratio, error, len(ratios)))
    fig.suptitle(f"T₂/T₁ = {ratio:.4f} ± {error:.4f} (standard error over {len(ratios)} runs; "
                 f"equipartition: 1)", fontsize=9)
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",", fmt="%.6g",
               header="mass,temperature,ks_pvalue,mean_speed,temperature_ratio,"
                      "its_standard_error,runs", comments="")
    return save(fig, out_dir, NAME)
