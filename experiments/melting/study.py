"""The melting of hard disks: the equation of state βP d² through liquid–hexatic coexistence
at the sizes and in the boxes of the published references, each point run until its error
reaches its group's target.

Every state point of :data:`PLAN` is one run of the ``melting`` scene in a folder of its own
under ``--out`` (``runs/<group>-<φ>/run.h5``), which also keeps the point's analysis
(``point.json``) and the processor seconds it took (``cpu_seconds``). A point is run in
rounds: the first runs ``first`` collisions per disk; after each,
:func:`sim.analysis.equation_of_state.run_pressure` drops the equilibration blocks by the
MSER rule and finds the blocking error of the rest, and the point is done when that error is
at most the group's ``target``, the blocking has converged, the means of the production's two
halves agree within :data:`DRIFT` standard errors and :data:`PRODUCTION_BLOCKS` blocks are
kept. Otherwise it is resumed to the length its error asks for (:func:`next_length`), at most
``longest`` collisions per disk; a point that reaches it stays as it is, its error in the
tables. The runs go to a pool of ``--jobs`` worker processes, the longest first, each point
given its next run as soon as one ends; or with ``--cluster slurm``, in rounds of jobs, to
SLURM through submitit.

Interrupted (Ctrl-C, a killed job, the end of a session), the study starts again where it
was: a run resumes from its last checkpoint (written every 30 s of wall time and at every
stop), a finished point is not run again, and a second ``make melting`` with every point done
only reads the analyses and draws.

Writes into ``--results`` (default outputs/melting/results; ``make melting`` copies them into
docs/results/): ``melting.csv`` (one row per run: n, aspect, phi, start,
collisions_per_disk, bPd2, err, psi6), ``melting_reference.csv`` (the published value of
each row's N, box and φ with its source), ``melting.md`` (the runs against the published
values, the loops' extrema, the processor hours), ``melting.json`` (per point the whole
analysis and processor seconds; per group the published loop's extrema and ours),
``melting_eos.png``, ``melting_psi6.png`` and ``melting_starts.png`` (web versions; the full
figures, PNG and PDF, in ``--out``/figures).

    python experiments/melting/study.py [--groups 72-square …] [--jobs 2] [--quick] [--report]
"""

import argparse
import csv
import json
import math
import os
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from matplotlib import pyplot as plt
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from PIL import Image

from sim.analysis.datasets import global_bond_order, open_run
from sim.analysis.equation_of_state import block_pressures, run_pressure
from sim.analysis.packing import orientational_correlation
from sim.checks.melting import LARGE_N, loop_extrema, reference
from sim.figures.style import draw_disks
from sim.figures.web import web_png
from sim.pipeline.resume import resume, stored_config
from sim.pipeline.run_cache import compose_config
from sim.pipeline.runner import run
from sim.storage.errors import RunFileError

#: the drift of the production's halves, in standard errors, below which a run is stationary
DRIFT = 3.0
#: a round resumes a point to this many times the length its error asks for
MARGIN = 1.3
#: and to at least 1.5, at most 4 times its length so far
GROWTH = (1.5, 4.0)
#: the fewest production blocks of a point done: blocking has three levels of 8 and more
PRODUCTION_BLOCKS = 64
#: the version of :func:`analyse`'s rules a record was made with; a record of another is
#: made anew from its run file when the study starts
ANALYSIS = 2


@dataclass(frozen=True)
class Group:
    """State points of one N and box: ``phis`` (published packing fractions), started as
    ``start`` (``compressed``: a random gas compressed by growing disks; ``melted``: a
    hexagonal lattice melted by a short elastic run); a snapshot, one block of the
    pressure, every ``block`` collisions per disk; ``first`` collisions per disk in the first
    round, at most ``longest``; done at an error of βP d² of at most ``target``."""

    name: str
    n: int
    box: str
    phis: tuple
    start: str
    block: int
    first: int
    longest: int
    target: float


#: the published sizes and boxes (Li et al. 2022), with the published points dense where the
#: curves bend; N = 128² at the points of its MPMC data, the loop's maximum (0.704) and its
#: lowest published point (0.716, the last: the minimum lies beyond) from both starts
PLAN = (
    Group("72-square", 72, "1:1", (0.650, 0.660, 0.670, 0.680, 0.686, 0.690, 0.694, 0.698,
                                   0.702, 0.706, 0.710, 0.720),
          "compressed", 1000, 1_000_000, 30_000_000, 0.002),
    Group("72-lattice", 72, "9:8√3/2", (0.650, 0.670, 0.680, 0.684, 0.686, 0.688, 0.690,
                                        0.692, 0.694, 0.696, 0.698, 0.700, 0.706, 0.720),
          "compressed", 1000, 1_000_000, 30_000_000, 0.002),
    Group("224-square", 224, "1:1", (0.670, 0.680, 0.686, 0.690, 0.692, 0.694, 0.698, 0.702,
                                     0.704, 0.706, 0.708, 0.712, 0.720),
          "compressed", 500, 300_000, 10_000_000, 0.003),
    Group("870-square", 870, "1:1", (0.670, 0.680, 0.690, 0.694, 0.698, 0.702, 0.706, 0.710,
                                     0.712, 0.714, 0.716, 0.718),
          "compressed", 200, 100_000, 3_000_000, 0.003),
    Group("870-lattice", 870, "29:30√3/2", (0.670, 0.680, 0.690, 0.694, 0.698, 0.702, 0.706,
                                            0.710, 0.712, 0.714, 0.716, 0.718),
          "compressed", 200, 100_000, 3_000_000, 0.003),
    Group("16384-square", 16384, "1:1", (0.698, 0.704, 0.708, 0.712, 0.716),
          "compressed", 1000, 80_000, 400_000, 0.003),
    Group("16384-square-melted", 16384, "1:1", (0.704, 0.716),
          "melted", 1000, 80_000, 400_000, 0.003),
)

#: a smoke run of the study: two points of N = 72, short, into a folder of the caller's
QUICK = (Group("72-square", 72, "1:1", (0.650, 0.700), "compressed", 500, 10_000, 20_000,
               0.05),)


@dataclass(frozen=True)
class Point:
    """One state point: its group and packing fraction, and its run folder."""

    group: Group
    phi: float
    folder: Path

    @property
    def aspect(self):
        return reference(self.group.n, self.group.box)[3]

    def overrides(self, collisions_per_disk):
        g = self.group
        return ["scenario=melting", f"disks.n={g.n}", f"disks.packing_fraction={self.phi}",
                f"box.size=[{self.aspect!r},1.0]", f"disks.placement={g.start}",
                f"stop.collisions={collisions_per_disk * g.n}",
                f"output.every_collisions={g.block * g.n}", "output.progress=false"]


def points(plan, out):
    return [Point(g, phi, Path(out) / "runs" / f"{g.name}-{phi:.3f}") for g in plan
            for phi in g.phis]


def _record(point):
    path = point.folder / "point.json"
    return json.loads(path.read_text()) if path.exists() else None


def _write(path, text):
    """``text`` into ``path`` whole or not at all (a signal between the two leaves the old)."""
    partial = path.with_name(path.name + ".partial")
    partial.write_text(text)
    os.replace(partial, path)


def reached(point, record):
    """Whether the point's run meets its group's target: error, convergence, no drift and
    :data:`PRODUCTION_BLOCKS` blocks kept."""
    return (record["err"] <= point.group.target and record["converged"]
            and abs(record["drift"]) < DRIFT and record["blocks"] >= PRODUCTION_BLOCKS)


def status(point, record):
    """``done``, ``longest`` (run to its group's longest, its target missed), ``failed``
    (the reason in its record) or ``running``."""
    if "failed" in record:
        return "failed"
    if reached(point, record):
        return "done"
    return "longest" if record["collisions_per_disk"] >= point.group.longest else "running"


def next_length(point, record):
    """Collisions per disk the point runs to in its next round, or None when it has none
    (:func:`status` other than ``running``): the length its error asks for, to
    :data:`MARGIN`, from :data:`GROWTH` [0] to [1] times its length so far, at most its
    group's longest, a whole number of blocks."""
    g = point.group
    if status(point, record) != "running":
        return None
    length = record["collisions_per_disk"]
    production = length * record["blocks"] / (record["blocks"] + record["cut"])
    ratio = (record["err"] / g.target) ** 2 if math.isfinite(record["err"]) else math.inf
    asked = length - production + max(production * MARGIN * ratio, PRODUCTION_BLOCKS * g.block)
    asked = min(max(asked, GROWTH[0] * length), GROWTH[1] * length, g.longest)
    return int(math.ceil(asked / g.block) * g.block)


def advance(point, collisions_per_disk):
    """Run or resume ``point`` to ``collisions_per_disk`` and analyse it; its record."""
    started = time.process_time()
    path = point.folder / "run.h5"
    overrides = point.overrides(collisions_per_disk)
    try:
        if path.exists():  # cut short, or to be run longer
            stored, _ = stored_config(path)
            collisions = max(stored.stop.collisions, collisions_per_disk * point.group.n)
            resume(path, [f"stop.collisions={collisions}"])
        else:
            run(compose_config(overrides), point.folder, overrides=overrides)
    finally:  # a round cut short by a signal counts too
        _spend(point, time.process_time() - started)
    record = analyse(point)
    if record is None:  # the run stopped at a signal: so does the study
        raise KeyboardInterrupt
    return record


def _spend(point, seconds):
    """Add ``seconds`` to the processor seconds the point has taken (its ``cpu_seconds``)."""
    point.folder.mkdir(parents=True, exist_ok=True)
    path = point.folder / "cpu_seconds"
    before = (float(path.read_text()) if path.exists()
              else (_record(point) or {}).get("cpu_seconds", 0.0))
    _write(path, repr(before + seconds))


def analyse(point):
    """The point's record from its run file, written to its ``point.json``: βP d² and its
    analysis (:func:`run_pressure`), the mean |Ψ₆| of the production's snapshots, the
    processor seconds of every round so far; or its reason to have none (``failed``). None
    for a run cut short by a signal."""
    g = point.group
    spent = point.folder / "cpu_seconds"
    record = {"group": g.name, "n": g.n, "box": g.box, "aspect": point.aspect,
              "phi": point.phi, "start": g.start, "analysis": ANALYSIS,
              "cpu_seconds": (float(spent.read_text()) if spent.exists()
                              else (_record(point) or {}).get("cpu_seconds", 0.0))}
    with open_run(point.folder / "run.h5") as dataset:
        reason = dataset.attrs["stop_reason"]
        if reason in ("interrupted", "terminated"):
            return None  # cut short by a signal: a later round goes on
        record["seed"] = int(dataset.attrs["seed"])
        snapshots = dataset["collisions"].values
        record["collisions_per_disk"] = int(snapshots[-1]) / g.n
        try:
            if reason != "collisions":
                raise ValueError(f"a run to its collisions, not one stopped by {reason}")
            eos = run_pressure(dataset)
        except ValueError as error:  # reported, never run again
            record["failed"] = str(error)
        else:
            psi = global_bond_order(dataset).values[snapshots > eos.production_start]
            record |= {"bPd2": eos.mean, "err": eos.error, "converged": bool(eos.converged),
                       "cut": eos.cut, "blocks": eos.blocks, "drift": eos.drift,
                       "psi6": float(np.mean(psi))}
    _write(point.folder / "point.json", json.dumps(record, indent=1))
    return record


def _pending(todo):
    """(point, collisions per disk) of every point that has a round to run."""
    rounds = []
    for point in todo:
        record = _record(point)
        if record is not None and record.get("analysis") != ANALYSIS:
            record = analyse(point)  # analysed by an older rule: read its run again
        if record is None:
            if (point.folder / "run.h5").exists():  # cut short before its first analysis
                stored = stored_config(point.folder / "run.h5")[0]
                rounds.append((point, stored.stop.collisions // point.group.n))
            else:
                rounds.append((point, point.group.first))
        elif (length := next_length(point, record)) is not None:
            rounds.append((point, length))
    return rounds


def _cost_of(round_):
    point, collisions_per_disk = round_
    return point.group.n * collisions_per_disk


def _report(point, record):
    print(f"melting: {point.folder.name} at {record['collisions_per_disk']:.3g} collisions "
          f"per disk: " + (f"βP d² = {record['bPd2']:.4f} ± {record['err']:.4f}, "
                           f"{status(point, record)}" if "bPd2" in record
                           else f"failed: {record['failed']}"), flush=True)


def _run_here(todo):
    """Every point's rounds in this process, the longest first."""
    while rounds := _pending(todo):
        point, collisions_per_disk = max(rounds, key=_cost_of)
        _report(point, advance(point, collisions_per_disk))


def _run_in_pool(todo, jobs):
    """Every point's rounds in ``jobs`` worker processes (spawned: the engine compiles in
    each, from numba's cache), the longest first; a point whose round ends is given its
    next at once, and no more runs are handed out than there are workers, so that a study
    stopped starts none."""
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from multiprocessing import get_context

    waiting = sorted(_pending(todo), key=_cost_of)
    with ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn")) as pool:
        running = {}
        while waiting or running:
            while waiting and len(running) < jobs:
                point, collisions_per_disk = waiting.pop()
                running[pool.submit(advance, point, collisions_per_disk)] = point
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                point = running.pop(future)
                record = future.result()  # KeyboardInterrupt: its run stopped at a signal
                _report(point, record)
                if (length := next_length(point, record)) is not None:
                    waiting.append((point, length))
                    waiting.sort(key=_cost_of)


def _run_on_cluster(todo, cluster, out, partition):
    """Rounds of every point's next run, each a job of ``cluster`` through submitit (a
    SLURM array, or local processes with ``local``)."""
    import submitit

    executor = submitit.AutoExecutor(folder=Path(out) / "submitit", cluster=cluster)
    executor.update_parameters(timeout_min=24 * 60, cpus_per_task=1,
                               **({"slurm_partition": partition} if partition else {}))
    while rounds := _pending(todo):
        print(f"melting: a round of {len(rounds)} jobs, "
              f"{sum(map(_cost_of, rounds)):.3g} collisions", flush=True)
        for (point, _), job in zip(rounds, executor.map_array(advance, *zip(*rounds,
                                                                          strict=True)),
                                   strict=True):
            _report(point, job.result())


def simulate(plan, out, jobs, cluster=None, partition=None):
    """Run every point of ``plan`` until it has no more run to make (:func:`next_length`):
    in this process (``jobs`` 1), in a pool of ``jobs`` processes, or through submitit on
    ``cluster``."""
    todo = points(plan, out)
    if cluster is not None:
        _run_on_cluster(todo, cluster, out, partition)
    elif jobs == 1:
        _run_here(todo)
    else:
        _run_in_pool(todo, jobs)


# ---------------------------------------------------------------------------- the results


def write_tables(records, results):
    """melting.csv and melting_reference.csv, one row per run."""
    columns = ("n", "aspect", "phi", "start", "collisions_per_disk", "bPd2", "err", "psi6")
    with open(results / "melting.csv", "w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file)
        writer.writerow(columns)
        for r in records:
            writer.writerow([r["n"], f"{r['aspect']:.12g}", f"{r['phi']:.3f}", r["start"],
                             f"{r['collisions_per_disk']:.0f}", f"{r['bPd2']:.5f}",
                             f"{r['err']:.5f}", f"{r['psi6']:.4f}"])
    with open(results / "melting_reference.csv", "w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file)
        writer.writerow(("n", "box", "aspect", "phi", "bPd2", "err", "source"))
        for r in records:
            phi, pressure, error, _ = reference(r["n"], r["box"])
            k = int(np.argmin(np.abs(phi - r["phi"])))
            writer.writerow([r["n"], r["box"], f"{r['aspect']:.12g}", f"{r['phi']:.3f}",
                             pressure[k], error[k], SOURCE])


SOURCE = ("Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth, J. Chem. Phys. 157, 234111 (2022), "
          "data of jellyfysh/HistoricDisks")


def extrema(records):
    """Per group with a loop in its published curve: the published maximum and minimum from
    all its points and from those at our φ only, and ours (:func:`loop_extrema`), where our
    points show one. The vertex of a parabola depends on the points fitted: ours compare
    with the published ones at our φ."""
    found = {}
    for name in dict.fromkeys(r["group"] for r in records):
        mine = sorted((r for r in records if r["group"] == name), key=lambda r: r["phi"])
        phi, pressure, error, _ = reference(mine[0]["n"], mine[0]["box"])
        published = loop_extrema(phi, pressure, error)
        if published is None:
            continue
        ours = np.array([[r[k] for k in ("phi", "bPd2", "err")] for r in mine]).T
        same = np.isin(np.round(phi, 3), np.round(ours[0], 3))
        found[name] = {"published": published,
                       "published_at_our_phi": loop_extrema(*(x[same] for x in
                                                              (phi, pressure, error))),
                       "sim": loop_extrema(*ours)}
    return found


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
            except RunFileError:  # running now, or not begun
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


def _cost(records):
    """Processor hours per group, and what a point of N = 256² at the points of N = 128²
    would cost at least: four times the disks, the same collisions per disk at the rate of
    N = 128² (its points done)."""
    hours = {}
    for r in records:
        hours[r["group"]] = hours.get(r["group"], 0.0) + r["cpu_seconds"] / 3600.0
    large = [r for r in records if r["n"] == 16384 and r.get("status") == "done"]
    large_point_hours = (4.0 * sum(r["cpu_seconds"] for r in large) / len(large) / 3600.0
                         if large else None)
    return hours, large_point_hours


def _extreme(e):
    return "none in the points" if e is None else \
        f"{e[0]:.4f} ± {e[1]:.4f}, {e[2]:.4f} ± {e[3]:.4f}"


def write_markdown(records, found, results):
    """melting.md: every run against the published value of its N and box, with its state,
    the loops' extrema, the processor hours."""
    lines = [f"A point is done when the blocking error of βP d² over its production is at "
             f"most its group's target, the blocking has converged, the means of the "
             f"production's halves differ by less than {DRIFT:g} standard errors and at "
             f"least {PRODUCTION_BLOCKS} blocks are kept; else it runs on to {MARGIN:g} times "
             f"the length its error asks for ({GROWTH[0]:g} to {GROWTH[1]:g} times its "
             f"length so far). Targets: "
             + "; ".join(f"{g.name} {g.target:g} (a block every {g.block} collisions per "
                         f"disk, at most {g.longest:.3g})" for g in PLAN) + ".", ""]
    measured = [r for r in records if "bPd2" in r]
    for name in dict.fromkeys(r["group"] for r in measured):
        rows = sorted((r for r in measured if r["group"] == name), key=lambda r: r["phi"])
        phi, pressure, error, _ = reference(rows[0]["n"], rows[0]["box"])
        lines += [f"**N = {rows[0]['n']}, box {rows[0]['box']}, {rows[0]['start']} start**",
                  "", "| φ | βP d², sim | published | difference / combined error | "
                  "collisions per disk | equilibration cut | drift | ⟨|Ψ₆|⟩ | state |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in rows:
            k = int(np.argmin(np.abs(phi - r["phi"])))
            z = (r["bPd2"] - pressure[k]) / math.hypot(r["err"], error[k])
            lines.append(f"| {r['phi']:.3f} | {r['bPd2']:.4f} ± {r['err']:.4f} | "
                         f"{pressure[k]:.4f} ± {error[k]:.4f} | {z:+.1f} | "
                         f"{r['collisions_per_disk']:.3g} | {r['cut']} of "
                         f"{r['cut'] + r['blocks']} blocks | {r['drift']:+.1f} | "
                         f"{r['psi6']:.3f} | {r['status']} |")
        lines.append("")
    for r in records:
        if "failed" in r:
            lines += [f"Failed: N = {r['n']}, box {r['box']}, φ = {r['phi']:.3f}: "
                      f"{r['failed']}.", ""]
    if found:
        lines += ["**The loops' extrema** (a parabola through the five points about each; "
                  "errors: half the 16–84 % range over resamplings of the points within "
                  "their errors). The published ones from all their points, and from those "
                  "at the φ of the runs, which compare with ours.", "",
                  "| N, box | | maximum: φ, βP d² | minimum: φ, βP d² |",
                  "| --- | --- | --- | --- |"]
        for name, all_three in found.items():
            for label, key in (("published, all points", "published"),
                               ("published, at our φ", "published_at_our_phi"),
                               ("sim", "sim")):
                e = all_three[key] or {"max": None, "min": None}
                lines.append(f"| {name} | {label} | {_extreme(e['max'])} | "
                             f"{_extreme(e['min'])} |")
        lines.append("")
    hours, large_point_hours = _cost(records)
    lines.append("Processor hours: " + "; ".join(f"{k} {v:.2f}" for k, v in hours.items())
                 + f"; in all {sum(hours.values()):.2f}.")
    if large_point_hours is not None:
        lines.append(f"N = 256² would take at least {large_point_hours:.2f} processor hours "
                     f"per state point (four times the disks of N = 128² at the same "
                     f"collisions per disk; its slower relaxation would ask for more).")
    _write(results / "melting.md", "\n".join(lines) + "\n")


def summarise(todo, out, results):
    """The tables, the figures, melting.md and melting.json of the points of ``todo`` that
    have a record, each with its :func:`status`."""
    records = [dict(record, status=status(p, record)) for p in todo
               if (record := _record(p)) is not None]
    measured = [r for r in records if "bPd2" in r]
    results.mkdir(parents=True, exist_ok=True)
    write_tables(measured, results)
    found = extrema(measured)
    write_markdown(records, found, results)
    draw_equation_of_state(measured, out, results)
    analysed = [p for p in todo if "bPd2" in (_record(p) or {})]
    draw_bond_order(analysed, out, results)
    draw_starts(todo, out, results)
    hours, _ = _cost(records)
    summary = {"points": records, "extrema": found, "cpu_hours": sum(hours.values()),
               "plan": [asdict(g) for g in PLAN if g.name in {r["group"] for r in records}],
               "rules": {"drift": DRIFT, "margin": MARGIN, "growth": GROWTH,
                         "production_blocks": PRODUCTION_BLOCKS}}
    _write(results / "melting.json", json.dumps(summary, indent=1, default=float))
    print(f"melting: {len(records)} points, {sum(hours.values()):.2f} processor hours, "
          f"into {results}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("outputs/melting"))
    parser.add_argument("--results", type=Path, default=Path("outputs/melting/results"))
    parser.add_argument("--groups", nargs="*", help="names of the groups of PLAN to run")
    parser.add_argument("--jobs", type=int, default=os.cpu_count())
    parser.add_argument("--cluster", choices=("slurm", "local"), default=None,
                        help="run the rounds through submitit instead of joblib")
    parser.add_argument("--partition", default=None, help="the SLURM partition of the jobs")
    parser.add_argument("--quick", action="store_true", help="a smoke run: two short points")
    parser.add_argument("--report", action="store_true",
                        help="run nothing: the results of the points done so far")
    args = parser.parse_args(argv)
    plan = QUICK if args.quick else PLAN
    if args.groups:
        unknown = set(args.groups) - {g.name for g in plan}
        if unknown:
            parser.error(f"--groups: {', '.join(sorted(unknown))}: no such group; allowed: "
                         + ", ".join(g.name for g in plan))
        plan = tuple(g for g in plan if g.name in args.groups)
    try:
        if not args.report:
            simulate(plan, args.out, args.jobs, args.cluster, args.partition)
    except KeyboardInterrupt:
        print("melting: interrupted; run it again to go on where it stopped", file=sys.stderr)
        return 130
    summarise(points(plan, args.out), args.out, args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
