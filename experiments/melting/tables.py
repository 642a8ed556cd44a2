"""The melting study's results as data: the tables (melting.csv, melting_reference.csv), the
replicas' weighted means, the loops' extrema, melting.md with every run against its published
value, and files written whole."""

import csv
import math

import numpy as np
from plan import AGREEMENT, CUT, DRIFT, GROWTH, MARGIN, PLAN, PRODUCTION_BLOCKS

from sim.checks.melting import loop_extrema, reference
from sim.storage.whole_file import whole_file


def write_tables(records, results):
    """melting.csv and melting_reference.csv, one row per run."""
    columns = ("n", "aspect", "phi", "start", "seed", "collisions_per_disk", "bPd2", "err",
               "psi6")
    with whole_file(results / "melting.csv") as partial, \
            open(partial, "w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file)
        writer.writerow(columns)
        for r in records:
            writer.writerow([r["n"], f"{r['aspect']:.12g}", f"{r['phi']:.3f}", r["start"],
                             r["seed"], f"{r['collisions_per_disk']:.0f}", f"{r['bPd2']:.5f}",
                             f"{r['err']:.5f}", f"{r['psi6']:.4f}"])
    with whole_file(results / "melting_reference.csv") as partial, \
            open(partial, "w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file)
        writer.writerow(("n", "box", "aspect", "phi", "bPd2", "err", "source"))
        for r in records:
            phi, pressure, error, _ = reference(r["n"], r["box"])
            k = int(np.argmin(np.abs(phi - r["phi"])))
            writer.writerow([r["n"], r["box"], f"{r['aspect']:.12g}", f"{r['phi']:.3f}",
                             pressure[k], error[k], SOURCE])


SOURCE = ("Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth, J. Chem. Phys. 157, 234111 (2022), "
          "data of jellyfysh/HistoricDisks")


def _weighted(runs):
    """The weighted mean p̄ of the runs' βP d², their weights 1/σᵢ² and the scale factor S
    (:func:`estimates`); NaN for an error not finite."""
    p = np.array([r["bPd2"] for r in runs])
    sigma = np.array([r["err"] for r in runs])
    w = 1.0 / sigma**2 if np.all(np.isfinite(sigma) & (sigma > 0)) else np.full(len(runs),
                                                                                  np.nan)
    mean = w @ p / w.sum()
    chi2 = w @ (p - mean) ** 2
    return mean, w, max(1.0, math.sqrt(chi2 / (len(runs) - 1))) if len(runs) > 1 else 1.0


def scale_factor(runs):
    """The scale factor S of the runs' βP d² (records with bPd2 and err, :func:`estimates`):
    1 for one run, NaN for an error not finite."""
    mean, _, scale = _weighted(runs)
    return scale if np.isfinite(mean) else math.nan


def estimates(records):
    """One βP d² per N, box, φ and start: its run's, or over its replicas (runs with other
    seeds) the weighted mean p̄ = Σ wᵢ pᵢ / Σ wᵢ, wᵢ = 1/σᵢ², with the error
    S (Σ wᵢ)^(−1/2), S = max(1, √(χ²/(k − 1))), χ² = Σ wᵢ (pᵢ − p̄)² over the k replicas:
    the scale factor of the Particle Data Group's averages (Review of Particle Physics,
    Introduction), which widens the error when the replicas scatter more than their own
    errors say, as short runs whose blocking has not seen the slowest fluctuations do. An
    error not finite makes the mean and the error NaN. Each a dict of n, box, phi, start,
    seeds, replicas (as many as the plan holds), bPd2, err, scale (S) and status (``done``
    when every replica of the plan is, else ``longest`` when every one is done or longest,
    else ``running``)."""
    runs = {}
    for r in records:
        runs.setdefault((r["n"], r["box"], round(r["phi"], 6), r["start"]), []).append(r)
    found = []
    for (n, box, _, start), same in runs.items():
        mean, w, scale = _weighted(same)
        states = {r["status"] for r in same} | (
            {"not begun"} if len(same) < same[0]["replicas"] else set())
        found.append({"n": n, "box": box, "phi": same[0]["phi"], "start": start,
                      "seeds": sorted(r["seed"] for r in same),
                      "replicas": same[0]["replicas"], "bPd2": float(mean),
                      "err": float(scale * w.sum() ** -0.5), "scale": float(scale),
                      "status": "done" if states == {"done"} else
                      "longest" if states <= {"done", "longest"} else "running"})
    return found


def extrema(records):
    """Per N and box with a loop in its published curve: the published maximum and minimum
    from all its points and from those at our φ only, and ours (:func:`loop_extrema`, one
    estimate per φ, :func:`estimates`: that of the first of its starts in ``STARTS``), where
    our points show one. The vertex of a parabola depends on the points fitted: ours
    compare with the published ones at our φ."""
    found = {}
    for n, box in dict.fromkeys((r["n"], r["box"]) for r in records):
        one = {}
        for r in sorted((e for e in estimates(records) if (e["n"], e["box"]) == (n, box)),
                        key=lambda r: STARTS.index(r["start"])):
            one.setdefault(round(r["phi"], 6), r)
        mine = [one[phi] for phi in sorted(one)]
        phi, pressure, error, _ = reference(n, box)
        published = loop_extrema(phi, pressure, error)
        if published is None:
            continue
        ours = np.array([[r[k] for k in ("phi", "bPd2", "err")] for r in mine]).T
        same = np.isin(np.round(phi, 3), np.round(ours[0], 3))
        found[f"N = {n}, box {box}"] = {
            "published": published,
            "published_at_our_phi": loop_extrema(*(x[same] for x in (phi, pressure, error))),
            "sim": loop_extrema(*ours)}
    return found


#: the starts, in the order in which one estimate per φ is taken for the loop's extrema
STARTS = ("compressed", "lattice", "melted")


def processor_hours(records):
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
    lines = [f"A point is done when the blocking error of βP d² over its production (with "
             f"replicas, times their scale factor S) is at most its target (its group's, "
             f"times √(replicas)), the blocking has converged, the means of the "
             f"production's halves differ by less than {DRIFT:g} standard errors, at "
             f"least {PRODUCTION_BLOCKS} blocks are kept, at most {CUT:.0%} of the blocks "
             f"are cut as equilibration (a longer cut is a transient the run is too short "
             f"for, or rare excursions taken for one) and its βP d² agrees with that of "
             f"the runs of the same state point from other starts or seeds that are "
             f"finished on their own (their target met or their longest run made) within "
             f"{AGREEMENT:g} combined standard errors; else it runs on to {MARGIN:g} times "
             f"the length its error asks for ({GROWTH[0]:g} to {GROWTH[1]:g} times its "
             f"length so far). Targets: "
             + "; ".join(f"{g.name} {g.target:g} (a block every {g.block} collisions per "
                         f"disk, at most {g.longest:.3g})" for g in PLAN) + ".", ""]
    measured = [r for r in records if "bPd2" in r]
    for name in dict.fromkeys(r["group"] for r in measured):
        rows = sorted((r for r in measured if r["group"] == name),
                      key=lambda r: (r["phi"], r["seed"]))
        phi, pressure, error, _ = reference(rows[0]["n"], rows[0]["box"])
        seeds = sorted({r["seed"] for r in rows})
        lines += [f"**N = {rows[0]['n']}, box {rows[0]['box']}, {rows[0]['start']} start, "
                  f"seed{'s' if len(seeds) > 1 else ''} {', '.join(map(str, seeds))}**",
                  "", "| φ | βP d², sim | published | difference / combined error | "
                  "collisions per disk | equilibration cut | drift | ⟨|Ψ₆|⟩ | state |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in rows:
            k = int(np.argmin(np.abs(phi - r["phi"])))
            z = (r["bPd2"] - pressure[k]) / math.hypot(r["err"], error[k])
            which = f" (seed {r['seed']})" if len(seeds) > 1 else ""
            lines.append(f"| {r['phi']:.3f}{which} | {r['bPd2']:.4f} ± {r['err']:.4f} | "
                         f"{pressure[k]:.4f} ± {error[k]:.4f} | {z:+.1f} | "
                         f"{r['collisions_per_disk']:.3g} | {r['cut']} of "
                         f"{r['cut'] + r['blocks']} blocks | {r['drift']:+.1f} | "
                         f"{r['psi6']:.3f} | {r['status']} |")
        lines.append("")
    several = [e for e in estimates(measured) if e["replicas"] > 1]
    if several:
        lines += ["**Replicas**: the runs of one state point and start with several seeds, "
                  "each done at its group's target times √(replicas), their weighted mean "
                  "(weights 1/σ²) against the published value, its error widened by the "
                  "scale factor S = max(1, √(χ²/(k − 1))) when the replicas scatter more "
                  "than their errors say, and each replica runs on until S times its error "
                  "meets its target; running until every replica is done.", "",
                  "| N, box | φ | start | seeds (runs of replicas) | βP d², sim | S | "
                  "published | difference / combined error | state |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for e in several:
            phi, pressure, error, _ = reference(e["n"], e["box"])
            k = int(np.argmin(np.abs(phi - e["phi"])))
            z = (e["bPd2"] - pressure[k]) / math.hypot(e["err"], error[k])
            lines.append(f"| {e['n']}, {e['box']} | {e['phi']:.3f} | {e['start']} | "
                         f"{', '.join(map(str, e['seeds']))} ({len(e['seeds'])} of "
                         f"{e['replicas']}) | {e['bPd2']:.4f} ± "
                         f"{e['err']:.4f} | {e['scale']:.2f} | {pressure[k]:.4f} ± "
                         f"{error[k]:.4f} | {z:+.1f} | {e['status']} |")
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
                  "| N and box | | maximum: φ, βP d² | minimum: φ, βP d² |",
                  "| --- | --- | --- | --- |"]
        for name, all_three in found.items():
            for label, key in (("published, all points", "published"),
                               ("published, at our φ", "published_at_our_phi"),
                               ("sim", "sim")):
                e = all_three[key] or {"max": None, "min": None}
                lines.append(f"| {name} | {label} | {_extreme(e['max'])} | "
                             f"{_extreme(e['min'])} |")
        lines.append("")
    hours, large_point_hours = processor_hours(records)
    lines.append("Processor hours: " + "; ".join(f"{k} {v:.2f}" for k, v in hours.items())
                 + f"; in all {sum(hours.values()):.2f}.")
    if large_point_hours is not None:
        lines.append(f"N = 256² would take at least {large_point_hours:.2f} processor hours "
                     f"per state point (four times the disks of N = 128² at the same "
                     f"collisions per disk; its slower relaxation would ask for more).")
    with whole_file(results / "melting.md") as partial:
        partial.write_text("\n".join(lines) + "\n", encoding="utf-8")
