"""Figure 2: two disks in a box.

The divergence of two runs whose starts differ by
1e-12 in one coordinate: the distance between the two copies against disk–disk collisions.
Each disk–disk collision multiplies a small error by about 2ℓ/R (ℓ the distance flown since
the previous disk–disk collision, R the radius: the defocusing of a convex scatterer), so
order is lost after about ln(R/1e-12) / ln(2ℓ/R) collisions. The figure gives that
prediction from the mean free path ℓ that the unperturbed run measures (its time over its
disk–disk collisions, times the disks' speed), independent of the divergence, beside the
count it measures and the growth per collision fitted where the distance grows as a straight
line on the log axis (from 1e3 to 1e-2 R times the start's 1e-12; the line drawn over those
points only). The growth measured is smaller than 2ℓ/R: an error that lies along the path
is not magnified, and a grazing collision magnifies less than a head-on one is taken to.
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
        speed = float(np.hypot(*np.moveaxis(a["velocity"].values, -1, 0)).mean())
        free_path = speed * float(a["time"].values[-1]) / float(a["collisions"].values[-1])
    defocusing = 2.0 * free_path / radius
    predicted = np.log(radius / PERTURBATION) / np.log(defocusing)
    lost = np.flatnonzero(distance > radius)
    k_lost = int(lost[0]) if lost.size else k - 1
    c_lost = int(collisions[k_lost])
    growing = (distance > 1e3 * PERTURBATION) & (distance < 1e-2 * radius)
    slope, intercept = np.polyfit(collisions[growing], np.log(distance[growing]), 1) \
        if growing.sum() > 3 else (np.nan, np.nan)
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
    fitted = collisions[growing]
    right.semilogy(fitted, np.exp(intercept + slope * fitted), "--", color="C1", lw=1.5,
                   label=f"fit: ×{np.exp(slope):.3g} per collision")
    right.axhline(radius, color="k", ls=":", lw=1, label=f"disk radius {radius:g}")
    right.axvline(c_lost, color="C3", ls="--", lw=1, label=f"order lost after {c_lost}")
    right.set(xlabel="disk–disk collisions", ylabel="distance between the runs (box units)",
              xlim=(0, min(float(collisions[-1]), 4.0 * c_lost)))  # saturated beyond
    right.set_title(f"starts 1e-12 apart; 2ℓ/R = {defocusing:.3g} (ℓ = {free_path:.3g} "
                    f"measured)\npredicts order lost after {predicted:.1f}; measured {c_lost}",
                    fontsize=9)
    right.legend(fontsize=8)
    np.savetxt(out_dir / f"{NAME}.csv", np.column_stack([collisions, distance]),
               delimiter=",", header="collisions,distance", comments="")
    (out_dir / f"{NAME}.txt").write_text("".join(f"{key}={value}\n" for key, value in (
        ("order_lost_after_collisions", c_lost), ("growth_per_collision", np.exp(slope)),
        ("free_path", free_path), ("defocusing_2l_over_r", defocusing),
        ("predicted_collisions", predicted))))
    return save(fig, out_dir, NAME)
