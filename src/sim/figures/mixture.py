"""Figure 6: a mixture of masses 1 and 4 (ξ = 1) started at equal speeds: the speeds of each
species after equilibration against Maxwell–Boltzmann at the common temperature T = E/N, with
the Kolmogorov–Smirnov p-value of each species' speeds in the last snapshot of the first run,
and (right) the ratio of the two species' temperatures, which equipartition makes 1 exactly
(an isolated gas of quadratic degrees of freedom, whatever the masses).

T_s is the mean kinetic energy of a disk of species s (2D: m v²/2 = T). From equal speeds
the heavy species starts four times hotter, and T₂/T₁ relaxes to 1 with a tail of some ten
collisions per disk (C/N): over 16 runs of N = 1000 at φ = 0.3 it read 1.073 ± 0.010 at
C/N = 2–5, 1.035 ± 0.007 at 5–10, 1.017 ± 0.005 at 10–20 and 0.996 ± 0.004 at 20–40. The
right panel shows it for these runs; each run's ratio is that of its species' energies
averaged over C/N ≥ ``AVERAGED_FROM`` (shaded), and its error the standard error over
``RUNS`` independent runs (seeds), since the snapshots of one run are correlated over many
collisions per disk. A window that starts as soon as each species' mean energy looks
settled takes in the tail: it read 1.0117 ± 0.0025.
"""

import numpy as np
from scipy import stats

from sim.analysis.datasets import open_sweep
from sim.analysis.theory import maxwell_speed_cdf, maxwell_speed_pdf
from sim.checks.rows import block_means
from sim.figures.style import figure, save

NAME = "fig06_mixture"


#: independent runs (seeds) of the full figure; the quick one has two
RUNS = 6
#: collisions per disk after which the species' energies are averaged (module docstring)
AVERAGED_FROM = 20.0


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
    per_disk = ds["collisions"].values[0] / n
    averaged = per_disk >= AVERAGED_FROM
    species = [[kind[run] == s for s in (0, 1)] for run in range(ds.sizes["seed"])]
    series = np.array([energy[run][:, at[1]].mean(axis=1) / energy[run][:, at[0]].mean(axis=1)
                       for run, at in enumerate(species)])  # [run, snapshot]
    ratios = [energy[run][averaged][:, at[1]].mean() / energy[run][averaged][:, at[0]].mean()
              for run, at in enumerate(species)]
    ratio, error = block_means(ratios)
    fig, axes = figure(ncols=3, width=13)
    rows = []
    for ax, s in zip(axes[:2], (0, 1), strict=True):
        m = float(mass[0][kind[0] == s][0])
        pooled = np.concatenate([speed[run][averaged][::10, kind[run] == s].ravel()
                                 for run in range(len(ratios))])
        p_value = stats.kstest(speed[0, -1, kind[0] == s],
                               lambda v, m=m: maxwell_speed_cdf(v, m, temperature)).pvalue
        v = np.linspace(0, pooled.max(), 300)
        ax.hist(pooled, bins=60, density=True, color=f"C{s}", alpha=0.6,
                label=f"m = {m:g}: {pooled.size} samples, {len(ratios)} runs")
        ax.plot(v, maxwell_speed_pdf(v, m, temperature), "k",
                label=f"Maxwell–Boltzmann, T = {temperature:.3g}")
        ax.set(xlabel="speed v (box units / time)", ylabel="probability density",
               title=f"species m = {m:g}: KS p = {p_value:.2f} (last snapshot)")
        ax.legend(fontsize=8)
        rows.append((m, temperature, p_value, pooled.mean(), ratio, error, len(ratios)))
    mean, spread = series.mean(axis=0), series.std(axis=0, ddof=1) / np.sqrt(len(ratios))
    right = axes[2]
    right.plot(per_disk, mean, color="C2", label="T₂/T₁, mean of the runs")
    right.fill_between(per_disk, mean - spread, mean + spread, color="C2", alpha=0.3, lw=0,
                       label="± standard error")
    right.axhline(1.0, color="k", lw=1, label="equipartition")
    right.axvspan(AVERAGED_FROM, per_disk[-1], color="0.9", zorder=0,
                  label=f"averaged: {ratio:.4f} ± {error:.4f}")
    right.set(xlabel="collisions per disk", ylabel="T₂ / T₁", ylim=(0.9, 1.2),
              title=f"from equal speeds ({len(ratios)} runs)")
    right.legend(fontsize=7)
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",", fmt="%.6g",
               header="mass,temperature,ks_pvalue,mean_speed,temperature_ratio,"
                      "its_standard_error,runs", comments="")
    return save(fig, out_dir, NAME)
