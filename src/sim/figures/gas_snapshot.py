"""Figure 4: a gas of 10 000 disks after 100 000 contacts (10 per disk), the disks drawn to
scale and coloured by speed, and its kinetic energy against contacts (elastic: constant to
round-off)."""

import numpy as np

from sim.analysis.datasets import open_run
from sim.figures.style import draw_disks, figure, save

NAME = "fig04_gas_snapshot"


def runs(quick):
    """The gas run that figures 4 and 5 share: N disks started at equal speeds (the seed
    study's 10 000; quick 1000), sampled every N/10 collisions for 3N + 200 000 collisions
    (quick 3N + 20 000)."""
    n = 1000 if quick else 10_000
    collisions = 3 * n + (20_000 if quick else 200_000)
    return {"gas": ["scenario=gas", f"disks.n={n}", f"stop.collisions={collisions}",
                    f"output.every_collisions={n // 10}"]}


def draw(runs, sweeps, out_dir):
    with open_run(runs["gas"]) as ds:
        contacts = ds["step"].values
        k = min(int(np.searchsorted(contacts, 10 * ds.sizes["disk"])), contacts.size - 1)
        position = ds["position"].isel(time=k).values
        velocity = ds["velocity"].isel(time=k).values
        radius = ds["radius"].values
        box = ds.attrs["box"]
        energy = ds["kinetic_energy"].values
        n = ds.sizes["disk"]
    speed = np.hypot(velocity[:, 0], velocity[:, 1])
    fig, (left, right) = figure(width=10, height=4.6)
    disks = draw_disks(left, position, radius, values=speed)
    fig.colorbar(disks, ax=left, label="speed (box units / time)")
    left.grid(False)
    left.set(xlim=(0, box[0]), ylim=(0, box[1]), aspect="equal", xlabel="x (box units)",
             ylabel="y (box units)", title=f"{n} disks after {contacts[k]} contacts")
    right.plot(contacts, energy / energy[0] - 1.0, color="C0")
    right.set(xlabel="contacts (disk–disk and disk–wall)", ylabel="E / E₀ − 1",
              title=f"kinetic energy: max |E/E₀ − 1| = "
                    f"{np.abs(energy / energy[0] - 1).max():.1e}")
    right.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    np.savetxt(out_dir / f"{NAME}.csv", np.column_stack([contacts, energy]), delimiter=",",
               header="contacts,kinetic_energy", comments="")
    return save(fig, out_dir, NAME)
