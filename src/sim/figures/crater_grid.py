"""Figure 8: the crater measure of the seed study (its Figures 1 and 2). A projectile of
radius 0.05 falls at v = (0, −10) from (0.5, 0.75) into 4000 bed disks of radius 0.0045,
ξ = 0.5, until 10 % of the kinetic energy is left. A grid of spacing Δx covers the bed; a cell
is occupied when a bed disk overlaps it (exact disk–square test, sim.analysis.crater); the crater
area is the number of empty cells times Δx².

Δx is the finest spacing at which the untouched bed shows no empty cell (the study chose it
by eye). Left: occupied cells yellow, empty purple (the study's colours); right: the disks,
with the crater's cells shaded. The numbers file gives the area over a ladder of Δx, at the
start (gaps between resting disks) and at the end. The crater area counts the cells the
projectile itself covers, as the study's did (its cells empty of bed disks); the title and
the numbers give them, and the area less them (the projectile counted as an occupant).
"""

import numpy as np

from sim.analysis.crater import CraterGeometry, crater_area, crater_overrides, preparation_of
from sim.analysis.datasets import open_run
from sim.figures.style import draw_disks, figure, save

NAME = "fig08_crater_grid"


def runs(quick):
    return {"crater": crater_overrides(quick)}


def draw(runs, sweeps, out_dir):
    with open_run(runs["crater"]) as ds:
        geometry = CraterGeometry.of_run(ds)
        start = ds["position"].isel(time=0).values
        end = ds["position"].isel(time=-1).values
        radius = ds["radius"].values
        t_end = float(ds["time"].values[-1])
        energy = ds["kinetic_energy"].values
        box = ds.attrs["box"]
        preparation = preparation_of(ds)
    area, occupied = crater_area(end[geometry.bed], geometry.radius, geometry.dx,
                                 geometry.width, geometry.height)
    bare = crater_area(end, radius, geometry.dx, geometry.width, geometry.height)[0]
    grid = occupied.T.astype(float)
    extent = (0, occupied.shape[0] * geometry.dx, 0, occupied.shape[1] * geometry.dx)
    fig, (left, right) = figure(width=11, height=4.4)
    fig.suptitle(preparation, fontsize=9)
    left.imshow(grid, origin="lower", extent=extent, cmap="viridis", vmin=0, vmax=1,
                interpolation="nearest")
    left.grid(False)
    right.grid(False)
    top = min(float(box[1]), 1.05 * max(geometry.height, float(np.max(end[:, 1] + radius))))
    left.set(xlabel="x (box units)", ylabel="y (box units)", aspect="equal",
             xlim=(0, geometry.width), ylim=(0, top),
             title=f"grid Δx = {geometry.dx:.3g}: occupied (yellow), empty (purple)")
    colors = np.where(geometry.bed, "0.35", "tab:red")
    draw_disks(right, end, radius, colors)
    right.imshow(np.ma.masked_where(grid > 0, 1 - grid), origin="lower", extent=extent,
                 cmap="Purples", vmin=0, vmax=1.5, alpha=0.6, interpolation="nearest")
    right.set(xlim=(0, geometry.width), ylim=(0, top), aspect="equal",
              xlabel="x (box units)", ylabel="y (box units)")
    right.set_title(f"t = {t_end:.3g}, E/E₀ = {energy[-1] / energy[0]:.2f}: crater area "
                    f"{area:.4f}\n(the projectile's cells {area - bare:.4f} of it, "
                    f"{(area - bare) / area:.0%})", fontsize=9)
    rows = []
    for k in range(int(geometry.height / (2 * geometry.radius.max())), 4, -1):
        dx = geometry.height / k
        rows.append((dx, geometry.area(start, dx), geometry.area(end, dx),
                     crater_area(end, radius, dx, geometry.width, geometry.height)[0]))
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",", fmt="%.6g",
               header=f"dx,area_at_start,area_at_end,area_at_end_less_the_projectile  "
                      f"(calibrated dx = {geometry.dx:.6g}, area {area:.6g}, less the "
                      f"projectile {bare:.6g})", comments="")
    return save(fig, out_dir, NAME)
