"""Figure 2: two disks in a box.

The divergence of two runs whose starts differ by
1e-12 in one coordinate: the distance between the two copies against disk–disk collisions.
Each disk–disk collision multiplies a small error by about 2ℓ/R (ℓ the distance flown since
the previous disk–disk collision, R the radius: the defocusing of a convex scatterer), so
order is lost after about ln(R/1e-12) / ln(2ℓ/R) collisions; the figure fits the growth
rate per collision and compares that estimate with the count it measures.
"""

import numpy as np

from sim.analysis.datasets import open_run
from sim.figures.style import figure, save

NAME = "fig02_two_disks"
PERTURBATION = 1e-12


def runs(quick):
    common = ["scenario=two_disks", f"stop.collisions={40 if quick else 150}",
              f"output.every_time={0.1 if quick else 0.05}"]
    moved = f"two_disks.positions=[[0.25,0.5],[0.75,{0.52 + PERTURBATION!r}]]"
    return {"start": common, "perturbed": [*common, moved]}


def draw(runs, sweeps, out_dir):
    with open_run(runs["start"]) as a, open_run(runs["perturbed"]) as b:
        k = min(a.sizes["time"], b.sizes["time"])
        distance = np.abs(a["position"].values[:k] - b["position"].values[:k]).max(axis=(1, 2))
        collisions = a["collisions"].values[:k]
        radius = float(a["radius"][0])
    lost = np.flatnonzero(distance > radius)
    k_lost = int(lost[0]) if lost.size else k - 1
    c_lost = int(collisions[k_lost])
    growing = (distance > 1e3 * PERTURBATION) & (distance < 1e-2 * radius)
    slope = np.polyfit(collisions[growing], np.log(distance[growing]), 1)[0] \
        if growing.sum() > 3 else np.nan
    estimate = np.log(radius / PERTURBATION) / slope
    fig, (left, right) = figure()
    with open_run(runs["start"]) as ds:
        shown = slice(0, k_lost + 1)
        position = ds["position"].values[shown]
    with open_run(runs["perturbed"]) as ds:
        perturbed = ds["position"].values[shown]
    for d in (0, 1):
        left.plot(position[:, d, 0], position[:, d, 1], "-", lw=0.8, color=f"C{d}",
                  label=f"disk {d + 1}")
        left.plot(perturbed[:, d, 0], perturbed[:, d, 1], ":", lw=0.8, color="k")
    left.plot([], [], ":", color="k", label="perturbed run")
    left.set(xlim=(0, 1), ylim=(0, 1), aspect="equal", xlabel="x (box units)",
             ylabel="y (box units)", title=f"paths until order is lost ({c_lost} collisions)")
    left.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3, fontsize=8)
    right.semilogy(collisions, np.maximum(distance, 1e-17), "-", color="C0",
                   label="max |Δx| between the two runs")
    right.axhline(radius, color="k", ls=":", lw=1, label=f"disk radius {radius:g}")
    right.axvline(c_lost, color="C3", ls="--", lw=1, label=f"order lost after {c_lost}")
    right.set(xlabel="disk–disk collisions", ylabel="distance between the runs (box units)",
              title=f"starts 1e-12 apart: ×{np.exp(slope):.2g} per collision, "
                    f"estimate {estimate:.0f}")
    right.legend(fontsize=8)
    np.savetxt(out_dir / f"{NAME}.csv", np.column_stack([collisions, distance]),
               delimiter=",", header="collisions,distance", comments="")
    (out_dir / f"{NAME}.txt").write_text(
        f"order_lost_after_collisions={c_lost}\ngrowth_per_collision={np.exp(slope)}\n"
        f"estimate_collisions={estimate}\n")
    return save(fig, out_dir, NAME)
