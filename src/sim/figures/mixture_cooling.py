"""Figure 7: the mixture of masses 1 and 4 cooling at ξ = 1, 0.9 and 0.8 (periodic box, TC
model far below the mean free time): mean kinetic energy per disk of each species against
time, and the ratio of species temperatures T₂/T₁ against the homogeneous-cooling value of
Garzó & Dufty, Phys. Rev. E 60, 5706 (1999) (sim.theory).

Temperatures are taken in the frame of the local flow (sim.analysis.granular_temperatures):
the box is larger than the critical size of the clustering instability, and the shear flow it
grows would otherwise count as heat, pushing the ratio of raw kinetic energies towards the
mass ratio 4 (dotted grey lines show that raw ratio). The numbers file gives the ratio
averaged from 2 to 8 collisions per disk, after the start's transient and before the
instability has grown.
"""

import numpy as np

from sim.analysis import granular_temperatures, open_run
from sim.figures.mixture import mixture_overrides
from sim.figures.style import figure, save
from sim.theory import garzo_dufty_temperature_ratio

NAME = "fig07_mixture_cooling"
RESTITUTION = (1.0, 0.9, 0.8)


def runs(quick):
    return {f"xi={xi}": [*mixture_overrides(quick, xi), "box.boundary=periodic",
                         "tc.time=1e-9"] for xi in RESTITUTION}


def draw(runs, sweeps, out_dir):
    fig, (left, right) = figure(width=10)
    rows = []
    for k, xi in enumerate(RESTITUTION):
        with open_run(runs[f"xi={xi}"]) as ds:
            time = ds["time"].values
            kind = ds["species_id"].values
            masses = [float(ds["mass"][kind == s][0]) for s in (0, 1)]
            counts = [int((kind == s).sum()) for s in (0, 1)]
            per_disk = ds["kinetic_energy_by_species"].values / np.array(counts)
            granular = granular_temperatures(ds["position"].values, ds["velocity"].values,
                                             ds["mass"].values, kind, ds.attrs["box"])
            per_disk_collisions = ds["collisions"].values * 2.0 / ds.sizes["disk"]
        raw_ratio = per_disk[:, 1] / per_disk[:, 0]
        ratio = granular[:, 1] / granular[:, 0]
        theory = garzo_dufty_temperature_ratio(masses, np.array(counts) / sum(counts), xi)
        for s, style in ((0, "-"), (1, "--")):
            left.plot(time, per_disk[:, s], style, color=f"C{k}",
                      label=f"ξ = {xi}, m = {masses[s]:g}")
        right.plot(time, raw_ratio, ":", color="0.6", lw=0.8)
        right.plot(time, ratio, color=f"C{k}", label=f"ξ = {xi}")
        right.axhline(theory, color=f"C{k}", ls=":", lw=1.2,
                      label=f"Garzó–Dufty {theory:.3f}")
        # the homogeneous cooling state: after the start's transient (2 collisions per disk),
        # before the instability grows (8 per disk)
        window = ratio[(per_disk_collisions >= 2) & (per_disk_collisions <= 8)]
        rows.append((xi, theory, window.mean(), window.std()))
    left.set(xlabel="time", ylabel="mean kinetic energy per disk", yscale="log",
             title="energy per species (solid m = 1, dashed m = 4)")
    left.legend(fontsize=7, ncol=2)
    right.set(xlabel="time", ylabel="T₂ / T₁ (m = 4 over m = 1)",
              title="temperature ratio (local-flow frame) vs theory")
    right.legend(fontsize=7, ncol=2)
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",",
               header="restitution,garzo_dufty_ratio,measured_ratio_mean,measured_ratio_std",
               comments="")
    return save(fig, out_dir, NAME)
