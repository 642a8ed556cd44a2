"""The melting study's figures: the equation of state per N and box beside the published
curves, a snapshot at coexistence coloured by ψ₆ beside g₆(r), and the runs of N = 128²
started both ways; and the traces of the runs of N = 128² that the records keep for them.
Each is written in full (PNG and PDF) under the study's output folder and as a web version
into the results folder."""

import shutil
from pathlib import Path

import numpy as np
from matplotlib import pyplot as plt
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from PIL import Image
from tables import estimates

from sim.analysis.datasets import global_bond_order, open_run
from sim.analysis.equation_of_state import block_pressures
from sim.analysis.packing import orientational_correlation
from sim.checks.melting import LARGE_N, reference
from sim.figures.style import draw_disks
from sim.figures.web import web_png
from sim.storage.errors import RunFileError

#: the packing fraction of the snapshot drawn, inside the coexistence of N = 128²
COEXISTENCE = 0.708
#: the N whose runs keep their traces (:func:`trace`) for the figures
TRACED = 16384
#: g₆(r) in this many bins up to this many diameters
G6_BINS, G6_REACH = 120, 12.0

#: the colours of the runs of N = 128² from each start, one per seed
COLOURS = {"compressed": ("C0", "C2", "C4", "C6", "C8"), "melted": ("C1", "C3", "C5", "C7", "C9")}
#: the states of a measured point (study.status) and what the legend says of them
STATES = {"done": "", "running": ", still running", "longest": ", at its longest run, not done"}
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
    """βP d² against φ per N and box: the runs with their blocking errors, the replicas of a
    state point and start as their weighted mean (:func:`tables.estimates`), beside the
    published curve of the same N and box (and, at N = 128², the large-N curves)."""
    fig, axes = plt.subplots(2, 3, figsize=(12.0, 7.0), constrained_layout=True)
    for ax, (n, box) in zip(axes.ravel(), PANELS, strict=True):
        phi, pressure, error, _ = reference(n, box)
        ax.fill_between(phi, pressure - 3 * error, pressure + 3 * error, color="0.6", alpha=0.4)
        ax.plot(phi, pressure, color="0.3", lw=1.0, label="Li et al. 2022, same N and box")
        if n == 16384:
            for k, (label, source, large, method) in enumerate(LARGE_N):
                lphi, lp, _, _ = reference(large, "1:1", source, method)
                ax.plot(lphi, lp, color=f"C{k + 2}", lw=0.8, ls="--", label=label)
        mine = [e for e in estimates(records) if e["n"] == n and e["box"] == box]
        for start, marker, colour in (("compressed", "o", "C0"), ("melted", "s", "C1"),
                                      ("lattice", "^", "C4")):
            for state, caption in STATES.items():
                rows = sorted((r for r in mine if r["start"] == start
                               and r["status"] == state), key=lambda r: r["phi"])
                if rows:
                    ax.errorbar([r["phi"] for r in rows], [r["bPd2"] for r in rows],
                                [r["err"] for r in rows], fmt=marker, ms=3.5, capsize=2,
                                mfc="none" if start == "melted" else None, color=colour,
                                alpha=1.0 if state == "done" else 0.35,
                                label=f"sim, from a {start} start{caption}")
        if mine:
            lo, hi = min(r["phi"] for r in mine), max(r["phi"] for r in mine)
            inside = (phi >= lo - 0.003) & (phi <= hi + 0.003)
            ax.set_xlim(lo - 0.003, hi + 0.003)
            span = [*pressure[inside], *(r["bPd2"] - r["err"] for r in mine),
                    *(r["bPd2"] + r["err"] for r in mine)]
            low, high = np.nanmin(span), np.nanmax(span)  # an error not yet known: NaN
            pad = 0.05 * (high - low) + 0.005
            ax.set_ylim(low - pad, high + pad)
        ax.set_title(f"N = {n}, box {box}", fontsize=10)
        ax.set_xlabel("packing fraction φ")
        ax.set_ylabel("βP d²")
        ax.legend(fontsize=7)
    seeds = ", ".join(str(seed) for seed in sorted({r["seed"] for r in records}))
    fig.suptitle(f"Hard disks through melting: sim (seeds {seeds}; replicas as their weighted "
                 "mean; ±1 blocking standard error)\nagainst the published pressures (band: ±3 "
                 "standard errors)", fontsize=10)
    publish(fig, "melting_eos", out, results)


def trace(dataset, n):
    """What the figures draw of a run of N = ``n`` = 128² (:data:`TRACED`), kept in its
    record so that a clone with the committed results draws them without the run file:
    βP d² of every block against collisions per disk at its end, |Ψ₆| of every snapshot,
    |g₆(r)| of the last snapshot against r/d in the bins that hold pairs (6 significant
    digits). None for other N."""
    if n != TRACED:
        return None
    pressure, ends, _ = block_pressures(dataset)
    last = dataset.isel(time=-1)
    psi = last["bond_order"].values
    diameter = 2.0 * float(dataset["radius"].values[0])
    r, g6 = orientational_correlation(last["position"].values, psi[:, 0] + 1j * psi[:, 1],
                                      tuple(dataset.attrs["box"]), (True, True), G6_BINS,
                                      G6_REACH * diameter)

    paired = np.isfinite(g6)  # bins below contact have no pairs

    def rounded(values):
        return [float(f"{v:.6g}") for v in np.asarray(values, np.float64)]

    return {"block_end": rounded(ends / n), "block_bPd2": rounded(pressure),
            "snapshot": rounded(dataset["collisions"].values / n),
            "psi6": rounded(global_bond_order(dataset).values),
            "r": rounded(r[paired] / diameter), "g6": rounded(np.abs(g6[paired]))}


def draw_starts(records, out, results):
    """The runs of N = 128² started both ways at the same φ, as far as they have come (their
    traces, :func:`trace`): βP d² of every block and |Ψ₆| of every snapshot against
    collisions per disk, the published βP d² beside; so that the two starts, and the
    replicas of one, are seen to meet."""
    large = [r for r in records if r["n"] == TRACED and "trace" in r]
    twice = sorted({r["phi"] for r in large if r["start"] == "melted"}
                   & {r["phi"] for r in large if r["start"] == "compressed"})
    if not twice:
        return
    fig, axes = plt.subplots(2, len(twice), figsize=(5.5 * len(twice), 6.0), squeeze=False,
                             constrained_layout=True, sharex="col")
    published = reference(TRACED, "1:1")
    for column, phi in enumerate(twice):
        top, bottom = axes[0, column], axes[1, column]
        k = int(np.argmin(np.abs(published[0] - phi)))
        top.axhspan(published[1][k] - 3 * published[2][k], published[1][k] + 3 * published[2][k],
                    color="0.6", alpha=0.4, label="Li et al. 2022 (±3 standard errors)")
        for r in sorted((r for r in large if r["phi"] == phi),
                        key=lambda r: (r["start"], r["seed"])):
            colour = COLOURS[r["start"]][r["seed"] % len(COLOURS[r["start"]])]
            top.plot(r["trace"]["block_end"], r["trace"]["block_bPd2"], lw=0.6, color=colour,
                     label=f"{r['start']} start, seed {r['seed']}, each block ({r['status']})")
            bottom.plot(r["trace"]["snapshot"], r["trace"]["psi6"], lw=0.8, color=colour,
                        label=f"{r['start']} start, seed {r['seed']}")
        top.set(ylabel="βP d²", title=f"N = 128², φ = {phi:.3f}")
        bottom.set(xlabel="collisions per disk", ylabel="|Ψ₆|")
        top.legend(fontsize=7)
        bottom.legend(fontsize=7)
    fig.suptitle("The two starts of N = 128², and the replicas of one (other seeds)",
                 fontsize=10)
    publish(fig, "melting_starts", out, results)


#: the name of the coexistence snapshot's figure (:func:`draw_bond_order`)
BOND_ORDER = "melting_psi6"


def draw_bond_order(records, todo, out, results, kept_in=None):
    """The last snapshot of the N = 128² run nearest φ = 0.708 whose run file is here at the
    length of its record, every disk coloured by the phase of its ψ₆, and |g₆(r)| of the
    last snapshot of every N = 128² run (their traces). With no run file of N = 128² here
    (a clone, which goes on from the ledger), no N = 128² run has been made since the
    ledger's figure in the folder ``kept_in`` was drawn: that figure is kept, not redrawn
    without its snapshot."""
    large = [r for r in records if r["n"] == TRACED and "trace" in r]
    here = [p for p in todo if p.group.n == TRACED and (p.folder / "run.h5").exists()]
    if not large:
        return
    kept = None if kept_in is None else kept_in / f"{BOND_ORDER}.png"
    if not here and kept is not None and kept.exists():
        if kept.resolve() != (results / kept.name).resolve():
            shutil.copyfile(kept, results / kept.name)
        return
    fig, (left, right) = plt.subplots(1, 2, figsize=(12.0, 5.6), constrained_layout=True,
                                      gridspec_kw={"width_ratios": (1.1, 1.0)})
    for r in sorted(large, key=lambda r: (r["start"], r["phi"])):
        right.loglog(r["trace"]["r"], r["trace"]["g6"], lw=1.0,
                     ls="-" if r["start"] == "compressed" else ":",
                     label=f"φ = {r['phi']:.3f}, {r['start']}"
                           + (f", seed {r['seed']}" if r["seed"] else ""))
    x = np.array([1.0, G6_REACH])
    right.loglog(x, x ** -0.25, color="k", lw=0.8, ls="--",
                 label="r^(−1/4), the slowest decay of a hexatic (KTHNY)")
    right.set(xlabel="r / d", ylabel="|g₆(r)|", ylim=(1e-2, 1.2))
    right.set_title("Bond-orientational correlation, last snapshot of each N = 128² run",
                    fontsize=10)
    right.legend(fontsize=7)
    for point in sorted(here, key=lambda p: (abs(p.phi - COEXISTENCE),
                                              p.group.start != "compressed")):
        try:
            run_data = open_run(point.folder / "run.h5")
        except RunFileError:  # --report while the study runs it on: the next one
            continue
        recorded = next(r["collisions_per_disk"] for r in records if (r["group"], r["phi"],
                        r["seed"]) == (point.group.name, point.phi, point.seed))
        with run_data:
            last = run_data.isel(time=-1)
            per_disk = float(last["collisions"].values) / point.group.n
            position, psi = last["position"].values, last["bond_order"].values
            radius = run_data["radius"].values
            box = tuple(run_data.attrs["box"])
            seed = run_data.attrs["seed"]
        if per_disk != recorded:  # a run made again, cut short before its record's length
            continue
        psi = psi[:, 0] + 1j * psi[:, 1]
        angle = Normalize(-np.pi / 6, np.pi / 6)
        hue = plt.get_cmap("hsv")(angle(np.angle(psi) / 6.0))
        hue[:, :3] *= np.clip(np.abs(psi), 0.0, 1.0)[:, None]  # a liquid's disks dark
        draw_disks(left, position, radius, colors=hue)
        fig.colorbar(ScalarMappable(angle, "hsv"), ax=left, shrink=0.7,
                     label="orientation of the local hexagon, arg(ψ₆)/6 (rad); "
                           "brightness |ψ₆|")
        left.set(xlim=(0, box[0]), ylim=(0, box[1]), aspect="equal", xticks=[], yticks=[])
        left.set_title(f"N = 128², φ = {point.phi:.3f}, {point.group.start} start,\n"
                       f"after {per_disk:.3g} collisions per disk (seed {seed})", fontsize=10)
        break
    else:  # a clone with the committed results alone: the snapshot needs a run file
        left.text(0.5, 0.5, "no run file of N = 128² here:\nthe snapshot is drawn where the "
                  "study has run", ha="center", va="center", transform=left.transAxes)
        left.set_axis_off()
    publish(fig, BOND_ORDER, out, results)
