"""Figure 5: relaxation to Maxwell–Boltzmann (2D, k_B = 1; docs/physics.md).

Left: mean speed against collisions, with the equilibration point found automatically — the
first snapshot after which the mean speed stays within four standard deviations of its
late-time mean (the seed study saw about 3N collisions). Right: the histogram of speeds
pooled from snapshots every N collisions after equilibration (200 000 collisions at full
size) against f(v) = (m v / T) exp(−m v² / 2T), T = E/N, with the Kolmogorov–Smirnov p-value
of the last snapshot's N speeds (samples within one snapshot are nearly independent).
"""

import numpy as np
from scipy import stats

from sim.analysis.datasets import open_run
from sim.figures import gas_snapshot
from sim.figures.style import figure, save

NAME = "fig05_maxwell_boltzmann"

#: the gas run of figure 4
runs = gas_snapshot.runs


def equilibration_index(mean_speed, tail=0.5, width=4.0):
    """First index after which ``mean_speed`` stays within ``width`` standard deviations of
    the mean of its last ``tail`` fraction."""
    late = mean_speed[int(len(mean_speed) * (1 - tail)):]
    centre, spread = late.mean(), late.std()
    outside = np.flatnonzero(np.abs(mean_speed - centre) > width * spread)
    return int(outside[-1] + 1) if outside.size else 0


def draw(runs, sweeps, out_dir):
    with open_run(runs["gas"]) as ds:
        n = ds.sizes["disk"]
        mass = float(ds["mass"][0])
        collisions = ds["collisions"].values
        velocity = ds["velocity"].values
        temperature = float(ds["kinetic_energy"][-1]) / n
    speed = np.hypot(velocity[..., 0], velocity[..., 1])
    mean_speed = speed.mean(axis=1)
    k0 = equilibration_index(mean_speed)
    every_n = max(1, int(round(n / max(np.diff(collisions).mean(), 1))))
    pooled = speed[k0::every_n].ravel()
    cdf = lambda v: 1.0 - np.exp(-mass * v**2 / (2 * temperature))  # noqa: E731
    p_value = stats.kstest(speed[-1], cdf).pvalue
    fig, (left, right) = figure()
    left.plot(collisions, mean_speed, color="C0", label="mean speed")
    left.axhline(np.sqrt(np.pi * temperature / (2 * mass)), color="C3", lw=1,
                 label="Maxwell–Boltzmann √(πT/2m)")
    left.axvline(collisions[k0], color="k", ls="--", lw=1,
                 label=f"equilibrated: {collisions[k0]} collisions = {collisions[k0] / n:.1f} N")
    left.set(xlabel="collisions", ylabel="mean speed (box units / time)",
             title=f"relaxation of {n} disks from equal speeds")
    left.legend(fontsize=8)
    v = np.linspace(0, pooled.max(), 300)
    right.hist(pooled, bins=80, density=True, color="C0", alpha=0.6,
               label=f"{pooled.size} samples, {len(speed[k0::every_n])} snapshots")
    right.plot(v, mass * v / temperature * np.exp(-mass * v**2 / (2 * temperature)), "C3",
               label="f(v) = (mv/T) exp(−mv²/2T)")
    right.set(xlabel="speed v (box units / time)", ylabel="probability density",
              title=f"T = E/N = {temperature:.4g}; KS p = {p_value:.2f} (last snapshot)")
    right.legend(fontsize=8)
    hist, edges = np.histogram(pooled, bins=80, density=True)
    np.savetxt(out_dir / f"{NAME}.csv", np.column_stack([edges[:-1], edges[1:], hist]),
               delimiter=",", header="speed_low,speed_high,density", comments="")
    np.savetxt(out_dir / f"{NAME}_relaxation.csv", np.column_stack([collisions, mean_speed]),
               delimiter=",", header="collisions,mean_speed", comments="")
    (out_dir / f"{NAME}.txt").write_text(
        f"equilibration_collisions={collisions[k0]}\nks_pvalue={p_value}\n"
        f"temperature={temperature}\n")
    return save(fig, out_dir, NAME)
