"""Figure 1: one disk launched at 45° from the middle of the left wall.

Left: its positions at every snapshot over 10 000 wall contacts — they all lie on the tilted
rectangle through the middles of the four walls. Right: each snapshot's distance from that
exact rectangle, |(|x − Lx/2| + |y − Ly/2|) − (L/2 − R)|/√2 in a square box of side L, against
time: the round-off the path has gathered (zero drawn at 1e-17).
"""

import numpy as np

from sim.analysis.datasets import open_run
from sim.figures.style import figure, save

NAME = "fig01_single_disk"


def runs(quick):
    contacts, every = (1000, 0.5) if quick else (10_000, 0.1)
    return {"single_disk": ["scenario=single_disk", f"stop.contacts={contacts}",
                            f"output.every_time={every}"]}


def draw(runs, sweeps, out_dir):
    with open_run(runs["single_disk"]) as ds:
        position = ds["position"].isel(disk=0).values
        energy = ds["kinetic_energy"].values
        step = ds["step"].values
        time = ds["time"].values
        radius = float(ds["radius"][0])
        box = ds.attrs["box"]
    fig, (left, right) = figure()
    left.plot(position[:, 0], position[:, 1], ".", ms=1.5, color="C0",
              label=f"{len(position)} snapshots")
    corners = np.array([[radius, 0.5], [0.5, 1 - radius], [1 - radius, 0.5], [0.5, radius],
                        [radius, 0.5]]) * [box[0], box[1]]
    left.plot(*corners.T, "-", color="C3", lw=0.8, label="tilted rectangle")
    left.set(xlim=(0, box[0]), ylim=(0, box[1]), aspect="equal", xlabel="x (box units)",
             ylabel="y (box units)", title=f"path over {step[-1]} wall contacts")
    left.legend(loc="upper right", fontsize=8)
    half = 0.5 * box[0]
    distance = np.abs(np.abs(position[:, 0] - half) + np.abs(position[:, 1] - half)
                      - (half - radius)) / np.sqrt(2.0)
    right.semilogy(time, np.maximum(distance, 1e-17), ".", ms=2, color="C0")
    energy_error = np.abs(energy / energy[0] - 1.0).max()
    right.set(xlabel="time  [L/v: box side over the disk's speed]",
              ylabel="distance from the rectangle (box units)",
              title=f"largest distance {distance.max():.1e}; "
                    + ("energy exact" if energy_error == 0 else f"|E/E₀ − 1| ≤ {energy_error:.0e}"))
    np.savetxt(out_dir / f"{NAME}.csv",
               np.column_stack([step, time, position, distance, energy]), delimiter=",",
               header="step,time,x,y,distance_from_rectangle,kinetic_energy", comments="")
    return save(fig, out_dir, NAME)
