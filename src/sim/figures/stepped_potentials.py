"""Figure 15: disks with a stepped pair potential (:mod:`sim.effects.potential`), the hard core
σ and shells of constant energy ε_k out to λ_k σ.

(1) The second virial coefficient. A square well (λ = 1.5, depth ε = 1 in the run's energy
units, ε₁ = −ε; kT = K/(N − 1) with zero total momentum) in a periodic box at four low
densities and two temperatures, one below the Boyle temperature (kT_B/ε = 1.70: B₂ < 0) and
one above (B₂ > 0), several seeds each: (βP/ρ − 1)/ρσ² against ρσ², with
βPA = N + (N − 1)X/⟨K⟩ (X the collision virial, steps included, over twice the time), a
weighted line taken to ρ → 0 and the exact B₂/σ² = (π/2)[1 + (λ² − 1)(1 − e^{βε})] (derived
in the docs) at the runs' mean kT. The pairs that fall into the well at the start warm the
gas, so the runs end at somewhat different kT: each run's value is moved to the mean kT by
the difference of the exact B₂ between the two (:func:`sim.checks.potential.second_virial`,
the validation row of the same measurement). The first eighth of every run (50 collisions
per disk) is cut as its equilibration; the error of each density is the standard error over
its seeds.
(2) g(r) of a gas with a well inside a shoulder (λ = 1.3, 1.6; ε = −1, +0.5) at φ = 0.2: it
jumps at every step by e^{−β(u_out − u_in)} (the cavity function is continuous), measured
by lines fitted to the six bins of 0.01 σ on each side of the step, the error from eight
blocks of the production's snapshots. The snapshots are equal in time, about four collisions
per disk apart (one taken at a collision would hold that pair at contact, a spike in g(σ)).
(3) The ``square_well`` scene at kT/ε = 0.35 between thermal walls, below the liquid–vapour
critical point: the gas splits into liquid drops and vapour, the disks coloured by how many
others sit inside their well (the movie of the same run is ``movie_square_well``).
"""

import numpy as np
import yaml
from scipy.spatial import cKDTree

from sim.analysis.datasets import open_run, open_sweep
from sim.checks.potential import extrapolated_b2, step_ratios
from sim.figures.style import draw_disks, figure, save

NAME = "fig15_stepped_potentials"

#: the square well of panels 1 and 3, and the well-in-a-shoulder of panel 2
WELL, WELL_ENERGY = 1.5, -1.0
STEPS, ENERGIES = (1.3, 1.6), (-1.0, 0.5)
#: panel 1: packing fractions, temperatures kT/ε, seeds, disks and collisions per run
PHIS, QUICK_PHIS = (0.01, 0.02, 0.03, 0.04), (0.02, 0.04)
TEMPERATURES = (1.0, 3.0)
SEEDS, QUICK_SEEDS = 8, 4
DISKS, QUICK_DISKS = 1000, 300
COLLISIONS, QUICK_COLLISIONS = 400_000, 60_000
#: the share of every run cut as its equilibration
EQUILIBRATION = 1 / 8
#: panel 2: bins of g(r) (r_max 2σ: 0.01 σ wide, edges on the steps), bins fitted on each
#: side of a step, blocks of the production's snapshots
BINS, R_MAX, FITTED, BLOCKS = 200, 2.0, 6, 8


def _gas(n, *overrides):
    """A periodic gas of ``n`` disks, Maxwellian with zero total momentum."""
    return ["scenario=gas", "box.boundary=periodic", f"disks.n={n}", "disks.speed=null",
            "disks.zero_momentum=true", "output.progress=false", *overrides]


def _potential(steps, energies):
    return [f"potential.steps=[{','.join(map(str, steps))}]",
            f"potential.energies=[{','.join(map(str, energies))}]"]


def split_run(quick):
    """The overrides of the ``square_well`` run that panel 3 and the movie share: a
    snapshot every 5 collisions per disk (quick: 50 000 collisions in all), the clusters
    linked within the well (gap 0.5 σ)."""
    return ["scenario=square_well", "observe.clusters.gap=0.5",
            *(["stop.collisions=50000"] if quick else []),
            f"output.every_collisions={1000 if quick else 10_000}"]


def sweeps(quick):
    n = QUICK_DISKS if quick else DISKS
    return {"virial": _gas(n, *_potential([WELL], [WELL_ENERGY]),
                           "disks.packing_fraction=" + ",".join(
                               map(str, QUICK_PHIS if quick else PHIS)),
                           "disks.temperature=" + ",".join(map(str, TEMPERATURES)),
                           f"stop.collisions={QUICK_COLLISIONS if quick else COLLISIONS}",
                           f"output.every_collisions={n}",
                           f"seed=range(0,{QUICK_SEEDS if quick else SEEDS})")}


def runs(quick):
    n = QUICK_DISKS if quick else DISKS
    return {"jumps": _gas(n, *_potential(STEPS, ENERGIES), "disks.packing_fraction=0.2",
                          "disks.temperature=1.0", "stop.collisions=null",
                          f"stop.time={7 if quick else 50}", "output.every_collisions=null",
                          f"output.every_time={0.025 if quick else 0.05}",
                          f"observe.radial_distribution.bins={BINS}",
                          f"observe.radial_distribution.r_max={R_MAX}"),
            "square_well": split_run(quick)}


def _production(run):
    """The snapshots after the equilibration cut of a run: a bool mask."""
    collisions = run["collisions"].values
    return collisions >= EQUILIBRATION * collisions[-1]


def _virial_ratio(run):
    """(ρσ², (βP/ρ − 1)/ρσ², kT) of one run over its production: X from the collision virial
    between its first and last snapshot, ⟨K⟩ the time average of the snapshots' K."""
    kept = _production(run)
    time, virial = run["time"].values[kept], run["collision_virial"].values[kept]
    kinetic = run["kinetic_energy"].values[kept]
    n = run.sizes["disk"]
    sigma = 2.0 * float(run["radius"].values[0])
    rho = n * sigma**2 / float(np.prod(run.attrs["box"]))
    mean_kinetic = float(np.trapezoid(kinetic, time) / (time[-1] - time[0]))
    x = (virial[-1] - virial[0]) / (2.0 * (time[-1] - time[0]))
    return rho, (n - 1) * x / (n * mean_kinetic) / rho, mean_kinetic / (n - 1)


def _second_virial(sweep):
    """A :class:`sim.checks.potential.Virial` per temperature of the sweep."""
    return [extrapolated_b2([_virial_ratio(sweep.sel(disks_temperature=temperature,
                                                     disks_packing_fraction=phi, seed=seed))
                             for phi in sweep["disks_packing_fraction"].values
                             for seed in sweep["seed"].values], [WELL], [WELL_ENERGY])
            for temperature in sweep["disks_temperature"].values]


def _jumps(run):
    """(r/σ, g, kT, [(λ, measured ratio, error, e^{−β(u_out − u_in)})]) over the production
    (:func:`sim.checks.potential.step_ratios`)."""
    kept = _production(run)
    g = run["radial_distribution"].values[kept]
    kt = float(np.mean(run["kinetic_energy"].values[kept])) / (run.sizes["disk"] - 1)
    r = run["r"].values
    blocks = np.array([block.mean(axis=0) for block in np.array_split(g, BLOCKS)])
    return r, g.mean(axis=0), kt, step_ratios(r, blocks, STEPS, ENERGIES, kt, FITTED)


def _wells_filled(position, radius, reach):
    """How many other disks sit inside each disk's well, centres closer than ``reach`` σ
    (equal disks between walls)."""
    pairs = cKDTree(position).query_pairs(reach * 2.0 * float(radius[0]), output_type="ndarray")
    return np.bincount(pairs.ravel(), minlength=len(position))


def draw(runs, sweeps, out_dir):
    sweep = open_sweep(sweeps["virial"])
    virial, seeds = _second_virial(sweep), sweep["seed"].values
    with open_run(runs["jumps"]) as run:
        r, g, kt_jumps, jumps = _jumps(run.load())
        seed_jumps, n_jumps = int(run.attrs["seed"]), run.sizes["disk"]
    with open_run(runs["square_well"]) as run:
        position = run["position"].values[-1]
        radius = run["radius"].values
        box = run.attrs["box"]
        config = yaml.safe_load(run.attrs["config"])
        n = run.sizes["disk"]
        kt_split = float(run["kinetic_energy"].values[-1]) / n  # K = N kT between walls
        collisions = int(run["collisions"].values[-1])
        seed_split = int(run.attrs["seed"])
    reach, walls = config["potential"]["steps"][-1], config["walls"]["left"]["temperature"]
    fig, (left, middle, right) = figure(ncols=3, width=16, height=4.8)
    line = np.linspace(0.0, max(v.density.max() for v in virial) * 1.05, 50)
    for color, v in zip(("C0", "C3"), virial, strict=False):
        left.errorbar(v.density, v.mean, v.error, fmt="o", color=color,
                      label=f"kT/ε = {v.kt:.3f}: B₂/σ² = {v.b2:.3f} ± {v.b2_error:.3f}")
        left.plot(line, v.b2 + v.slope * line, color=color, lw=1)
        left.plot([0.0], [v.exact], "*", ms=12, color=color, mec="k",
                  label=f"exact B₂/σ² = {v.exact:.3f}")
    left.axhline(0.0, color="0.6", lw=0.8)
    left.set(xlabel="ρσ²", ylabel="(βP/ρ − 1)/ρσ²",
             title=f"square well λ = {WELL}: to ρ → 0 ({virial[0].runs} runs per kT,\n"
                   f"N = {sweep.sizes['disk']}, seeds {seeds.min()}–{seeds.max()}; "
                   f"± standard error over the seeds)")
    left.legend(fontsize=7)
    middle.plot(r, g, color="C0", lw=1, drawstyle="steps-mid")
    for step, ratio, error, expected in jumps:
        middle.axvline(step, color="0.6", lw=0.8, ls=":")
        middle.annotate(f"λ = {step}\n{ratio:.3f} ± {error:.3f}\ne^(−βΔu) = {expected:.3f}",
                        (step, 0.95 * g.max()), fontsize=7, ha="left")
    middle.set(xlim=(0.9, R_MAX), xlabel="r/σ", ylabel="g(r)",
               title=f"well ε = {ENERGIES[0]:g} to {STEPS[0]}σ, shoulder {ENERGIES[1]:g} to "
                     f"{STEPS[1]}σ; kT/ε = {kt_jumps:.3f}\nN = {n_jumps}, seed {seed_jumps}; "
                     f"± standard error over {BLOCKS} blocks")
    filled = _wells_filled(position, radius, reach)
    disks = draw_disks(right, position, radius, values=filled.astype(float), cmap="viridis")
    fig.colorbar(disks, ax=right, label=f"disks within {reach}σ")
    right.grid(False)
    right.set(xlim=(0, box[0]), ylim=(0, box[1]), aspect="equal", xticks=[], yticks=[],
              title=f"square well, walls at kT/ε = {walls}: {n} disks, {collisions:.2g} "
                    f"collisions\n(kinetic kT/ε = {kt_split:.2f} at the end), seed {seed_split}")
    np.savetxt(out_dir / f"{NAME}.csv",
               [(v.kt, v.b2, v.b2_error, v.exact, v.slope, v.runs) for v in virial],
               delimiter=",", header="kT,B2,B2_error,B2_exact,slope,runs", comments="")
    (out_dir / f"{NAME}.txt").write_text("".join(
        f"jump_{k}_lambda={step} jump_{k}_ratio={ratio} jump_{k}_error={error} "
        f"jump_{k}_expected={expected}\n"
        for k, (step, ratio, error, expected) in enumerate(jumps)) + f"jumps_kT={kt_jumps}\n")
    return save(fig, out_dir, NAME)
