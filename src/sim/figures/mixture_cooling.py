"""Figure 7: the species temperatures of a cooling mixture of masses 1 and 4 (equal sizes,
equimolar, ξ = 1, 0.9 and 0.8) settle to the homogeneous cooling state, whose ratio T₂/T₁
Garzó & Dufty, Phys. Rev. E 60, 5706 (1999) predict (sim.analysis.theory).

Each run starts equilibrated: both species Maxwellian at one temperature, zero total
momentum, random positions in a dilute periodic gas. The box is kept below the length at
which a cooling gas grows shear and clusters, L_c = 2√π / (n σ √(1 − ξ²)) (n the number
density, σ the diameter), by the choice of N φ: with φ fixed, n σ grows as √(N φ), and
N φ = 16 puts L_c at 1.31 box sides for the smallest ξ = 0.8 (more for ξ = 0.9), so the gas
stays homogeneous at every stage and the species temperatures are the kinetic energies per
disk (2D, k_B = 1: T_s = E_s/N_s), no flow to subtract. The ratio leaves T₂/T₁ = 1 in the
first few collisions per disk; the window from ``WINDOW[0]`` collisions per disk on is the
homogeneous cooling state. The ratio is that of the species temperatures averaged over the
independent runs (seeds), at each snapshot, then over the window; its error is the
jackknife standard error over the runs (:func:`ratio_over_runs`). The theory takes both
velocity distributions as Maxwellian (the leading Sonine order) and the Enskog collision
rate, which cancels for equal sizes; this figure measures how close that approximation
comes. L_c is the estimate of a gas of one mass, with the elastic gas's viscosity, applied
to the mixture; the margin of 31 % covers that.
"""

import numpy as np

from sim.analysis.datasets import open_sweep
from sim.analysis.theory import garzo_dufty_temperature_ratio
from sim.figures.style import figure, save

NAME = "fig07_mixture_cooling"
RESTITUTION = (1.0, 0.9, 0.8)
#: collisions per disk (C/N) over which a run's ratio is averaged: the homogeneous cooling state
WINDOW = (5.0, 30.0)
#: disks and packing fraction: N φ = 16, L_c ≥ 1.31 box sides (module docstring)
DISKS, PACKING = 800, 0.02


def seeds(quick):
    return 4 if quick else 16


def instability_length(restitution, n=DISKS, phi=PACKING, area=1.0):
    """L_c = 2√π / (n σ √(1 − ξ²)) in box units for ``n`` equal disks at packing fraction
    ``phi`` in a box of ``area`` (number density n/A, σ = 2R, φ = n π R²/A); inf at ξ = 1."""
    if restitution == 1.0:
        return np.inf
    sigma = 2.0 * np.sqrt(phi * area / (n * np.pi))
    return 2.0 * np.sqrt(np.pi) / (n / area * sigma * np.sqrt(1.0 - restitution**2))


def sweeps(quick):
    collisions = int(WINDOW[1] * DISKS)
    return {"cooling": ["scenario=mixture", "box.boundary=periodic", f"disks.n={DISKS}",
                        f"disks.packing_fraction={PACKING}", "disks.speed=null",
                        "disks.temperature=1.0", "disks.zero_momentum=true", "tc.time=1e-9",
                        f"stop.collisions={collisions}",
                        f"output.every_collisions={DISKS // 2}",
                        "restitution.disk=" + ",".join(map(str, RESTITUTION)),
                        f"seed=range(0,{seeds(quick)})"]}


def _first(array, keep):
    """``array`` of the first run, along its dimension ``keep`` (the same in every run)."""
    return array.isel({d: 0 for d in array.dims if d != keep}).values


def ratio_over_runs(temperature, window):
    """T₂/T₁ of the runs together: the ratio of their mean temperatures at each snapshot
    (a mean of per-run ratios would carry the bias E[T₂/T₁] − E[T₂]/E[T₁], about 1/N_s),
    and its mean over the snapshots in ``window``, each with its jackknife standard error
    over the runs (leave one run out). ``temperature``: float64[runs, snapshots, 2].
    Returns (curve [snapshots], its error, window mean, its error)."""
    runs = temperature.shape[0]
    curve = temperature[:, :, 1].mean(axis=0) / temperature[:, :, 0].mean(axis=0)
    left_out = np.array([np.delete(temperature, j, axis=0).mean(axis=0) for j in range(runs)])
    curves = left_out[:, :, 1] / left_out[:, :, 0]  # [runs, snapshots]
    means = curves[:, window].mean(axis=1)

    def jackknife(values):
        return np.sqrt((runs - 1) / runs * np.sum((values - values.mean(axis=0)) ** 2, axis=0))

    return curve, jackknife(curves), curve[window].mean(), jackknife(means)


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["cooling"])
    kind = _first(ds["species_id"], "disk")
    mass = _first(ds["mass"], "disk")
    masses = [float(mass[kind == s][0]) for s in (0, 1)]
    counts = np.array([np.sum(kind == s) for s in (0, 1)])
    area = float(np.prod(ds.attrs["box"]))
    phi = float(np.sum(np.pi * _first(ds["radius"], "disk") ** 2)) / area
    # (restitution, seed, snapshot, species): kinetic energy per disk of each species
    temperature = ds["kinetic_energy_by_species"].transpose(
        "restitution_disk", "seed", "snapshot", "species").values / counts
    per_disk = _first(ds["collisions"], "snapshot") / counts.sum()
    window = (per_disk >= WINDOW[0]) & (per_disk <= WINDOW[1])
    seeds = temperature.shape[1]
    fig, (left, right) = figure(width=10)
    rows = []
    for k, xi in enumerate(ds["restitution_disk"].values):
        theory = garzo_dufty_temperature_ratio(masses, counts / counts.sum(), xi)
        curve, band, mean, error = ratio_over_runs(temperature[k], window)
        rows.append((xi, theory, mean, error, seeds,
                     instability_length(xi, counts.sum(), phi, area)))
        for s, style in ((0, "-"), (1, "--")):
            left.semilogy(per_disk, temperature[k, :, :, s].mean(axis=0), style, color=f"C{k}",
                          label=f"ξ = {xi:g}, m = {masses[s]:g}")
        right.fill_between(per_disk, curve - band, curve + band, color=f"C{k}", alpha=0.25,
                           lw=0)
        right.plot(per_disk, curve, color=f"C{k}",
                   label=f"ξ = {xi:g}: {mean:.3f} ± {error:.3f}")
        right.axhline(theory, color=f"C{k}", ls=":", lw=1.2, label=f"Garzó–Dufty {theory:.3f}")
    right.axvspan(*WINDOW, color="0.9", zorder=0, label="averaged (cooling state)")
    left.set(xlabel="collisions per disk", ylabel="temperature T_s = E_s / N_s",
             title="species temperatures (solid m = 1, dashed m = 4)")
    left.legend(fontsize=7, ncol=2)
    right.set(xlabel="collisions per disk", ylabel="T₂ / T₁ (m = 4 over m = 1)",
              ylim=(0.9, 1.6),
              title=f"{seeds} runs ± jackknife error, N = {counts.sum()}, φ = {phi:.3g}")
    right.legend(fontsize=7, ncol=2, loc="upper left")
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",", fmt="%.6g",
               header="restitution,garzo_dufty_ratio,measured_ratio,standard_error,runs,"
                      "instability_length", comments="")
    return save(fig, out_dir, NAME)
