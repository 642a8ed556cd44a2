"""The melting study's figures: the equation of state per N and box beside the published
curves, a snapshot at coexistence coloured by ψ₆ beside g₆(r), and the runs of N = 128²
started both ways. Each is written in full (PNG and PDF) under the study's output folder
and as a web version into the results folder."""

from pathlib import Path

import numpy as np
from matplotlib import pyplot as plt
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from PIL import Image

from sim.analysis.datasets import global_bond_order, open_run
from sim.analysis.equation_of_state import block_pressures
from sim.analysis.packing import orientational_correlation
from sim.checks.melting import LARGE_N, reference
from sim.figures.style import draw_disks
from sim.figures.web import web_png
from sim.storage.errors import RunFileError

#: the packing fraction of the snapshot drawn, inside the coexistence of N = 128²
COEXISTENCE = 0.708

#: the panels of the equation of state: (N, box) and the groups drawn in each
PANELS = ((72, "1:1"), (72, "9:8√3/2"), (224, "1:1"), (870, "1:1"), (870, "29:30√3/2"),
          (16384, "1:1"))


def publish(fig, name, out, results):
    """``name``.png and .pdf into ``out``/figures, and the web version (``web_png``: at most
    ``sim.figures.web.LARGEST_IMAGE`` bytes) into ``results``."""
    folder = Path(out) / "figures"
    folder.mkdir(parents=True, exist_ok=True)
    fig.savefig(folder / f"{name}.png", dpi=150)
    fig.savefig(folder / f"{name}.pdf")
    plt.close(fig)
    with Image.open(folder / f"{name}.png") as image:
        (results / f"{name}.png").write_bytes(web_png(image))


def draw_equation_of_state(records, out, results):
    """βP d² against φ per N and box: the runs with their blocking errors beside the published
    curve of the same N and box (and, at N = 128², the large-N curves)."""
    fig, axes = plt.subplots(2, 3, figsize=(12.0, 7.0), constrained_layout=True)
    for ax, (n, box) in zip(axes.ravel(), PANELS, strict=True):
        phi, pressure, error, _ = reference(n, box)
        ax.fill_between(phi, pressure - 3 * error, pressure + 3 * error, color="0.6", alpha=0.4)
        ax.plot(phi, pressure, color="0.3", lw=1.0, label="Li et al. 2022, same N and box")
        if n == 16384:
            for k, (label, source, large, method) in enumerate(LARGE_N):
                lphi, lp, _, _ = reference(large, "1:1", source, method)
                ax.plot(lphi, lp, color=f"C{k + 2}", lw=0.8, ls="--", label=label)
        mine = [r for r in records if r["n"] == n and r["box"] == box]
        for start, marker in (("compressed", "o"), ("melted", "s")):
            for done in (True, False):
                rows = sorted((r for r in mine if r["start"] == start
                               and (r["status"] == "done") == done), key=lambda r: r["phi"])
                if rows:
                    ax.errorbar([r["phi"] for r in rows], [r["bPd2"] for r in rows],
                                [r["err"] for r in rows], fmt=marker, ms=3.5, capsize=2,
                                mfc="none" if start == "melted" else None,
                                color="C0" if start == "compressed" else "C1",
                                alpha=1.0 if done else 0.35,
                                label=f"sim, from a {start} start"
                                      + ("" if done else ", not done yet"))
        if mine:
            lo, hi = min(r["phi"] for r in mine), max(r["phi"] for r in mine)
            inside = (phi >= lo - 0.003) & (phi <= hi + 0.003)
            ax.set_xlim(lo - 0.003, hi + 0.003)
            span = [*pressure[inside], *(r["bPd2"] for r in mine)]
            pad = 0.05 * (max(span) - min(span)) + 0.005
            ax.set_ylim(min(span) - pad, max(span) + pad)
        ax.set_title(f"N = {n}, box {box}", fontsize=10)
        ax.set_xlabel("packing fraction φ")
        ax.set_ylabel("βP d²")
        ax.legend(fontsize=7)
    seeds = ", ".join(str(seed) for seed in sorted({r["seed"] for r in records}))
    fig.suptitle(f"Hard disks through melting: sim (seed {seeds}, ±1 blocking standard error) "
                 "against the published pressures (band: ±3 standard errors)", fontsize=10)
    publish(fig, "melting_eos", out, results)


def draw_starts(todo, out, results):
    """The runs of N = 128² started both ways at the same φ, as far as they have come: βP d²
    of every block and |Ψ₆| of every snapshot against collisions per disk, the published
    βP d² beside; so that the two starts are seen to meet."""
    large = [p for p in todo if p.group.n == 16384]
    twice = sorted({p.phi for p in large if p.group.start == "melted"}
                   & {p.phi for p in large if p.group.start == "compressed"})
    if not twice:
        return
    fig, axes = plt.subplots(2, len(twice), figsize=(5.5 * len(twice), 6.0), squeeze=False,
                             constrained_layout=True, sharex="col")
    for column, phi in enumerate(twice):
        top, bottom = axes[0, column], axes[1, column]
        published = reference(16384, "1:1")
        k = int(np.argmin(np.abs(published[0] - phi)))
        top.axhspan(published[1][k] - 3 * published[2][k], published[1][k] + 3 * published[2][k],
                    color="0.6", alpha=0.4, label="Li et al. 2022 (±3 standard errors)")
        for point in (p for p in large if p.phi == phi):
            try:
                run_data = open_run(point.folder / "run.h5")
            except RunFileError:  # running now, or not begun: said on the panel
                top.text(0.02, 0.04 if point.group.start == "compressed" else 0.12,
                         f"{point.group.start} start: not drawn (running, or not begun)",
                         transform=top.transAxes, fontsize=7)
                continue
            with run_data:
                pressure, ends = block_pressures(run_data)
                order = global_bond_order(run_data)
                per_disk = run_data["collisions"].values / point.group.n
            colour = "C0" if point.group.start == "compressed" else "C1"
            top.plot(ends / point.group.n, pressure, lw=0.6, color=colour,
                     label=f"{point.group.start} start, each block")
            bottom.plot(per_disk, order.values, lw=0.8, color=colour,
                        label=f"{point.group.start} start")
        top.set(ylabel="βP d²", title=f"N = 128², φ = {phi:.3f}")
        bottom.set(xlabel="collisions per disk", ylabel="|Ψ₆|")
        top.legend(fontsize=7)
        bottom.legend(fontsize=7)
    publish(fig, "melting_starts", out, results)


def draw_bond_order(points_done, out, results):
    """The last snapshot of the N = 128² run nearest φ = 0.708 with every disk coloured by
    the phase of its ψ₆, and g₆(r) of the last snapshot of every N = 128² run."""
    large = [p for p in points_done if p.group.n == 16384 and (p.folder / "run.h5").exists()]
    if not large:
        return
    fig, (left, right) = plt.subplots(1, 2, figsize=(12.0, 5.6), constrained_layout=True,
                                      gridspec_kw={"width_ratios": (1.1, 1.0)})
    shown = min(large, key=lambda p: (abs(p.phi - COEXISTENCE), p.group.start != "compressed"))
    for point in sorted(large, key=lambda p: (p.group.start, p.phi)):
        try:
            run_data = open_run(point.folder / "run.h5")
        except RunFileError:  # --report while the study runs it on
            continue
        with run_data:
            last = run_data.isel(time=-1)
            position, psi = last["position"].values, last["bond_order"].values
            radius = run_data["radius"].values
            box = tuple(run_data.attrs["box"])
            seed = run_data.attrs["seed"]
        psi = psi[:, 0] + 1j * psi[:, 1]
        diameter = 2.0 * radius[0]
        r, g6 = orientational_correlation(position, psi, box, (True, True), 120, 12 * diameter)
        right.loglog(r / diameter, np.abs(g6), lw=1.0, ls="-" if point.group.start ==
                     "compressed" else ":", label=f"φ = {point.phi:.3f}, {point.group.start}")
        if point == shown:
            angle = Normalize(-np.pi / 6, np.pi / 6)
            hue = plt.get_cmap("hsv")(angle(np.angle(psi) / 6.0))
            hue[:, :3] *= np.clip(np.abs(psi), 0.0, 1.0)[:, None]  # a liquid's disks dark
            draw_disks(left, position, radius, colors=hue)
            fig.colorbar(ScalarMappable(angle, "hsv"), ax=left, shrink=0.7,
                         label="orientation of the local hexagon, arg(ψ₆)/6 (rad); "
                               "brightness |ψ₆|")
            left.set(xlim=(0, box[0]), ylim=(0, box[1]), aspect="equal", xticks=[], yticks=[])
            left.set_title(f"N = 128², φ = {point.phi:.3f}, {point.group.start} start, last "
                           f"snapshot (seed {seed})", fontsize=10)
    x = np.array([1.0, 12.0])
    right.loglog(x, x ** -0.25, color="k", lw=0.8, ls="--",
                 label="r^(−1/4), the slowest decay of a hexatic (KTHNY)")
    right.set(xlabel="r / d", ylabel="|g₆(r)|", ylim=(1e-2, 1.2))
    right.set_title("Bond-orientational correlation, last snapshot of each N = 128² run",
                    fontsize=10)
    right.legend(fontsize=7)
    publish(fig, "melting_psi6", out, results)
