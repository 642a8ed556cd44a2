"""The equation of state of elastic hard disks at the published sizes and boxes, against
Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth, J. Chem. Phys. 157, 234111 (2022)
(``data/li_2022.csv``: βP d² with its error per N, box and φ).

A state point: N disks at packing fraction φ in a periodic box of aspect ratio L_x/L_y
(L_y = 1), placed as ``auto`` places a gas (:func:`sim.pipeline.initial.compressed` above
φ = 0.6), Maxwellian at T = 1 with zero total momentum; an equilibration of ``warmup``
collisions per disk; then blocks of collisions whose pressures (:func:`sim.analysis.
equation_of_state.reduced_pressure_d2`, exact for zero momentum), averaged over the time
they span (:func:`sim.analysis.equation_of_state.time_weighted`), give the mean and its
blocking error.
"""

import csv
import math
import time
from pathlib import Path

import numpy as np

from sim.analysis.equation_of_state import blocking, reduced_pressure_d2, time_weighted
from sim.checks.rows import Check
from sim.engine import Boundary, Engine
from sim.pipeline.initial import compressed, maxwellian, random_sequential, remove_drift

REFERENCE = Path(__file__).with_name("data") / "li_2022.csv"
#: Engel, Anderson, Glotzer, Isobe, Bernard & Krauth, Phys. Rev. E 87, 042134 (2013): event-
#: driven MD and MPMC at N = 256², 512², MPMC at 1024², square boxes
LARGE_N_REFERENCE = Path(__file__).with_name("data") / "engel_2013.csv"
#: the large-N curves drawn beside a study for orientation: (label, file, N, method)
LARGE_N = (("Engel et al. 2013, EDMD, N = 256²", LARGE_N_REFERENCE, 65536, "EDMD"),
           ("Engel et al. 2013, EDMD, N = 512²", LARGE_N_REFERENCE, 262144, "EDMD"),
           ("Engel et al. 2013, MPMC, N = 1024²", LARGE_N_REFERENCE, 1048576, "MPMC"))


def reference(n, box, source=REFERENCE, method=None):
    """The published (φ, βP d², error) float64 arrays of ``n`` disks in the box ``box`` (as
    the data files name it: ``"1:1"``, ``"9:8√3/2"``, …) and its aspect ratio, from
    ``source`` (Li et al. 2022 unless given), of ``method`` if given."""
    with open(source, encoding="utf-8") as file:
        rows = [row for row in csv.DictReader(line for line in file if not line.startswith("#"))
                if int(row["n"]) == n and row["box"] == box
                and method in (None, row["method"])]
    if not rows:
        raise ValueError(f"no published pressures of N = {n} in the box {box}")
    values = np.array([[float(row[k]) for k in ("packing_fraction", "pressure_d2", "error")]
                       for row in rows])
    return values[:, 0], values[:, 1], values[:, 2], float(rows[0]["aspect"])


def state_point(n, aspect, phi, seed=0, warmup=100, collisions=20_000, blocks=256):
    """βP d² of ``n`` disks at ``phi`` in a periodic box of aspect ratio ``aspect``:
    (mean, blocking error, converged, collisions per disk run) over ``blocks`` blocks of
    ``collisions`` collisions per disk in all, after ``warmup`` collisions per disk."""
    box = (aspect, 1.0)
    radius = math.sqrt(phi * aspect / (n * math.pi))
    periodic = (True, True)
    place = compressed if phi > 0.5 else random_sequential
    position = place(np.full(n, radius), box=box, periodic=periodic, seed=seed)
    mass = np.ones(n)
    velocity = remove_drift(maxwellian(mass, 1.0, seed=seed + 1), mass)
    engine = Engine(position, velocity, radius, boundary=Boundary(size=box, periodic=periodic))
    engine.run(collisions=warmup * n)
    per_block = max(1, collisions * n // blocks)
    kinetic = engine.kinetic_energy()
    pressures, spans = [], []
    for _ in range(blocks):
        virial, started = engine.virial, engine.time
        engine.run(collisions=engine.collisions + per_block)
        spans.append(engine.time - started)
        pressures.append(reduced_pressure_d2(n, kinetic, engine.virial - virial, spans[-1],
                                             aspect, 2.0 * radius))
    mean, error, converged, _ = blocking(time_weighted(pressures, spans))
    return mean, error, converged, warmup + blocks * per_block / n


def small_n_pressure(n=72, box="1:1", phis=(0.65,), seed=0, collisions=300_000):
    """βP d² of N = ``n`` in the published box at ``phis`` against Li et al. 2022: within
    three combined standard errors (theirs and the blocking error of the run, about 0.002
    after ``collisions`` per disk)."""
    started = time.perf_counter()
    published_phi, published, published_error, aspect = reference(n, box)
    rows = []
    for phi in phis:
        k = int(np.argmin(np.abs(published_phi - phi)))
        mean, error, converged, per_disk = state_point(n, aspect, phi, seed,
                                                       collisions=collisions)
        rows.append(Check(
            f"βP d², N = {n}, box {box}, φ = {phi} ({per_disk:.3g} collisions per disk"
            f"{'' if converged else ', blocking not converged'})", mean, float(published[k]),
            3.0 * math.hypot(error, float(published_error[k])),
            "Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth 2022 (ECMC)",
            time.perf_counter() - started if not rows else None))
    return rows


def loop_extrema(phi, pressure, error, draws=2000, seed=0):
    """The maximum and the minimum of a van der Waals loop through the points (``phi``,
    ``pressure`` ± ``error``, float64[m] in increasing φ): {"max": (φ, σ_φ, p, σ_p), "min":
    (…)}, each the vertex of a parabola fitted (weighted by 1/error²) to the five points about
    the extreme point, with errors as half the 16–84 % range of the vertices of ``draws``
    resamplings of the points within their errors (a resampling whose parabola bends the
    other way or whose vertex leaves the five points' span is left out); None when the
    points do not rise, fall and rise again. The vertex depends on the points fitted: compare
    two curves on the same φ."""
    phi, pressure, error = (np.asarray(x, np.float64) for x in (phi, pressure, error))
    inner = np.arange(1, phi.size - 1)
    peaks = inner[(pressure[inner] > pressure[inner - 1]) & (pressure[inner] > pressure[inner + 1])]
    if peaks.size == 0:
        return None
    top = int(peaks[0])
    dips = inner[(inner > top) & (pressure[inner] < pressure[inner - 1])
                 & (pressure[inner] < pressure[inner + 1])]
    if dips.size == 0:
        return None
    rng = np.random.default_rng(seed)
    samples = pressure + error * rng.standard_normal((draws, phi.size))
    extrema = {}
    for name, k, bend in (("max", top, -1.0), ("min", int(dips[0]), 1.0)):
        near = slice(max(k - 2, 0), min(k + 3, phi.size))
        x = phi[near] - phi[k]
        vertices = []
        for y in (pressure[near], *samples[:, near]):
            c2, c1, c0 = np.polyfit(x, y, 2, w=1.0 / error[near])
            at = -c1 / (2.0 * c2) if c2 * bend > 0 else np.nan
            if x[0] <= at <= x[-1]:
                vertices.append((phi[k] + at, c0 + c1 * at + c2 * at * at))
            elif not vertices:  # the points' own parabola: none
                break
        if not vertices or len(vertices) < draws // 2:
            return None
        low, high = np.percentile(np.array(vertices[1:]), [16.0, 84.0], axis=0)
        extrema[name] = (vertices[0][0], 0.5 * (high[0] - low[0]), vertices[0][1],
                         0.5 * (high[1] - low[1]))
    return extrema
