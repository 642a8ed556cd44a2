"""What sim's features cost: the engine against a minimal implementation of the same design.

The minimal engine below does only what the fastest published design does for equal elastic
disks in a periodic box (Smallenburg, Eur. Phys. J. E 45, 22 (2022)): one event per disk,
neighbour shells rebuilt from a cell grid (lists of fixed capacity, cleared and refilled),
collision counters against stale events, lazy positions, and sim's own calendar queue and
contact-time roots. No walls, masses, species, big disks, effects, observables, stop
conditions or renumbering. Both engines use the same shell diameter r_n (sim's default for
the packing fraction unless ``--shell`` is given).

Both engines start from the same equilibrated state and run in alternating chunks in one
process, so that a busy machine slows both alike; the ratio of their rates is what this
prints. The minimal engine is the design without sim's features, so the ratio is what they
cost (or, at large N, what sim's memory layout gains).

    python benchmarks/minimal_design.py --n 10000 100000 --phi 0.5
"""

import argparse
import math
import statistics
import time

import numpy as np
from numba import njit

from engine_rate import equal_disks
from sim.engine import Boundary, Engine
from sim.engine.kinematics import (
    may_touch_before,
    minimum_image,
    pair_contact_time,
    shell_exit_time,
    wrap,
)
from sim.engine.queue import build_queue, earliest, empty_queue, reschedule
from sim.engine.sizing import shell_ratio

SHELL_EXIT = -2


@njit(inline="always")
def advance(i, t, p, length):
    """p: float64[n, 8] rows (x, y, vx, vy, t_own, cx, cy, unused)."""
    dt = t - p[i, 4]
    p[i, 0] = wrap(p[i, 0] + p[i, 2] * dt, length, True)
    p[i, 1] = wrap(p[i, 1] + p[i, 3] * dt, length, True)
    p[i, 4] = t


@njit(inline="always")
def predict(i, t, p, nb, nb_count, count, event_time, partner, partner_count, length, sigma,
            delta):
    x, y, vx, vy = p[i, 0], p[i, 1], p[i, 2], p[i, 3]
    tau = shell_exit_time(minimum_image(x - p[i, 5], length, True),
                          minimum_image(y - p[i, 6], length, True), vx, vy, delta)
    best = SHELL_EXIT
    for k in range(nb_count[i]):
        j = nb[i, k]
        dt = t - p[j, 4]
        rx = minimum_image(x - p[j, 0] - p[j, 2] * dt, length, True)
        ry = minimum_image(y - p[j, 1] - p[j, 3] * dt, length, True)
        vx_ij = vx - p[j, 2]
        vy_ij = vy - p[j, 3]
        if may_touch_before(rx, ry, vx_ij, vy_ij, sigma, tau):
            tau_ij = pair_contact_time(rx, ry, vx_ij, vy_ij, sigma)
            if tau_ij < tau:
                tau = tau_ij
                best = j
    event_time[i] = t + tau
    partner[i] = best
    if best >= 0:
        partner_count[i] = count[best]


@njit(inline="always")
def cell_of(x, y, cells, width):
    return min(int(y / width), cells - 1) * cells + min(int(x / width), cells - 1)


@njit(_nrt=False, error_model="numpy")
def rebuild(i, p, nb, nb_count, head, following, preceding, cell, cells, width, length,
            reach_squared):
    """Leave every old list, move the shell centre to the disk, refile its cell, and link
    every disk of the 3×3 cells around it whose shell centre lies within r_n + 2δ."""
    for k in range(nb_count[i]):
        j = nb[i, k]
        last = nb_count[j] - 1
        for m in range(last + 1):
            if nb[j, m] == i:
                nb[j, m] = nb[j, last]
                break
        nb_count[j] = last
    nb_count[i] = 0
    cx, cy = p[i, 0], p[i, 1]
    p[i, 5], p[i, 6] = cx, cy
    c = cell_of(cx, cy, cells, width)
    if c != cell[i]:
        after, before = following[i], preceding[i]
        if before >= 0:
            following[before] = after
        else:
            head[cell[i]] = after
        if after >= 0:
            preceding[after] = before
        first = head[c]
        following[i], preceding[i] = first, -1
        if first >= 0:
            preceding[first] = i
        head[c], cell[i] = i, c
    for dy in range(-1, 2):
        row = (c // cells + dy) % cells
        for dx in range(-1, 2):
            j = head[row * cells + (c % cells + dx) % cells]
            while j >= 0:
                if j != i:
                    rx = minimum_image(cx - p[j, 5], length, True)
                    ry = minimum_image(cy - p[j, 6], length, True)
                    if rx * rx + ry * ry < reach_squared:
                        nb[i, nb_count[i]] = j
                        nb_count[i] += 1
                        nb[j, nb_count[j]] = i
                        nb_count[j] += 1
                j = following[j]


@njit(_nrt=False, error_model="numpy")
def link_all(p, nb, nb_count, head, following, preceding, cell, cells, width, length,
             reach_squared):
    """Build every list by rebuilding each disk in turn (each rebuild leaves the lists
    symmetric)."""
    for i in range(p.shape[0]):
        rebuild(i, p, nb, nb_count, head, following, preceding, cell, cells, width, length,
                reach_squared)


@njit(_nrt=False, error_model="numpy")
def run(collisions, p, nb, nb_count, head, following, preceding, cell, count, event_time,
        partner, partner_count, heap, links, list_head, calendar, block_rate, cells, width,
        length, sigma, delta, reach_squared):
    done = 0
    while done < collisions:
        i = earliest(heap, links, list_head, calendar, block_rate, event_time)
        t = event_time[i]
        j = partner[i]
        advance(i, t, p, length)
        if j >= 0 and count[j] == partner_count[i]:
            advance(j, t, p, length)
            rx = minimum_image(p[i, 0] - p[j, 0], length, True)
            ry = minimum_image(p[i, 1] - p[j, 1], length, True)
            b = (rx * (p[i, 2] - p[j, 2]) + ry * (p[i, 3] - p[j, 3])) / (sigma * sigma)
            p[i, 2] -= b * rx
            p[i, 3] -= b * ry
            p[j, 2] += b * rx
            p[j, 3] += b * ry
            count[i] += 1
            count[j] += 1
            done += 1
            predict(j, t, p, nb, nb_count, count, event_time, partner, partner_count, length,
                    sigma, delta)
            reschedule(heap, links, list_head, calendar, block_rate, event_time, j)
        elif j == SHELL_EXIT:
            rebuild(i, p, nb, nb_count, head, following, preceding, cell, cells, width,
                    length, reach_squared)
        predict(i, t, p, nb, nb_count, count, event_time, partner, partner_count, length,
                sigma, delta)
        reschedule(heap, links, list_head, calendar, block_rate, event_time, i)


class MinimalEngine:
    """Equal elastic disks of radius ``radius`` in the periodic unit box, at time 0."""

    def __init__(self, position, velocity, radius, shell):
        n = len(position)
        phi = n * math.pi * radius**2
        # lists do not grow: room for the mean number of neighbours 4φ (r_n/σ)² plus eight
        # standard deviations of its fluctuations and a margin
        expected = 4.0 * phi * shell**2
        capacity = int(expected + 8.0 * math.sqrt(expected) + 16.0)
        self.length, self.sigma = 1.0, 2.0 * radius
        self.delta = 0.5 * (shell - 1.0) * self.sigma
        reach = self.sigma + 2.0 * self.delta
        self.reach_squared = reach * reach
        self.cells = int(self.length / reach)
        self.width = self.length / self.cells
        self.p = np.zeros((n, 8))
        self.p[:, 0:2] = position
        self.p[:, 2:4] = velocity
        self.p[:, 5:7] = position
        self.nb = np.full((n, capacity), -1, np.int32)
        self.nb_count = np.zeros(n, np.int32)
        self.head = np.full(self.cells**2, -1, np.int32)
        self.following = np.full(n, -1, np.int32)
        self.preceding = np.full(n, -1, np.int32)
        self.cell = np.full(n, -1, np.int32)
        for i in range(n):
            c = cell_of(position[i, 0], position[i, 1], self.cells, self.width)
            first = self.head[c]
            self.following[i] = first
            if first >= 0:
                self.preceding[first] = i
            self.head[c], self.cell[i] = i, c
        link_all(self.p, self.nb, self.nb_count, self.head, self.following, self.preceding,
                 self.cell, self.cells, self.width, self.length, self.reach_squared)
        self.count = np.zeros(n, np.int32)
        self.event_time = np.zeros(n)
        self.partner = np.zeros(n, np.int32)
        self.partner_count = np.zeros(n, np.int32)
        for i in range(n):
            predict(i, 0.0, self.p, self.nb, self.nb_count, self.count, self.event_time,
                    self.partner, self.partner_count, self.length, self.sigma, self.delta)
        self.queue = empty_queue(n)
        build_queue(*self.queue, self.event_time, 0.0)

    def run(self, collisions):
        run(collisions, self.p, self.nb, self.nb_count, self.head, self.following,
            self.preceding, self.cell, self.count, self.event_time, self.partner,
            self.partner_count, *self.queue, self.cells, self.width, self.length, self.sigma,
            self.delta, self.reach_squared)


def compare(n, phi, chunk, rounds, warmup, shell):
    """Rates (collisions/s) of both engines in alternating chunks after a common warm-up."""
    position, velocity, radius = equal_disks(n, phi)
    shell = shell_ratio(phi) if shell is None else shell
    engine = Engine(position, velocity, radius, boundary=Boundary(periodic=(True, True)),
                    shell=shell)
    engine.run(collisions=int(warmup * n))
    minimal = MinimalEngine(engine.positions(), engine.velocities(), radius, shell)
    minimal.run(chunk // 10)
    rates = {"sim": [], "minimal": []}
    for _ in range(rounds):
        started = time.perf_counter()
        minimal.run(chunk)
        rates["minimal"].append(chunk / (time.perf_counter() - started))
        c0 = engine.collisions
        started = time.perf_counter()
        engine.run(collisions=c0 + chunk)
        rates["sim"].append((engine.collisions - c0) / (time.perf_counter() - started))
    ratios = [s / m for s, m in zip(rates["sim"], rates["minimal"], strict=True)]
    return {"n": n, "phi": phi, "shell": round(shell, 2),
            "sim_collisions_per_s": round(max(rates["sim"])),
            "minimal_collisions_per_s": round(max(rates["minimal"])),
            "sim_over_minimal": round(statistics.median(ratios), 3)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--phi", type=float, nargs="+", default=[0.5])
    parser.add_argument("--chunk", type=int, default=1_000_000, help="collisions per round")
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--warmup", type=float, default=10.0, help="collisions per disk")
    parser.add_argument("--shell", type=float, default=None,
                        help="shell diameter r_n/σ for both (default: sim's for each φ)")
    args = parser.parse_args(argv)
    print("n | phi | shell | sim_collisions_per_s | minimal_collisions_per_s | sim_over_minimal")
    print("--- | --- | --- | --- | --- | ---")
    for n in args.n:
        for phi in args.phi:
            row = compare(n, phi, args.chunk, args.rounds, args.warmup, args.shell)
            print(" | ".join(str(v) for v in row.values()), flush=True)
    print("\nrates: best chunk; ratio: median over rounds of sim / minimal in the same round")


if __name__ == "__main__":
    main()
