"""Figure 5: relaxation to Maxwell–Boltzmann (2D, k_B = 1; docs/physics.md).

Left: from equal speeds, the mean speed and the speed moment ratio K = ⟨v⁴⟩/⟨v²⟩² of each
snapshot against collisions per disk, each over its Maxwell–Boltzmann value (√(πT/2m) and
2). Equilibration is judged by K, which sees the shape of the distribution, not by the mean
speed: the first snapshot at which K's mean over the last N collisions has gone 95 % of its
way to the mean of its late half (:func:`settled_index`, three relaxation times of an
exponential approach; the mean speed, judged alike, settles sooner; the seed study's "about
3N collisions" read it). Beside it, the Kolmogorov–Smirnov p-value of one snapshot's N
speeds (a fixed sample size, samples within a snapshot nearly independent) at that snapshot
and at the last: pooling ever more snapshots would reject in the end, since a finite
isolated gas is not exactly Maxwellian (its energy is fixed). Right: the histogram of speeds
pooled from snapshots every N collisions after equilibration (200 000 collisions at full
size) against
f(v) = (m v / T) exp(−m v² / 2T), T = E/N.
"""

import numpy as np
from scipy import stats

from sim.analysis.datasets import open_run
from sim.figures import gas_snapshot
from sim.figures.style import figure, save

NAME = "fig05_maxwell_boltzmann"

#: the gas run of figure 4
runs = gas_snapshot.runs


#: the share of its way to the late level at which a relaxation counts as done (three
#: relaxation times of an exponential approach)
SETTLED = 0.95


def settled_index(series, every_n, tail=0.5):
    """The first snapshot at which the mean of ``series`` over the last ``every_n`` snapshots
    (N collisions) has gone :data:`SETTLED` of its way from its first value to the mean of
    the last ``tail`` fraction of ``series``."""
    smooth = np.convolve(series, np.ones(every_n) / every_n, "valid")
    level = series[int(len(series) * (1 - tail)):].mean()
    done = np.flatnonzero((smooth - smooth[0]) / (level - smooth[0]) >= SETTLED)
    return every_n - 1 + (int(done[0]) if done.size else 0)


def draw(runs, sweeps, out_dir):
    with open_run(runs["gas"]) as ds:
        n = ds.sizes["disk"]
        mass = float(ds["mass"][0])
        collisions = ds["collisions"].values
        velocity = ds["velocity"].values
        temperature = float(ds["kinetic_energy"][-1]) / n
    speed = np.hypot(velocity[..., 0], velocity[..., 1])
    mean_speed = speed.mean(axis=1)
    moments = np.mean(speed**4, axis=1) / np.mean(speed**2, axis=1) ** 2
    every_n = max(1, int(round(n / max(np.diff(collisions).mean(), 1))))
    k0, k_mean = settled_index(moments, every_n), settled_index(mean_speed, every_n)
    pooled = speed[k0::every_n].ravel()
    cdf = lambda v: 1.0 - np.exp(-mass * v**2 / (2 * temperature))  # noqa: E731
    p_value = stats.kstest(speed[-1], cdf).pvalue
    p_at_equilibration = stats.kstest(speed[k0], cdf).pvalue
    per_disk = collisions / n
    fig, (left, right) = figure()
    left.plot(per_disk, moments / 2.0, color="C1", label="⟨v⁴⟩/⟨v²⟩² / 2")
    left.plot(per_disk, mean_speed / np.sqrt(np.pi * temperature / (2 * mass)), color="C0",
              label="mean speed / √(πT/2m)")
    left.axhline(1.0, color="C3", lw=1, label="Maxwell–Boltzmann")
    left.axvline(per_disk[k0], color="k", ls="--", lw=1,
                 label=f"equilibrated by ⟨v⁴⟩/⟨v²⟩²: {per_disk[k0]:.1f} N "
                       f"(KS p = {p_at_equilibration:.2g}, N speeds)")
    left.axvline(per_disk[k_mean], color="0.5", ls=":", lw=1,
                 label=f"by the mean speed alone: {per_disk[k_mean]:.1f} N")
    left.set(xlabel="collisions per disk", ylabel="over the Maxwell–Boltzmann value",
             title=f"relaxation of {n} disks from equal speeds")
    left.legend(fontsize=7)
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
    np.savetxt(out_dir / f"{NAME}_relaxation.csv",
               np.column_stack([collisions, mean_speed, moments]), delimiter=",",
               header="collisions,mean_speed,speed_moment_ratio", comments="")
    (out_dir / f"{NAME}.txt").write_text("".join(f"{key}={value}\n" for key, value in (
        ("disks", n), ("equilibration_collisions", collisions[k0]),
        ("equilibration_by_the_mean_speed_alone", collisions[k_mean]),
        ("ks_pvalue_at_equilibration", p_at_equilibration), ("ks_pvalue", p_value),
        ("late_speed_moment_ratio", moments[k0:].mean()), ("temperature", temperature))))
    return save(fig, out_dir, NAME)
