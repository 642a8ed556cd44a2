"""Figure 12: cooling rough disks (ξ = 0.9, q = 1/2, the ``rough_cooling`` scene), beside
the DSMC solution of the same Boltzmann–Enskog equation (:mod:`sim.checks.dsmc`, same n, σ,
χ, q and start). From spins at rest, T_rot/T_tr climbs within a few collisions per disk to
the ratio of the homogeneous cooling state; from there on T_tr falls as Haff's law. The
two-temperature Maxwellian theory (:func:`sim.analysis.theory.rough_disk_temperature_ratio`,
:func:`sim.analysis.theory.rough_disk_haff_temperature` from the first snapshot of
``WINDOW`` with Enskog's collision frequency there, each run from its own T_tr) is an
approximation: its closure
neglects the fourth cumulants, and it misses the ratio by a few per cent, where DSMC solves
the kinetic equation itself. The numbers file gives measured/DSMC − 1 and measured/theory −
1 of the ratio, each with its standard error, the runs, and T_tr at the end of the runs
against DSMC's and Haff's law (mean of the runs' T_tr(end)/T_tr(0), its standard error).

T_tr is taken in the frame of the local flow on 4 × 4 cells
(:func:`sim.analysis.datasets.granular_temperatures`), T_rot = ⟨I ω²⟩, both averaged over the
runs (seeds) at each snapshot; the ratio's error is the standard error over the runs of each
run's mean over ``WINDOW`` (DSMC's, of ``DSMC_SEEDS`` runs of ``DSMC_DISKS`` particles, over
the same window). Time is in units of L √(m/T₀) (box side L, disk mass m, initial
temperature T₀), averaged over the runs. The more nearly smooth the disks (β → −1), the
weaker the coupling of spin and translation and the slower the climb (β = −0.5 has not
settled after 12 collisions per disk, C/N, so it is not drawn). The gas is dilute and its
box small against the length at which a cooling gas grows shear and clusters, L_c =
2√π/(n σ √(1 − ξ²)) = 2.3 box sides for ξ = 0.9 at N = 2000, φ = 0.005 (roughness dissipates
more per collision and shortens it somewhat), so that it stays homogeneous over the window.
"""

import numpy as np
import yaml

from sim.analysis.datasets import granular_temperatures, open_sweep
from sim.analysis.theory import (
    enskog_collision_frequency,
    kolafa_rottner_z,
    rough_disk_haff_temperature,
    rough_disk_temperature_ratio,
)
from sim.checks import dsmc
from sim.checks.rows import block_means, relative_difference
from sim.effects.rotation import moment_of_inertia
from sim.figures import QUICK_FOLDER
from sim.figures.style import figure, save

NAME = "fig12_rough_cooling"
RESTITUTION = 0.9
ROUGHNESS = (0.0, 0.5, 1.0)
#: collisions per disk (C/N) over which a run's ratio is averaged: the homogeneous cooling state
WINDOW = (7.0, 12.0)
#: disks and packing fraction: the clustering length of ξ = 0.9 is 2.3 box sides (module docstring)
DISKS, PACKING = 2000, 0.005
#: particles and runs of the DSMC beside the engine (quick: a fifth of the particles, 4 runs)
DSMC_DISKS, DSMC_SEEDS = 10000, 16


def sweeps(quick):
    seeds = 4 if quick else 16
    return {"rough": ["scenario=rough_cooling", f"disks.n={DISKS}",
                      f"disks.packing_fraction={PACKING}",
                      f"restitution.disk={RESTITUTION}",
                      "restitution.tangential=" + ",".join(map(str, ROUGHNESS)),
                      f"stop.collisions={int(WINDOW[1] * DISKS)}",
                      f"output.every_collisions={DISKS // 4}", f"seed=range(0,{seeds})"]}


def temperatures(run, q):
    """(T_tr [snapshots], T_rot [snapshots]) of one run of the sweep (a Dataset without the
    swept dimensions)."""
    mass, radius = run["mass"].values, run["radius"].values
    translational = granular_temperatures(run["position"].values, run["velocity"].values, mass,
                                          np.zeros(mass.size, int), run.attrs["box"], 4)[:, 0]
    inertia = moment_of_inertia(q, mass, radius)
    rotational = np.mean(inertia * run["angular_velocity"].values ** 2, axis=1)
    return translational, rotational


def beside(n, sigma, chi, q, beta, temperature, times, quick):
    """The DSMC of the figure's gas (density ``n`` disks per unit area, diameter ``sigma``,
    Enskog factor ``chi``, q, ξ = :data:`RESTITUTION`, β) from the runs' start (Maxwellian
    at ``temperature``, spins at rest), read out at ``times``: (C/N [K], T_tr [K], T_rot [K]),
    each float64 averaged over the DSMC runs, the runs' window means of T_rot/T_tr, and their
    T_tr at the end over that at the start)."""
    gas = dsmc.Gas(diameters=(sigma,), density=n, chi=chi, inertia_factor=q)
    rule = dsmc.RoughDisks(RESTITUTION, beta)
    particles, seeds = (DSMC_DISKS // 5, 4) if quick else (DSMC_DISKS, DSMC_SEEDS)
    series = [dsmc.run(gas, rule, particles, times, seed, temperature=temperature)[0]
              for seed in range(seeds)]
    per_disk = np.mean([s.collisions_per_particle for s in series], axis=0)
    window = (per_disk >= WINDOW[0]) & (per_disk <= WINDOW[1])
    ratios = [np.mean(s.rotational[window, 0] / s.translational[window, 0]) for s in series]
    return (per_disk, np.mean([s.translational[:, 0] for s in series], axis=0),
            np.mean([s.rotational[:, 0] for s in series], axis=0), ratios,
            [s.translational[-1, 0] / s.translational[0, 0] for s in series])


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["rough"])
    q = float(yaml.safe_load(ds["config"].values.flat[0])["disks"]["inertia_factor"])
    per_disk = ds["collisions"].isel(restitution_tangential=0, seed=0).values / ds.sizes[
        "disk"]
    window = (per_disk >= WINDOW[0]) & (per_disk <= WINDOW[1])
    n = ds.sizes["disk"]
    area = float(np.prod(ds.attrs["box"]))
    density = n / area
    phi = float(np.sum(np.pi * ds["radius"] ** 2) / area)
    chi = (kolafa_rottner_z(phi) - 1.0) / (2.0 * phi)
    sigma = 2.0 * float(ds["radius"].max())
    fig, (left, right) = figure(width=10)
    rows = []
    for k, beta in enumerate(ds["restitution_tangential"].values):
        curves, ratios, times = [], [], []
        for seed in ds["seed"].values:
            run = ds.sel(restitution_tangential=beta, seed=seed)
            translational, rotational = temperatures(run, q)
            curves.append((translational, rotational))
            ratios.append(np.mean(rotational[window] / translational[window]))
            times.append(run["time"].values)
        time = np.mean(times, axis=0)
        ratio, error = block_means(ratios)
        theory = rough_disk_temperature_ratio(RESTITUTION, beta, q)
        exact_per_disk, exact_tr, exact_rot, exact_ratios, exact_cooled = beside(
            density, sigma, chi, q, beta, np.mean([c[0][0] for c in curves]), time,
            out_dir.name == QUICK_FOLDER)
        exact, exact_error = block_means(exact_ratios)
        off, off_error = relative_difference(ratio, error, exact, exact_error)
        # each run's T_tr at the end: over its start against DSMC's, and against Haff's law
        # from its own T_tr at the first snapshot of the cooling state
        start = np.argmax(window)
        haff = np.array([rough_disk_haff_temperature(
            t[start:] - t[start], c[0][start],
            enskog_collision_frequency(density, sigma, chi, c[0][start]), RESTITUTION, beta, q)
            for c, t in zip(curves, times, strict=True)])
        to_dsmc = relative_difference(*block_means([c[0][-1] / c[0][0] for c in curves]),
                                      *block_means(exact_cooled))
        to_haff = relative_difference(*block_means(np.array([c[0][-1] for c in curves])
                                                  / haff[:, -1]),
                                      1.0)
        rows.append((beta, exact, exact_error, theory, ratio, error, off, off_error,
                     ratio / theory - 1.0, error / theory, len(ratios), *to_dsmc, *to_haff))
        translational, rotational = np.mean(curves, axis=0)
        left.plot(per_disk, rotational / translational, color=f"C{k}",
                  label=f"β = {beta:g}: {ratio:.3f} ± {error:.3f}, /DSMC − 1 = "
                        f"{off:+.3f} ± {off_error:.3f}")
        left.plot(exact_per_disk, exact_rot / exact_tr, color=f"C{k}", ls="--", lw=1.2)
        left.axhline(theory, color=f"C{k}", ls=":", lw=1.2)
        right.semilogy(time, translational / translational[0], color=f"C{k}", lw=4, alpha=0.4,
                       label=f"β = {beta:g}: at the end /DSMC − 1 = {to_dsmc[0]:+.3f} ± "
                             f"{to_dsmc[1]:.3f}, /Haff − 1 = {to_haff[0]:+.3f} ± "
                             f"{to_haff[1]:.3f}")
        right.semilogy(time, exact_tr / exact_tr[0], color=f"C{k}", ls="--", lw=1.2)
        right.semilogy(time[start:], haff.mean(axis=0) / translational[0], color="k", ls=":",
                       lw=1.2)
    left.axvspan(*WINDOW, color="0.9", zorder=0, label="averaged (cooling state)")
    left.set(xlabel="collisions per disk", ylabel="T_rot / T_tr")
    left.set_title(f"ξ = {RESTITUTION}, q = {q}, N = {n}, φ = {phi:.3g}, {ds.sizes['seed']} "
                   f"runs\nsolid: engine; dashed: DSMC; dotted: Maxwellian theory", fontsize=9)
    left.legend(fontsize=7)
    right.set(xlabel="t  [L √(m/T₀)]", ylabel="T_tr / T_tr(0)")
    right.set_title("T_tr, wide: mean of the runs; dashed: DSMC;\nblack dotted: Haff's law "
                    f"(Maxwellian theory) from C/N = {WINDOW[0]:g}", fontsize=9)
    right.legend(fontsize=7)
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",", fmt="%.6g",
               header="tangential_restitution,dsmc_ratio,dsmc_standard_error,theory_ratio,"
                      "measured_ratio,standard_error,measured_over_dsmc_minus_1,its_error,"
                      "measured_over_theory_minus_1,its_error,runs,"
                      "temperature_at_the_end_over_dsmc_minus_1,its_error,"
                      "temperature_at_the_end_over_haff_minus_1,its_error", comments="")
    return save(fig, out_dir, NAME)
