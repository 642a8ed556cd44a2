"""Figure 14: compression to jamming (the ``compress`` scene: Lubachevsky–Stillinger growth,
:mod:`sim.effects.growth`). A random gas at φ = 0.3, half its disks 1.4 times larger than the
rest, grows at a rate γ (every radius R(0)(1 + γ t), velocities rescaled to T = 1) until
its reduced pressure βP/ρ reaches 10⁹; the rate is shown dimensionless, Γ = ṡ √(m/T)/⟨σ⟩
(the speed at which a contact of the mean diameter grows, over the thermal speed).

(1) The jamming density φ_J against Γ over two decades, every run (seed) a point, the mean
and standard deviation of each rate's runs beside the published values of the same mixture:
φ_J ≈ 0.84 for fast quenches (O'Hern, Silbert, Liu & Nagel, PRE 68, 011306 (2003)) and
0.84 to 0.853 by protocol (Schreck, O'Hern & Silbert, PRE 84, 011305 (2011)). Those come
from energy minimisation of soft disks — overlaps removed from a random start, at no
temperature — not from growing hard disks at a temperature: the slower the growth, the
longer the gas relaxes on the way and the denser it jams, so LS φ_J rises as Γ falls, and
the published range is a band, not a line. (2) The mean contact number z of each run's
backbone (contacts: gaps below 10⁻⁵ ⟨σ⟩; rattlers, disks with fewer than three contacts,
removed recursively: :mod:`sim.analysis.packing`) against φ_J, beside the isostatic z = 4 of
frictionless disks: slow compressions reach it, fast ones jam hypostatic with more rattlers.
(3) βP/ρ along the slowest compressions (mean over the seeds, in bins of φ) against the
mixture's fluid equation of state (:func:`sim.analysis.theory.mixture_z`: Santos, Yuste &
López de Haro's mapping onto Kolafa & Rottner's one-size fluid) and, near jamming, the
free-volume form 2/(1 − φ/φ_J) with that rate's mean φ_J. (4) Disks of one size compressed
alike: the global bond order |Ψ₆| (:func:`sim.analysis.packing.global_bond_order`) grows as
they crystallise, at the slowest rate towards the hexagonal packing (φ above 0.88), while
the mixture stays disordered: why jamming studies use mixtures (the maximally random jammed
state of one size, φ ≈ 0.826, is reached only by suppressing that order: Atkinson,
Stillinger & Torquato, PNAS 111, 18436 (2014)).
"""

from typing import NamedTuple

import numpy as np
import yaml

from sim.analysis.datasets import global_bond_order, open_sweep
from sim.analysis.packing import compression_pressure, contact_number
from sim.analysis.theory import free_volume_z, mixture_z
from sim.checks.jamming import CONTACT_TOLERANCE, LARGE_FRACTION, PUBLISHED_JAMMING, RADIUS_RATIO
from sim.effects.growth import growth_rate
from sim.figures.style import figure, save

NAME = "fig14_jamming"

#: growth rates γ (1/time) of the full figure: with N = 1000 at φ = 0.3 (⟨σ⟩ ≈ 0.0166 in
#: the unit box, T = 1) Γ runs from 1.7·10⁻⁴ to 1.7·10⁻²
RATES = (0.01, 0.03, 0.1, 0.3, 1.0)
QUICK_RATES = (0.3, 1.0)
SEEDS, QUICK_SEEDS = 5, 2
DISKS, QUICK_DISKS = 1000, 200


def _compress(quick, *overrides):
    return ["scenario=compress", f"disks.n={QUICK_DISKS if quick else DISKS}",
            "observe.bond_order=true", "output.every_time=0.25", *overrides,
            f"seed=range(0,{QUICK_SEEDS if quick else SEEDS})"]


def sweeps(quick):
    rates = QUICK_RATES if quick else RATES
    return {"mixture": _compress(quick, "growth.rate=" + ",".join(map(str, rates))),
            "one_size": _compress(quick, "compress.radius_ratio=1",
                                  f"growth.rate={rates[0]},{rates[-1]}")}


def _runs(sweep):
    """Each run of a sweep as a Dataset, with its rate γ."""
    for rate in sweep["growth_rate"].values:
        for seed in sweep["seed"].values:
            run = sweep.sel(growth_rate=rate, seed=seed)
            yield float(rate), run.isel(snapshot=np.flatnonzero(run["time"].notnull().values))


def _packing(run):
    """φ at every snapshot of a run: π Σ (R_i(0) s)² / A."""
    area = float(np.prod(run.attrs["box"]))
    return np.pi * float(np.sum(run["radius"].values ** 2)) * run["radius_scale"].values**2 / area


def _dimensionless(run, rate):
    """Γ of a run grown at γ = ``rate``: the inverse of :func:`sim.effects.growth.growth_rate`
    at its start (T = K/N, m the mean mass)."""
    temperature = float(run["kinetic_energy"].values[0]) / run.sizes["disk"]
    return rate / growth_rate(1.0, run["radius"].values, temperature / float(run["mass"].mean()))


class Packing(NamedTuple):
    """One run compressed to jamming."""
    relative_rate: float  # Γ
    rate: float  # γ
    jammed: float  # φ_J
    contacts: float  # z of the backbone
    rattlers: float  # their fraction
    interval_phi: np.ndarray  # φ at the middle of each interval between snapshots
    pressure: np.ndarray  # βP/ρ over each interval
    order: np.ndarray  # |Ψ₆| at each snapshot
    phi: np.ndarray  # φ at each snapshot


def _jammed(sweep):
    """Every run of a sweep as a :class:`Packing`."""
    packings = []
    for rate, run in _runs(sweep):
        phi = _packing(run)
        box, periodic = run.attrs["box"], [b == "periodic" for b in run.attrs["boundary"]]
        radius = run["radius"].values * float(run["radius_scale"].values[-1])
        z, rattlers, _ = contact_number(run["position"].values[-1], radius, box, periodic,
                                        CONTACT_TOLERANCE)
        middle, pressure = compression_pressure(run["time"].values,
                                                run["collision_virial"].values,
                                                run["kinetic_energy"].values, phi)
        packings.append(Packing(_dimensionless(run, rate), rate, phi[-1], z, rattlers, middle,
                                pressure, global_bond_order(run).values, phi))
    return packings


def draw(runs, sweeps, out_dir):
    mixture = _jammed(open_sweep(sweeps["mixture"]))
    one_size = _jammed(open_sweep(sweeps["one_size"]))
    fig, axes = figure(ncols=4, width=18)
    table = []
    by_rate = {}  # the mean Γ of the runs at one γ (the seeds' temperatures differ a little)
    for gamma in sorted({p.rate for p in mixture}):
        group = [p for p in mixture if p.rate == gamma]
        by_rate[float(np.mean([p.relative_rate for p in group]))] = group
    rates = list(by_rate)
    for g, group in by_rate.items():
        phis, zs = np.array([p.jammed for p in group]), np.array([p.contacts for p in group])
        axes[0].plot([g] * len(phis), phis, ".", color="C0", alpha=0.6)
        axes[0].errorbar(g, phis.mean(), phis.std(ddof=1), fmt="s", color="C0", capsize=3)
        table.append((g, group[0].rate, phis.mean(), phis.std(ddof=1), zs.mean(),
                      zs.std(ddof=1), np.mean([p.rattlers for p in group]), len(group)))
    low, high = PUBLISHED_JAMMING
    axes[0].axhspan(low, high, color="0.85", label="published, 0.84–0.853 (energy "
                    "minimisation)")
    axes[0].set(xscale="log", xlabel="growth rate Γ = ṡ √(m/T)/⟨σ⟩", ylabel="φ_J",
                title=f"1:{RADIUS_RATIO} mixture jams at φ_J ({table[0][7]} seeds per rate)")
    axes[0].legend(fontsize=7)
    for g, group in by_rate.items():
        axes[1].plot([p.jammed for p in group], [p.contacts for p in group], "o", ms=4,
                     label=f"Γ = {g:.2g}")
    axes[1].axhline(4.0, color="k", lw=1, label="isostatic z = 4")
    axes[1].set(xlabel="φ_J", ylabel="z of the backbone",
                title=f"contacts: gaps < {CONTACT_TOLERANCE:g} ⟨σ⟩, rattlers removed")
    axes[1].legend(fontsize=7)
    slowest = by_rate[rates[0]]
    edges = np.arange(0.3, 0.86, 0.01)
    middle = np.concatenate([p.interval_phi for p in slowest])
    pressure = np.concatenate([p.pressure for p in slowest])
    which = np.digitize(middle, edges)
    bins = [which == k for k in np.unique(which)]
    centres = np.array([middle[b].mean() for b in bins])
    means = np.array([pressure[b].mean() for b in bins])
    errors = np.array([pressure[b].std(ddof=1) / np.sqrt(b.sum()) if b.sum() > 1 else np.nan
                       for b in bins])
    phi_j = table[0][2]
    axes[2].errorbar(centres, means, errors, fmt=".", color="C0", ms=3,
                     label=f"Γ = {rates[0]:.2g}, {len(slowest)} seeds")
    fluid = np.linspace(0.3, 0.7, 100)
    diameters, fractions = (1.0, RADIUS_RATIO), (1.0 - LARGE_FRACTION, LARGE_FRACTION)
    axes[2].plot(fluid, mixture_z(fluid, diameters, fractions), "k",
                 label="fluid (SYH on Kolafa–Rottner)")
    near = np.linspace(0.75, phi_j - 1e-4, 100)
    axes[2].plot(near, free_volume_z(near, phi_j), "k--", label=f"2/(1 − φ/φ_J), φ_J = "
                 f"{phi_j:.4f}")
    axes[2].set(yscale="log", xlabel="φ", ylabel="βP/ρ", title="pressure along the slowest "
                "compression")
    axes[2].legend(fontsize=7)
    for label, packings, color in (("one size", one_size, "C3"), ("mixture", slowest, "C0")):
        gammas = sorted({p.rate for p in packings})
        for gamma in gammas:
            first = next(p for p in packings if p.rate == gamma)  # the first seed
            axes[3].plot(first.phi, first.order, color=color, marker=".", ms=3,
                         ls="-" if gamma == gammas[0] else ":",
                         label=f"{label}, Γ = {first.relative_rate:.2g}: φ_J = "
                               f"{first.jammed:.3f}")
    axes[3].set(xlabel="φ", ylabel="|Ψ₆|",
                title="|Ψ₆| at each snapshot (first seed)")
    axes[3].legend(fontsize=7)
    np.savetxt(out_dir / f"{NAME}.csv", np.array(table), delimiter=",", fmt="%.6g",
               header="rate_dimensionless,growth_rate,phi_j_mean,phi_j_std,z_mean,z_std,"
                      "rattler_fraction,seeds", comments="")
    (out_dir / f"{NAME}.txt").write_text(yaml.safe_dump({
        "one size (rate Γ, φ_J, final |Ψ6|) per run": [
            [round(float(p.relative_rate), 6), round(float(p.jammed), 4),
             round(float(p.order[-1]), 3)] for p in one_size],
        "mixture at the slowest rate (φ_J, final |Ψ6|) per run": [
            [round(float(p.jammed), 4), round(float(p.order[-1]), 3)] for p in slowest]}))
    return save(fig, out_dir, NAME)
