"""Figure 6: a mixture of masses 1 and 4 (ξ = 1) started at equal speeds: the speeds of each
species after equilibration against Maxwell–Boltzmann at the common temperature T = E/N, with
the Kolmogorov–Smirnov p-value of each species' speeds in the last snapshot."""

import numpy as np
from scipy import stats

from sim.analysis.datasets import open_run
from sim.analysis.theory import maxwell_speed_cdf, maxwell_speed_pdf
from sim.figures.maxwell_boltzmann import equilibration_index
from sim.figures.style import figure, save

NAME = "fig06_mixture"


def mixture_overrides(quick, restitution=1.0):
    n = 1000 if quick else 4000
    collisions = 3 * n + (20_000 if quick else 200_000)
    return ["scenario=mixture", f"disks.n={n}", f"stop.collisions={collisions}",
            f"output.every_collisions={n // 10}", f"restitution.disk={restitution}"]


def runs(quick):
    return {"mixture": mixture_overrides(quick)}


def draw(runs, sweeps, out_dir):
    with open_run(runs["mixture"]) as ds:
        n = ds.sizes["disk"]
        mass = ds["mass"].values
        kind = ds["species_id"].values
        velocity = ds["velocity"].values
        temperature = float(ds["kinetic_energy"][-1]) / n
    speed = np.hypot(velocity[..., 0], velocity[..., 1])
    energy = 0.5 * mass * speed**2
    # equilibrated once the mean energy of each species has settled
    k0 = max(equilibration_index(energy[:, kind == s].mean(axis=1)) for s in (0, 1))
    fig, axes = figure()
    rows = []
    for ax, s in zip(axes, (0, 1), strict=True):
        m = float(mass[kind == s][0])
        pooled = speed[k0::10, kind == s].ravel()
        p_value = stats.kstest(speed[-1, kind == s],
                               lambda v, m=m: maxwell_speed_cdf(v, m, temperature)).pvalue
        v = np.linspace(0, pooled.max(), 300)
        ax.hist(pooled, bins=60, density=True, color=f"C{s}", alpha=0.6,
                label=f"m = {m:g}: {pooled.size} samples")
        ax.plot(v, maxwell_speed_pdf(v, m, temperature), "k",
                label=f"Maxwell–Boltzmann, T = {temperature:.3g}")
        ax.set(xlabel="speed v (box units / time)", ylabel="probability density",
               title=f"species m = {m:g}: KS p = {p_value:.2f} (last snapshot)")
        ax.legend(fontsize=8)
        rows.append((m, temperature, p_value, pooled.mean()))
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",",
               header="mass,temperature,ks_pvalue,mean_speed", comments="")
    return save(fig, out_dir, NAME)
