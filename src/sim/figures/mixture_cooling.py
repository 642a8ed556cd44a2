"""Figure 7: the species temperatures of a cooling mixture of masses 1 and 4 (equal sizes,
equimolar, ξ = 1, 0.9 and 0.8) settle to the homogeneous cooling state, whose ratio T₂/T₁
Garzó & Dufty, Phys. Rev. E 60, 5706 (1999) predict (sim.analysis.theory).

Each run starts equilibrated: both species Maxwellian at one temperature, zero total
momentum, random positions in a dilute periodic gas. The box is kept below the length at
which a cooling gas grows shear and clusters, L_c = 2√π / (n σ √(1 − ξ²)) (n the number
density, σ the diameter), by the choice of N φ: with φ fixed, n σ grows as √(N φ), and
N φ = 16 puts L_c at 1.31 box sides for the smallest ξ = 0.8 (more for ξ = 0.9), so the gas
stays homogeneous at every stage. A cooling gas still carries flow below that length (its
shear modes, excited by fluctuations, decay more slowly than the heat), and the heavier
species carries more of it, so the species temperatures are taken in the frame of the local
flow on ``CELLS`` × ``CELLS`` cells, momentum-corrected
(:func:`sim.analysis.datasets.granular_temperatures`), as DSMC's homogeneous gas has none.

The window rule: the ratio leaves T₂/T₁ = 1 within the first few collisions per disk (C/N)
and the homogeneous cooling state is averaged over C/N from ``WINDOW[0]`` to the end of the
runs, ``WINDOW[1]``. The right panel shows the window's effect: the mean from each start in
``STARTS`` to the end, with its error. The ratio is that of the species temperatures averaged
over the independent runs (seeds), at each snapshot, then over the window; its error is the
jackknife standard error over the runs (:func:`sim.checks.rows.ratio_of_means`).

Two references. Garzó & Dufty take both velocity distributions as Maxwellian (the leading
Sonine order) and the Enskog collision rate, which cancels in the ratio for equal sizes; DSMC
solves the same Boltzmann–Enskog equation without that approximation
(:mod:`sim.checks.dsmc`, same masses, fractions, n, σ, χ and Maxwellian start, read out at
the runs' mean times, ``DSMC_DISKS`` particles, ``DSMC_SEEDS`` runs). The left panel gives the
mixture temperature T = (T₁ + T₂)/2 against time, beside DSMC's and Haff's law with the
Garzó–Dufty cooling rate from the window's first snapshot
(:func:`sim.analysis.theory.garzo_dufty_haff_temperature`), each run against the law from
its own temperature there. Time is in units of L√(m₁/T₀)
(box side L, the lighter mass m₁, initial temperature T₀), averaged over the runs. L_c is the
estimate of a gas of one mass, with the elastic gas's viscosity, applied to the mixture; the
margin of 31 % covers that.
"""

import numpy as np

from sim.analysis.datasets import granular_temperatures, open_sweep
from sim.analysis.theory import (
    garzo_dufty_haff_temperature,
    garzo_dufty_temperature_ratio,
    kolafa_rottner_z,
)
from sim.checks import dsmc
from sim.checks.rows import block_means, ratio_of_means, relative_difference
from sim.figures import QUICK_FOLDER
from sim.figures.style import figure, save

NAME = "fig07_mixture_cooling"
RESTITUTION = (1.0, 0.9, 0.8)
#: collisions per disk (C/N) over which a run's ratio is averaged: the homogeneous cooling state
WINDOW = (5.0, 30.0)
#: the window's starts (C/N) whose effect the right panel shows, each to ``WINDOW[1]``
STARTS = (2.0, 3.0, 5.0, 7.0, 10.0, 15.0, 20.0)
#: disks and packing fraction: N φ = 16, L_c ≥ 1.31 box sides (module docstring)
DISKS, PACKING = 800, 0.02
#: cells along a side of the grid on which the local flow is subtracted (50 disks a cell)
CELLS = 4
#: particles and runs of the DSMC beside the engine (quick: a fifth of the particles, 4 runs)
DSMC_DISKS, DSMC_SEEDS = 10000, 16


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


def beside(gas, restitution, times, quick):
    """The DSMC of the figure's mixture ``gas`` (:class:`sim.checks.dsmc.Gas`) with ξ =
    ``restitution`` from the runs' start (both species Maxwellian at T = 1), read out at
    ``times``: (C/N [K], T_s float64[K, 2] averaged over the DSMC runs, each run's mean T₂/T₁
    over ``WINDOW``, and each run's mixture temperature at the end over that at the start)."""
    particles, runs = (DSMC_DISKS // 5, 4) if quick else (DSMC_DISKS, DSMC_SEEDS)
    series = [dsmc.run(gas, dsmc.SmoothDisks(restitution), particles, times, seed)[0]
              for seed in range(runs)]
    per_disk = np.mean([s.collisions_per_particle for s in series], axis=0)
    window = (per_disk >= WINDOW[0]) & (per_disk <= WINDOW[1])
    ratios = [np.mean(s.translational[window, 1] / s.translational[window, 0]) for s in series]
    fractions = np.asarray(gas.fractions) / np.sum(gas.fractions)
    cooled = [(s.translational[-1] @ fractions) / (s.translational[0] @ fractions)
              for s in series]
    return per_disk, np.mean([s.translational for s in series], axis=0), ratios, cooled


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["cooling"])
    kind = _first(ds["species_id"], "disk")
    mass = _first(ds["mass"], "disk")
    masses = [float(mass[kind == s][0]) for s in (0, 1)]
    counts = np.array([np.sum(kind == s) for s in (0, 1)])
    fractions = counts / counts.sum()
    area = float(np.prod(ds.attrs["box"]))
    radius = _first(ds["radius"], "disk")
    phi = float(np.sum(np.pi * radius**2)) / area
    density, sigma = counts.sum() / area, 2.0 * float(radius.max())
    chi = (kolafa_rottner_z(phi) - 1.0) / (2.0 * phi)
    gas = dsmc.Gas(masses=tuple(masses), diameters=(sigma, sigma), fractions=tuple(fractions),
                   density=density, chi=chi)
    # (restitution, seed, snapshot, species): temperatures in the frame of the local flow
    position = ds["position"].transpose("restitution_disk", "seed", "snapshot", "disk",
                                        "axis").values
    velocity = ds["velocity"].transpose("restitution_disk", "seed", "snapshot", "disk",
                                        "axis").values
    # each run (seed) places its own species: its masses and species ids
    run_mass = ds["mass"].transpose("seed", "disk").values
    run_kind = ds["species_id"].transpose("seed", "disk").values
    temperature = np.array([[granular_temperatures(position[k, j], velocity[k, j], run_mass[j],
                                                   run_kind[j], ds.attrs["box"], CELLS)
                             for j in range(position.shape[1])]
                            for k in range(position.shape[0])])
    run_time = ds["time"].transpose("restitution_disk", "seed", "snapshot").values
    time = run_time.mean(axis=1)
    per_disk = _first(ds["collisions"], "snapshot") / counts.sum()
    window = (per_disk >= WINDOW[0]) & (per_disk <= WINDOW[1])
    runs = temperature.shape[1]
    quick = out_dir.name == QUICK_FOLDER
    fig, (left, middle, right) = figure(ncols=3, width=15, height=4.4)
    rows, window_rows = [], []
    for k, xi in enumerate(ds["restitution_disk"].values):
        theory = garzo_dufty_temperature_ratio(masses, fractions, xi)
        curve, band, mean, error = ratio_of_means(temperature[k], window)
        exact_per_disk, exact_temperature, exact_ratios, exact_cooled = beside(
            gas, xi, time[k], quick)
        exact, exact_error = block_means(exact_ratios)
        off, off_error = relative_difference(mean, error, exact, exact_error)
        off_theory, off_theory_error = relative_difference(mean, error, theory)
        # the mixture temperature T = Σ x_s T_s of each run, at the end against its own start
        # (DSMC's) and against Haff's law from its own temperature at the window's start
        mixture = temperature[k] @ fractions  # [runs, snapshots]
        start = np.argmax(window)
        haff = np.array([garzo_dufty_haff_temperature(t[start:] - t[start], m[start], masses,
                                                      fractions, xi, density, sigma, chi)
                         for m, t in zip(mixture, run_time[k], strict=True)])
        to_dsmc = relative_difference(*block_means(mixture[:, -1] / mixture[:, 0]),
                                      *block_means(exact_cooled))
        to_haff = relative_difference(*block_means(mixture[:, -1] / haff[:, -1]), 1.0)
        rows.append((xi, theory, exact, exact_error, mean, error, off, off_error, off_theory,
                     off_theory_error, *to_dsmc, *to_haff, runs,
                     instability_length(xi, counts.sum(), phi, area)))
        for first in STARTS:
            _, _, from_start, its_error = ratio_of_means(
                temperature[k], (per_disk >= first) & (per_disk <= WINDOW[1]))
            window_rows.append((xi, first, from_start, its_error))
        left.loglog(time[k, 1:], mixture[:, 1:].mean(axis=0), color=f"C{k}", lw=4, alpha=0.4,
                    label=f"ξ = {xi:g}")
        left.loglog(time[k, 1:], exact_temperature[1:] @ fractions, color=f"C{k}", ls="--",
                    lw=1.2)
        if xi < 1.0:
            left.loglog(time[k, start:], haff.mean(axis=0), color="k", ls=":", lw=1.2)
        middle.fill_between(per_disk, curve - band, curve + band, color=f"C{k}", alpha=0.25,
                            lw=0)
        middle.plot(per_disk, curve, color=f"C{k}",
                    label=f"ξ = {xi:g}: {mean:.3f} ± {error:.3f}; /DSMC − 1 = {off:+.3f} ± "
                          f"{off_error:.3f}, /GD − 1 = {off_theory:+.3f} ± "
                          f"{off_theory_error:.3f}")
        middle.plot(exact_per_disk, exact_temperature[:, 1] / exact_temperature[:, 0],
                    color=f"C{k}", ls="--", lw=1.2)
        middle.axhline(theory, color=f"C{k}", ls=":", lw=1.2)
        window_rows_k = np.array(window_rows[-len(STARTS):])
        right.errorbar(window_rows_k[:, 1], window_rows_k[:, 2], yerr=window_rows_k[:, 3],
                       fmt="o-", color=f"C{k}", capsize=3, ms=4, label=f"ξ = {xi:g}")
        right.axhline(theory, color=f"C{k}", ls=":", lw=1.2)
        right.axhline(exact, color=f"C{k}", ls="--", lw=1.2)
    left.set(xlabel="t  [L √(m₁/T₀)]", ylabel="mixture temperature (T₁ + T₂)/2")
    left.set_title("wide: mean of the runs; dashed: DSMC;\nblack dotted: Haff's law "
                   "(Garzó–Dufty rate)",
                   fontsize=9)
    left.legend(fontsize=8)
    middle.axvspan(*WINDOW, color="0.9", zorder=0)
    middle.set(xlabel="collisions per disk", ylabel=f"T₂ / T₁ (m = {masses[1]:g} over "
                                                    f"m = {masses[0]:g})", ylim=(0.9, 1.6))
    middle.set_title(f"{runs} runs ± jackknife error, N = {counts.sum()}, φ = {phi:.3g};\n"
                     f"dashed: DSMC; dotted: Garzó–Dufty (Maxwellian); grey: averaged",
                     fontsize=9)
    middle.legend(fontsize=6, loc="upper left")
    right.set(xlabel="window start (collisions per disk)",
              ylabel=f"T₂ / T₁ averaged from there to {WINDOW[1]:g}")
    right.axvline(WINDOW[0], color="0.6", lw=1)
    right.set_title("the window's effect; dashed: DSMC, dotted: Garzó–Dufty\n"
                    f"(grey line: the start used, C/N = {WINDOW[0]:g})", fontsize=9)
    right.legend(fontsize=8, loc="center right")
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",", fmt="%.6g",
               header="restitution,garzo_dufty_ratio,dsmc_ratio,dsmc_standard_error,"
                      "measured_ratio,standard_error,measured_over_dsmc_minus_1,its_error,"
                      "measured_over_garzo_dufty_minus_1,its_error,"
                      "temperature_at_the_end_over_dsmc_minus_1,its_error,"
                      "temperature_at_the_end_over_haff_minus_1,its_error,runs,"
                      "instability_length", comments="")
    np.savetxt(out_dir / f"{NAME}_window.csv", np.array(window_rows), delimiter=",",
               fmt="%.6g", header=f"restitution,window_start,measured_ratio_to_{WINDOW[1]:g},"
                                  "standard_error", comments="")
    return save(fig, out_dir, NAME)
