"""The engine as Python sees it: a state of arrays, and ``run`` with stop conditions.

Python builds the state, calls the compiled loop (:func:`sim.engine.loop.run_events`) in chunks
of events, checks the conditions that need Python (wall-clock budget, user predicates) between
chunks, and turns the loop's error codes into exceptions. No Python runs per event.

The per-disk state lives in :class:`sim.engine.state.DiskArrays`, in engine order: disks are
renumbered by grid cell so that neighbours in space are neighbours in memory, and renumbered
again every ``reorder_every`` events as they diffuse. Everything the user reads
(:meth:`Engine.positions`, :meth:`Engine.velocities`, ``radius``, ``mass``, ``species``, …) is
in the original order.
"""

import math
import operator
import time as wallclock
from dataclasses import dataclass

import numpy as np
from numba import njit

from sim.effects import Effects
from sim.effects.event_log import LOG_COLUMNS, LOG_DISK, LOG_PARTNER
from sim.effects.gravity import gravity_vector, potential_energy
from sim.effects.restitution import CollapseWatch, restitution_matrix, wall_restitution_value
from sim.effects.tc import tc_time
from sim.effects.thermal_walls import wall_temperature
from sim.effects.walls import wall_motion, wall_state
from sim.engine import loop
from sim.engine.box import WALL_NAMES
from sim.engine.groups import Box, Disks, Limits, Neighbours, Schedule, Tallies
from sim.engine.kinematics import DISK_COLUMNS, RADIUS, T_OWN, VX, VY, X, Y, minimum_image
from sim.engine.neighbours import build_all_neighbours, grow_lists, list_starts
from sim.engine.parameters import common_value
from sim.engine.queue import BLOCK_EVENTS, build_queue, empty_queue
from sim.engine.state import DiskArrays

#: Neighbour-shell diameter r_n/σ by packing fraction (Smallenburg 2022 found 2.0 best at
#: φ = 0.5 and about 4.6 at φ = 0.1); interpolated linearly between the points.
SHELL_TABLE = ((0.0, 6.0), (0.1, 4.6), (0.3, 2.6), (0.5, 2.0), (0.7, 1.6), (0.91, 1.3))

#: Lead λ of a new shell's centre ahead of its disk, in units of the shell radius δ
#: (:func:`sim.engine.neighbours.shell_centre`), by packing fraction. Chosen for the fewest shell
#: exits per collision at N = 1e4 (λ = 0 … 0.95): 2.09 → 1.41 at φ = 0.1, 0.87 → 0.68 at
#: 0.3, 0.37 → 0.32 at 0.5, 0.21 → 0.20 at 0.6; at 0.7 every lead adds exits (a caged disk
#: turns back before it reaches the shell).
LEAD_TABLE = ((0.0, 0.9), (0.1, 0.8), (0.3, 0.6), (0.5, 0.4), (0.6, 0.25), (0.7, 0.0))

#: Disks are renumbered by cell every this many events per disk, from this many disks on
#: (below it the whole state sits in cache and order does not matter). 20 beat 50 by 9 % at
#: N = 1e6 and 3 % at N = 1e5 (φ = 0.5); a renumbering costs about 0.4 s per 1e6 disks.
REORDER_EVENTS_PER_DISK = 20
REORDER_MIN_DISKS = 20_000

#: From this many disks on, the event loop prefetches several events ahead (``lookahead`` of
#: :func:`sim.engine.loop.run_events`). At φ = 0.5, against the same build without it: 0.94 at
#: N = 2e4 and 3e4, whose state (290 bytes per disk) still sits mostly in cache, 1.11 at 5e4.
#: The hints of a shell exit's cell scan start here too
#: (:func:`sim.engine.neighbours._prefetch_candidates`).
LOOKAHEAD_MIN_DISKS = 40_000

#: Entries every list gains when one list of a common capacity overflows (32 bytes): the
#: lists hold a Poisson-like number of neighbours, and among 10⁴ disks at φ = 0.1 with
#: shells ahead of their disks a list exceeds its 24 entries within 3·10⁶ collisions;
#: doubling all lists for it would cost 96 bytes per disk.
LIST_GROWTH = 8

#: A disk is "big" (kept out of the cell grid) when its radius exceeds this multiple of the
#: median radius, provided at most MAX_BIG disks are that large.
BIG_RADIUS_RATIO = 2.0
MAX_BIG = 64


class PhysicsBreakdown(RuntimeError):
    """The run cannot go on: the dynamics left what the engine can follow. Each kind names
    its cause in the class attribute ``stop_reason`` (recorded in the run file), and its
    message, one line, says what to change."""


class StalledError(PhysicsBreakdown):
    """Events keep arriving without the clock advancing: a numerical breakdown."""

    stop_reason = "stalled"


class ClosedBoxError(PhysicsBreakdown):
    """Moving walls have squeezed the disks to jamming, or closed the box."""

    stop_reason = "closed_box"


class InelasticCollapseError(PhysicsBreakdown):
    """Inelastic collapse: a few disks collide infinitely often in finite time."""

    stop_reason = "inelastic_collapse"

    def __init__(self, disks, time, collisions):
        self.disks = disks
        self.time = time
        shown = ", ".join(str(d) for d in disks[:10]) + (" …" if len(disks) > 10 else "")
        super().__init__(
            f"inelastic collapse at t = {time:.17g} after {collisions} disk collisions: disks "
            f"[{shown}] collide ever faster (consecutive contacts less than the collapse "
            f"interval apart). Hard disks with restitution < 1 can collide infinitely often in "
            f"finite time; switch on the TC model (tc.time, far below the mean free time; the "
            f"seed study used 1e-8) so that contacts closer than t_c are elastic."
        )


#: wall numbers of :mod:`sim.effects.walls` by name
WALLS = {name: wall for wall, name in enumerate(WALL_NAMES)}

#: The keys a wall's entry in ``walls`` may have.
WALL_KEYS = ("temperature", "speed", "amplitude", "frequency")


@dataclass(frozen=True)
class Boundary:
    """Box [0, Lx] × [0, Ly]; each axis has hard walls or is periodic."""

    size: tuple = (1.0, 1.0)
    periodic: tuple = (False, False)


#: With a wall-clock budget (``Engine.run(wall_seconds=...)``) chunks of events are sized to
#: take about this many seconds, from the rate of the chunk before, so that the budget is kept
#: to about that; the first chunk has TIMED_FIRST_CHUNK events, none fewer than
#: TIMED_MIN_CHUNK.
TIMED_CHUNK_SECONDS = 0.15
TIMED_FIRST_CHUNK = 20_000
TIMED_MIN_CHUNK = 1_000

#: A piston (a wall moving at constant speed) that has raised the kinetic energy this many
#: times above max(initial energy, N m U²) has jammed the disks against the opposite wall:
#: driven at constant speed, their collision rate and energy diverge at a finite time.
PISTON_ENERGY_LIMIT = 1e6


def _closing_time(motion, box, periodic, largest_radius):
    """The absolute time at which moving walls could come closer to the opposite wall than
    the largest disk diameter (inf when they never do): the gap along each walled axis is at
    least L + (U_high − U_low) t − A_low − A_high."""
    if motion is None:
        return math.inf
    closing = math.inf
    for axis in range(2):
        if periodic[axis]:
            continue
        low, high = motion[2 * axis], motion[2 * axis + 1]
        room = box[axis] - low[1] - high[1] - 2.0 * largest_radius
        if room <= 0.0:
            raise ValueError(f"the walls of axis {'xy'[axis]} oscillate with amplitudes "
                             f"{low[1]} and {high[1]} in a box {box[axis]} wide: they would "
                             f"crush disks of radius {largest_radius}")
        rate = low[0] - high[0]
        if rate > 0.0:
            closing = min(closing, room / rate)
    return closing


#: The stall guard of :func:`sim.engine.loop.run_events` ends a run after more than
#: 16 N + 1000 events in a row, each at most stall_dt = STALL_RESOLUTION · D / v after the one
#: before (:func:`stall_interval`): D the far edge of the disks at the start (the largest
#: x + R or y + R, the side of a periodic axis; the box side for disks that fill the box),
#: whose ulps bound those of their coordinates, and v the fastest speed the scene sets (1 when
#: it sets none). stall_dt is then the time in which such a disk moves 256–512 ulps of D: a
#: float64 resolution, not a physical time. A chain of disks touching all round a periodic box
#: creeps on by round-off, at most about 2 ulps of the box side per contact (measured), and is
#: caught.
#:
#: A real gas never trips it: the intervals between its events are near exponential, with
#: mean m = (mean time between a disk's events) / N, and a run of k = 16 N + 1000 of them all
#: below stall_dt has the chance (1 − exp(−stall_dt/m))^k, negligible until stall_dt/m comes
#: near ln k ≈ 20. At φ = 0.8 in a unit box (v = 1) stall_dt/m is 9e-7 at N = 10⁴, and grows
#: as N^1.5 (m ∝ R/N): 9e-4 at N = 10⁶, 20 only near N = 10⁹. In a very dilute gas a disk's
#: events are its shell exits, a few radii R apart, so D counts at most STALL_RADII smallest
#: radii: stall_dt/m stays below 2⁻³⁴ N. Disks settled under the TC model have an event every
#: t_c or so, so a settled bed of N disks keeps clear of the guard while t_c ≫ 20 N stall_dt.
STALL_RESOLUTION = 2.0**-44

#: The largest D of :data:`STALL_RESOLUTION`, in smallest radii.
STALL_RADII = 1024.0


def stall_interval(length, box, initial_energy, mass, gravity, motion, temperature):
    """stall_dt of :data:`STALL_RESOLUTION` for the length D = ``length``, from the fastest
    of the initial rms speed, √(|g| L), the wall speeds |U| + A ω and √(T_w / m_min)
    (float64; box (Lx, Ly), mass (n,), gravity, motion and temperature as :class:`Engine`
    keeps them)."""
    speeds = [math.sqrt(2.0 * initial_energy / float(mass.sum()))]
    if gravity is not None:
        speeds.append(math.sqrt(float(np.hypot(*gravity)) * float(np.max(box))))
    if motion is not None:
        speeds.append(float(np.max(np.abs(motion[:, 0]) + motion[:, 1] * motion[:, 2])))
    if temperature is not None:
        speeds.append(math.sqrt(float(np.nanmax(temperature)) / float(mass.min())))
    fastest = max(speeds)
    return STALL_RESOLUTION * length / (fastest if fastest > 0.0 else 1.0)


def first_event_time(box, velocity, gravity, motion):
    """A time by which some disk has its first event, within a factor of a few, when any
    has one: the box's longer side crossed at the fastest speed the scene starts with, of a
    disk, of a fall across the box (√(|g| L)) or of a wall (|U| + A ω); a disk's first
    event, a shell exit or a contact, comes before it crosses a few shells or the box. One
    time unit when nothing moves. box (Lx, Ly), velocity (n, 2); gravity and motion as
    :class:`Engine` keeps them."""
    side = float(np.max(box))
    speeds = [math.sqrt(float(np.max(np.einsum("ij,ij->i", velocity, velocity))))]
    if gravity is not None:
        speeds.append(math.sqrt(float(np.hypot(*gravity)) * side))
    if motion is not None:
        speeds.append(float(np.max(np.abs(motion[:, 0]) + motion[:, 1] * motion[:, 2])))
    fastest = max(speeds)
    return side / fastest if fastest > 0.0 else 1.0


def grid_cells(box, width, limit):
    """Cells per axis (int64[2]) of a grid over ``box`` (Lx, Ly) whose cells are at least
    ``width`` wide along both axes, at most ``limit`` cells in all: as many as fit, else fewer
    in proportion to the sides. Wider cells than needed are correct, only slower; the count
    is formed in float64, as box / width may exceed int64 (tiny disks in a huge box), or even
    float64, whose inf the clip takes back to ``limit``."""
    with np.errstate(over="ignore"):
        fit = np.clip(np.floor(np.asarray(box, dtype=np.float64) / width), 1.0, limit)
    if fit[0] * fit[1] > limit:
        shrink = math.sqrt(fit[0] * fit[1] / limit)
        across = max(1.0, math.floor(fit[0] / shrink))
        fit = np.array([across, min(fit[1], max(1.0, math.floor(limit / across)))])
    return fit.astype(np.int64)


def cell_limit(n):
    """Most cells a grid for ``n`` disks may have: a few per disk."""
    return max(4 * n, 64)


@njit(cache=True)
def _first_overlap(position, radius, level, reach, cells, box, periodic, tolerance):
    """The first disk, in the given order, that overlaps a disk before it:
    (i, j, distance) with j the earliest disk it overlaps, or (-1, -1, 0.0) when none does.
    Overlap: |r_i − r_j| < (R_i + R_j)(1 − tolerance), minimum image on periodic axes.

    Each disk is checked against the disks filed before it, then filed itself, in a grid per
    radius level (``level`` int64[n], 0 … K−1; level k has radii up to ``reach[k]`` and
    ``cells[k]`` (``cells`` int64[K, 2]) cells, each at least 2 ``reach[k]`` wide, no more
    than :func:`cell_limit` of its number of disks). The disks filed never overlap, so a cell
    holds a few of them when the disks spread over the box, and the cost is O(N K) for K
    levels, also when most disks overlap (the check stops at the first); disks crowded into a
    corner of a box far larger than they crowd the cells, as they do the engine's own.

    position float64[n, 2] (inside the box, or wrapped into it on periodic axes), radius
    float64[n], box float64[2], periodic bool[2].
    """
    n = position.shape[0]
    n_levels = reach.shape[0]
    first_cell = np.zeros(n_levels + 1, dtype=np.int64)
    for k in range(n_levels):
        first_cell[k + 1] = first_cell[k] + cells[k, 0] * cells[k, 1]
    head = np.full(first_cell[n_levels], -1, dtype=np.int64)
    following = np.full(n, -1, dtype=np.int64)
    for i in range(n):
        x = position[i, 0]
        y = position[i, 1]
        found = -1
        found_distance = 0.0
        for k in range(n_levels):
            nx = cells[k, 0]
            ny = cells[k, 1]
            width_x = box[0] / nx
            width_y = box[1] / ny
            cx = min(int(x / width_x), nx - 1)
            cy = min(int(y / width_y), ny - 1)
            kx = int(math.ceil((radius[i] + reach[k]) / width_x))
            ky = int(math.ceil((radius[i] + reach[k]) / width_y))
            # a periodic axis narrower than the reach: every cell, each once
            if not periodic[0]:
                x_lo, x_hi = max(cx - kx, 0), min(cx + kx + 1, nx)
            elif 2 * kx + 1 < nx:
                x_lo, x_hi = cx - kx, cx + kx + 1
            else:
                x_lo, x_hi = 0, nx
            if not periodic[1]:
                y_lo, y_hi = max(cy - ky, 0), min(cy + ky + 1, ny)
            elif 2 * ky + 1 < ny:
                y_lo, y_hi = cy - ky, cy + ky + 1
            else:
                y_lo, y_hi = 0, ny
            for ay in range(y_lo, y_hi):
                row = first_cell[k] + (ay % ny) * nx
                for ax in range(x_lo, x_hi):
                    j = head[row + ax % nx]
                    while j >= 0:
                        dx = minimum_image(x - position[j, 0], box[0], periodic[0])
                        dy = minimum_image(y - position[j, 1], box[1], periodic[1])
                        distance = math.sqrt(dx * dx + dy * dy)
                        if (distance < (radius[i] + radius[j]) * (1.0 - tolerance)
                                and (found < 0 or j < found)):
                            found = j
                            found_distance = distance
                        j = following[j]
        if found >= 0:
            return i, found, found_distance
        k = level[i]
        nx = cells[k, 0]
        c = (first_cell[k] + min(int(y / (box[1] / cells[k, 1])), cells[k, 1] - 1) * nx
             + min(int(x / (box[0] / nx)), nx - 1))
        following[i] = head[c]
        head[c] = i
    return -1, -1, 0.0


def first_overlap(position, radius, box, periodic, tolerance=1e-9):
    """(i, j, distance) of the first disk i, in the given order, that overlaps a disk j before
    it (the earliest such j), or None; see :func:`_first_overlap`. Radii are grouped in
    levels a factor 2 apart, so that small disks are not filed in cells sized for large ones.
    """
    octave = np.floor(np.log2(radius / radius.min())).astype(np.int64)
    present = np.flatnonzero(np.bincount(octave))
    number = np.zeros(present[-1] + 1, dtype=np.int64)
    number[present] = np.arange(present.size)
    level = number[octave]
    reach = np.zeros(present.size)
    np.maximum.at(reach, level, radius)
    count = np.bincount(level)
    cells = np.array([grid_cells(box, 2.0 * reach[k], cell_limit(int(count[k])))
                      for k in range(present.size)])
    i, j, distance = _first_overlap(position, radius, level, reach, cells,
                                    np.asarray(box, dtype=np.float64),
                                    np.asarray(periodic, dtype=np.bool_), float(tolerance))
    return None if i < 0 else (int(i), int(j), float(distance))


def _interpolate(table, packing_fraction):
    """The value of a table of (φ, value) pairs at ``packing_fraction``, linearly
    interpolated and held constant beyond its ends."""
    phis, values = zip(*table, strict=True)
    return float(np.interp(packing_fraction, phis, values))


def shell_ratio(packing_fraction):
    """Default neighbour-shell diameter r_n in units of the contact distance σ."""
    return _interpolate(SHELL_TABLE, packing_fraction)


def shell_lead(packing_fraction):
    """Default lead λ of a new shell's centre ahead of its disk, in shell radii δ."""
    return _interpolate(LEAD_TABLE, packing_fraction)


#: Disks per bin, on average, of :func:`packing_fraction_around_disks`.
DISKS_PER_BIN = 32


def packing_fraction_around_disks(position, radius, box):
    """The packing fraction a typical disk sees: the box cut into about N / DISKS_PER_BIN
    bins, each bin's covered fraction Σ π R²/A_bin (disks counted at their centres) weighted
    by its number of disks.

    For a gas filling the box this is the box's φ, raised by the relative variance of the
    counts per bin (at most 1/DISKS_PER_BIN for an ideal gas, 0.4 % for hard disks at
    φ = 0.5); for a bed filling part of the box (the crater) it is the bed's φ, not the
    box's. Shells and list capacities sized by it: the crater bed of
    ``benchmarks/engine_rate.py`` (φ = 0.25 in the box, 0.49 in the bed) gets shells of
    2.04 σ instead of 3.06 σ and lists of 24 instead of 48 (grown from 24 as they
    overflowed), and ran 1.1–1.3× faster, with the projectile in 1.5–2.7× (both shells run
    side by side, three pairs of runs). Fewer than 64 disks: the box's φ.

    position float64[n, 2], radius float64[n], box (Lx, Ly): same length unit.
    """
    n = len(radius)
    bins = max(1, n // DISKS_PER_BIN)
    nx = max(1, round(math.sqrt(bins * box[0] / box[1])))
    ny = max(1, bins // nx)
    edges = (np.linspace(0.0, box[0], nx + 1), np.linspace(0.0, box[1], ny + 1))
    x = np.clip(position[:, 0], 0.0, box[0])
    y = np.clip(position[:, 1], 0.0, box[1])
    count, _, _ = np.histogram2d(x, y, bins=edges)
    covered, _, _ = np.histogram2d(x, y, bins=edges, weights=np.pi * radius**2)
    bin_area = box[0] * box[1] / (nx * ny)
    return float(np.sum(count * covered) / (bin_area * n))


def _first(mask):
    """Index of the first True entry of the bool array ``mask``, or None."""
    bad = np.flatnonzero(mask)
    return int(bad[0]) if bad.size else None


def _check_disks(position, velocity, radius, mass, species):
    """Refuse non-finite positions and velocities (n, 2), radii and masses (n,) that are not
    finite and > 0, and negative species, naming the first disk at fault."""
    for name, values in (("radius", radius), ("mass", mass)):
        bad = _first(~((values > 0.0) & (values < math.inf)))
        if bad is not None:
            raise ValueError(f"disk {bad} has {name} {values[bad]}: a {name} must be finite "
                             f"and > 0")
    for name, values in (("position", position), ("velocity", velocity)):
        bad = _first(~np.isfinite(values.ravel()))
        if bad is not None:
            raise ValueError(f"disk {bad // 2} has {name} {values[bad // 2].tolist()}: "
                             f"positions and velocities must be finite")
    bad = _first(species < 0)
    if bad is not None:
        raise ValueError(f"disk {bad} has species {species[bad]}: species are integers ≥ 0")


def _box_size(boundary):
    """The box sides float64[2] of a :class:`Boundary`, refused unless finite and > 0."""
    box = np.array(boundary.size, dtype=np.float64).reshape(-1)
    if box.shape != (2,) or not np.all((box > 0.0) & (box < math.inf)):
        raise ValueError(f"box size must be two finite sides > 0, got {boundary.size}")
    return box


def _check_inside(given, position, radius, box, periodic):
    """Refuse a disk reaching beyond a wall (R ≤ x ≤ L − R on a walled axis), naming the
    first; ``given`` are the positions as the caller gave them, ``position`` wrapped."""
    for axis in range(2):
        if not periodic[axis]:
            bad = _first((position[:, axis] - radius < 0.0)
                         | (position[:, axis] + radius > box[axis]))
            if bad is not None:
                raise ValueError(f"disk {bad} at {given[bad].tolist()} with radius "
                                 f"{radius[bad]} pokes through a wall of the box "
                                 f"{box.tolist()}: along a walled axis of side L a disk of "
                                 f"radius R needs R ≤ x ≤ L − R")


def _wall_specs(walls, periodic):
    """``walls`` as :class:`Engine` takes them (name → {key: value}), checked and keyed by
    wall number (:mod:`sim.effects.walls`); walls without an entry stay hard and still."""
    walls = {} if walls is None else dict(walls)
    for name, spec in walls.items():
        if name not in WALLS:
            raise ValueError(f"unknown wall {name!r}: use {', '.join(WALLS)}")
        unknown = sorted(set(spec or {}) - set(WALL_KEYS))
        if unknown:
            raise ValueError(f"{name} wall: unknown keys {unknown}, use {', '.join(WALL_KEYS)}")
        if spec and periodic[WALLS[name] >> 1]:
            raise ValueError(f"{name} wall is given on a periodic axis, which has no walls")
    return {WALLS[name]: dict(spec) for name, spec in walls.items() if spec}


#: float64 squares and multiplies the scales of a scene in its roots, impulses and energies:
#: each length (box sides, radii), speed (the fastest disk, |U| + A ω of a wall, √(|g| L) of
#: gravity, √(T_w/m) of a thermal wall) and mass must lie in [1/SCALE_LIMIT, SCALE_LIMIT], so
#: that their squares and products keep far inside its normal range (1e-308 … 1e308).
SCALE_LIMIT = 1e60

#: The smallest radius must be at least this fraction of the far edge D of the disks (the
#: largest x + R or y + R, the side of a periodic axis): coordinates near D are resolved to
#: 2⁻⁵² D, and the contacts of smaller disks could not be located to 2⁻¹² of their radius.
RESOLUTION_LIMIT = 2.0**-40


def _check_scales(box, radius, mass, velocity, extent, gravity, motion, temperature):
    """Refuse a scene that float64 cannot hold (:data:`SCALE_LIMIT`, :data:`RESOLUTION_LIMIT`),
    naming the parameter at fault. box (Lx, Ly), radius, mass (n,), velocity (n, 2),
    ``extent`` the far edge of the disks; gravity, motion, temperature as :class:`Engine`
    keeps them."""
    def check(name, value):
        if not 1.0 / SCALE_LIMIT <= value <= SCALE_LIMIT:
            raise ValueError(f"{name} is {value:.3g}: it must lie in [{1.0 / SCALE_LIMIT:g}, "
                             f"{SCALE_LIMIT:g}], as float64 squares and multiplies the lengths, "
                             f"speeds and masses of a scene")

    for axis in range(2):
        check(f"the box side along {'xy'[axis]}", box[axis])
    for name, values in (("radius", radius), ("mass", mass)):
        for i in (int(np.argmin(values)), int(np.argmax(values))):
            check(f"the {name} of disk {i}", values[i])
    with np.errstate(over="ignore"):
        fastest = int(np.argmax(np.einsum("ij,ij->i", velocity, velocity)))
    speed = float(np.hypot(*velocity[fastest]))
    # disks at rest set no speed scale, and slower ones only relative speeds, which may be tiny
    if speed > 0.0:
        check(f"the speed of disk {fastest}", speed)
    if gravity is not None:
        check("√(|g| L), the speed of a fall across the box,",
              math.sqrt(float(np.hypot(*gravity)) * float(np.max(box))))
    for wall in range(4):
        if motion is not None and np.any(motion[wall, :2]):
            check(f"the speed |U| + A ω of the {WALL_NAMES[wall]} wall",
                  abs(motion[wall, 0]) + motion[wall, 1] * motion[wall, 2])
        if temperature is not None and not math.isnan(temperature[wall]):
            for m in (mass.min(), mass.max()):
                check(f"√(T_w / m) of the {WALL_NAMES[wall]} wall for mass {m:g}",
                      math.sqrt(temperature[wall] / m))
    i = int(np.argmin(radius))
    if radius[i] < RESOLUTION_LIMIT * extent:
        raise ValueError(f"the radius of disk {i} is {radius[i]:.3g}, less than 2**-40 of the "
                         f"far edge of the disks ({extent:.3g}; the largest x + R or y + R, the "
                         f"side of a periodic axis): float64 coordinates there cannot resolve "
                         f"its contacts; radii must be at least {RESOLUTION_LIMIT * extent:.3g}")


def _seed(seed):
    """The thermal walls' seed as the compiled generator takes it (int64 ≥ 0)."""
    try:
        value = operator.index(seed)
    except TypeError:
        value = None
    if value is None or not 0 <= value <= np.iinfo(np.int64).max:
        raise ValueError(f"seed must be an integer in [0, 2**63 - 1], got {seed!r}")
    return value


class Engine:
    """Event-driven hard disks in a rectangular box.

    Parameters
    ----------
    position, velocity : array (n, 2)
    radius, mass : array (n,) or scalar
    species : int array (n,), default all 0
    boundary : :class:`Boundary`
    restitution : scalar or (s, s) normal restitution ξ per species pair; 1 = elastic
    wall_restitution : ξ_w for every wall; 1 = elastic
    tc : TC-model time t_c (None or 0 = off)
    shell : neighbour-shell diameter r_n/σ (default from the packing fraction around the
        disks, :func:`packing_fraction_around_disks`)
    shell_lead : λ in [0, 1): a new shell is centred λ δ ahead of its disk along its
        velocity (:func:`sim.engine.neighbours.shell_centre`; default from the same packing
        fraction, :data:`LEAD_TABLE`); changes the cost, never the physics
    list_capacity : initial slots per neighbour list of an ordinary disk (default from the
        expected number of neighbours); full lists grow on demand
    gravity : [gx, gy] uniform acceleration (:mod:`sim.effects.gravity`); None or zero = off
    walls : {"left" | "right" | "bottom" | "top": {"temperature": T_w, "speed": U,
        "amplitude": A, "frequency": ω}} — thermal, moving and vibrating walls
        (:mod:`sim.effects.walls`); absent keys keep the wall hard and still
    seed : keys the random draws of thermal walls (same seed, same bits)
    unwrap : count periodic windings, for :meth:`unwrapped_positions` (mean squared
        displacements)
    pressure_tensor : accumulate the collision virial tensor Σ r_a Δp_b
        (:attr:`virial_tensor`)
    event_log : rows buffered in the loop for the log of every contact; None = no log. Full
        buffers go to :attr:`event_sink` (a callable taking float64[k, 6], e.g. the run
        file's writer) or else are kept for :meth:`take_event_log`
    collapse_interval, collapse_streak : inelastic-collapse detector: more than
        ``collapse_streak`` consecutive dissipative contacts of one disk, each within
        ``collapse_interval`` of the previous one. The default interval is 1e-6 of the time
        a disk at the initial rms speed takes to cross its own diameter; in a gas, even a
        dense one, a run of ten such intervals is far too unlikely ever to be seen, while a
        collapsing cluster shrinks its intervals geometrically through that scale
    """

    def __init__(self, position, velocity, radius, mass=1.0, species=None,
                 boundary=Boundary(), restitution=None, wall_restitution=None, tc=None,
                 gravity=None, walls=None, seed=0, unwrap=False, pressure_tensor=False,
                 event_log=None, shell=None, collapse_interval=None, collapse_streak=10,
                 list_capacity=None, shell_lead=None):
        position = np.array(position, dtype=np.float64, order="C")
        velocity = np.array(velocity, dtype=np.float64, order="C")
        n = position.shape[0]
        if position.shape != (n, 2) or velocity.shape != (n, 2) or n == 0:
            raise ValueError(f"position and velocity must both be (n, 2) with n ≥ 1; got "
                             f"{position.shape} and {velocity.shape}")
        radius = np.array(np.broadcast_to(np.asarray(radius, np.float64), (n,)))
        mass = np.array(np.broadcast_to(np.asarray(mass, np.float64), (n,)))
        species = (np.zeros(n, np.int32) if species is None
                   else np.array(np.broadcast_to(np.asarray(species), (n,)), dtype=np.int32))
        _check_disks(position, velocity, radius, mass, species)
        box = _box_size(boundary)
        periodic = np.array(boundary.periodic, dtype=bool)
        self.boundary = boundary
        self.n = n
        self.n_species = int(species.max()) + 1
        self.box = box
        self.periodic = periodic
        given = position
        position = np.where(periodic, position % box, position)
        _check_inside(given, position, radius, box, periodic)

        self.restitution = restitution_matrix(restitution, self.n_species)
        self.wall_restitution = wall_restitution_value(wall_restitution)
        dissipative = self.restitution is not None or self.wall_restitution is not None
        self.tc = tc_time(tc, dissipative)
        self.gravity = gravity_vector(gravity)
        if self.gravity is not None and np.any(self.gravity[periodic] != 0.0):
            raise ValueError(f"gravity {self.gravity.tolist()} has a component along a periodic "
                             f"axis, where nothing stops the fall; give it walls")
        by_number = _wall_specs(walls, periodic)
        self.wall_motion = wall_motion(by_number)
        self.wall_temperature = wall_temperature(by_number)
        self.seed = _seed(seed)
        # the far edge of the disks, whose ulps bound those of their coordinates (a disk
        # crossing a periodic axis reappears near its far side)
        extent = max(float(box[axis]) if periodic[axis]
                     else float(np.max(position[:, axis] + radius)) for axis in range(2))
        _check_scales(box, radius, mass, velocity, extent, self.gravity, self.wall_motion,
                      self.wall_temperature)
        overlap = first_overlap(position, radius, box, periodic)
        if overlap is not None:
            i, j, distance = overlap
            raise ValueError(f"disk {i} at {given[i].tolist()} overlaps disk {j} (distance "
                             f"{distance:.6g} < contact distance {radius[i] + radius[j]:.6g}): "
                             f"disks may touch but not overlap")
        self.closing_time = _closing_time(self.wall_motion, box, periodic, float(radius.max()))

        self.radius = radius
        self.mass = mass
        self.species = species
        self.counters = np.zeros(loop.N_COUNTERS, dtype=np.int64)
        self.accumulators = np.zeros(loop.N_ACCUMULATORS)
        self.pair_collisions = np.zeros((self.n_species, self.n_species), dtype=np.int64)
        self.wall_impulse = np.zeros(4)
        self.virial_tensor = np.zeros(3) if pressure_tensor else None
        self.event_log = (None if event_log is None
                          else np.zeros((max(int(event_log), 1), LOG_COLUMNS)))
        self.log_fill = np.zeros(1, dtype=np.int64)
        self._logged = []
        self.event_sink = None
        self.initial_energy = float(np.sum(0.5 * mass * np.sum(velocity**2, axis=1)))
        self.rebase_every = 16 * n + 1024
        self.reorder_every = (REORDER_EVENTS_PER_DISK * n if n >= REORDER_MIN_DISKS
                              else np.iinfo(np.int64).max)
        self.lookahead = n >= LOOKAHEAD_MIN_DISKS

        v_rms = math.sqrt(2.0 * self.initial_energy / mass.sum()) if self.initial_energy else 1.0
        crossing_time = 2.0 * float(np.median(radius)) / v_rms
        self.collapse_interval = (1e-6 * crossing_time if collapse_interval is None
                                  else float(collapse_interval))
        self.collapse_streak = int(collapse_streak)
        self.stall_dt = stall_interval(min(extent, STALL_RADII * float(radius.min())), box,
                                       self.initial_energy, mass, self.gravity,
                                       self.wall_motion, self.wall_temperature)
        self.stall_watch = np.array([-math.inf, 0.0])
        self._build(position, velocity, shell, shell_lead, list_capacity, unwrap,
                    first_event_time(box, velocity, self.gravity, self.wall_motion))

    # -- construction ---------------------------------------------------------------------
    def _build(self, position, velocity, shell, lead, list_capacity, unwrap, first_event):
        """Size shells and cells, allocate the state, link neighbours, schedule events;
        ``first_event``: :func:`first_event_time`."""
        n, radius, box = self.n, self.radius, self.box
        median = float(np.median(radius))
        big = np.flatnonzero(radius > BIG_RADIUS_RATIO * median)
        if big.size > MAX_BIG:
            big = big[:0]
        is_big = np.zeros(n, dtype=bool)
        is_big[big] = True
        small_radius = radius[~is_big]
        phi = float(np.pi * np.sum(radius**2) / np.prod(box))
        # shells and lists concern the small disks, where they are
        phi_small = packing_fraction_around_disks(position[~is_big], small_radius, box)
        ratio = shell_ratio(phi_small) if shell is None else float(shell)
        if ratio <= 1.0:
            raise ValueError(f"shell (r_n/σ) must exceed 1, got {ratio}")
        lead = shell_lead(phi_small) if lead is None else float(lead)
        if not 0.0 <= lead < 1.0:
            raise ValueError(f"shell_lead must lie in [0, 1), got {lead}")
        delta_small = 0.5 * (ratio - 1.0) * 2.0 * median
        max_small = float(small_radius.max())
        # the two largest radii: two disks whose shells overlap are less than R_i + R_j + 4 δ
        # apart (shell centres within R_i + δ + R_j + δ, each disk within δ of its centre)
        r_2, r_1 = (np.sort(radius)[-2:] if n > 1 else (0.0, radius[0]))
        for axis in range(2):
            if self.periodic[axis]:
                # predictions take the nearest image of a separation: that is the image in
                # which the pair can touch only while R_1 + R_2 + 4 δ ≤ L/2
                limit = 0.25 * (0.5 * box[axis] - r_1 - r_2)
                if limit <= 0.0:
                    raise ValueError(f"periodic box side {box[axis]} is too small for disks of "
                                     f"radii {r_1:g} and {r_2:g}: it must exceed "
                                     f"2 (R_1 + R_2) = {2.0 * (r_1 + r_2):g}")
                delta_small = min(delta_small, limit)
        delta = np.full(n, delta_small)
        reach = max_small + delta_small
        cells = grid_cells(box, 2.0 * reach, cell_limit(n))
        self.geometry = np.array([box[0], box[1], box[0] / cells[0], box[1] / cells[1], reach,
                                  lead])
        self.grid = np.array([cells[0], cells[1], int(self.periodic[0]), int(self.periodic[1])],
                             dtype=np.int64)
        # list capacity: the expected number of overlapping shells, 4 φ (1 + δ/R)², plus three
        # standard deviations of its (at most Poisson) fluctuations and a margin; the rare
        # list that overflows grows on demand
        expected = 4.0 * phi_small * (1.0 + delta_small / median) ** 2
        if list_capacity is None:
            list_capacity = int(4 * math.ceil((expected + 3.0 * math.sqrt(expected) + 4.0) / 4))
        cap = np.full(n, max(int(list_capacity), 1), dtype=np.int32)
        if big.size:
            density = max(phi_small, 0.6) / (np.pi * median**2)
            reach_big = radius[big] + delta[big] + reach
            cap[big] = (2.0 * density * np.pi * reach_big**2 + 16).astype(np.int32)
        self.disks = self._initial_state(position, velocity, radius, delta, is_big, big, cap,
                                         int(cells[0] * cells[1]), unwrap)
        self.packing_fraction = phi
        d = self.disks
        # per-disk values every disk shares (None where they differ): the compiled code gets
        # the number, and never loads the array (sim.engine.parameters); delta, mass and species
        # never change, the list capacity only when the lists grow
        self._common = {name: common_value(getattr(d, name))
                        for name in ("delta", "mass", "species")}
        self._common_capacity = common_value(d.nb_cap)
        shell_radius = self._per_disk_parameters()[0]
        while True:
            full = build_all_neighbours(d.table, shell_radius, d.is_big, *self._list_layout(),
                                        d.nb_count, d.nb, d.cell_head, d.cell_next,
                                        d.cell_prev, d.cell_of, d.big, self.geometry, self.grid,
                                        self.lookahead)
            if full < 0:
                break
            self._grow_lists(full)
        # first predictions: every disk queued at t = 0 and predicted by the event loop itself
        # (with the argument types of every later call) in a call that may apply no event;
        # then the queue is sized for the predicted events. Until then its blocks are sized
        # for the scene's first events (:func:`first_event_time`): a width of one time unit
        # would put the earliest prediction of disks slow against their box beyond the int64
        # blocks the queue's years reach, and the queue would look for it for ever. A contact
        # due at once (τ = 0) ends the call early, at the head of the queue: the other disks
        # are then predicted in the first run, in this queue, until the clock's first rebase
        # sizes it anew.
        d.event_time[:] = 0.0
        d.event_partner[:] = loop.UNPREDICTED
        build_queue(*d.queue, d.event_time, 0.0)
        d.block_rate[0] = n / (BLOCK_EVENTS * first_event)
        self._run_chunk(0, 0, 0, 0.0, np.inf)
        if not np.any(d.event_partner == loop.UNPREDICTED):
            build_queue(*d.queue, d.event_time, 0.0)
        self.stall_watch[:] = (-math.inf, 0.0)  # the first predictions, all at t = 0, are no run
        if n >= REORDER_MIN_DISKS:
            self.reorder()

    def _initial_state(self, position, velocity, radius, delta, is_big, big, cap, n_cells,
                       unwrap):
        """The state arrays before any list is built or event predicted (:mod:`sim.engine.state`);
        its own function, so that the arrays it makes are freed once they are copied into
        the state's buffer."""
        n = self.n
        minus_one = np.full(n, -1, dtype=np.int32)
        heap, links, list_head, calendar, block_rate = empty_queue(n)
        table = np.zeros((n, DISK_COLUMNS))
        table[:, X:Y + 1] = position
        table[:, VX:VY + 1] = velocity
        table[:, RADIUS] = radius
        return DiskArrays(
            table=table, delta=delta, mass=self.mass.copy(), species=self.species.copy(),
            is_big=is_big, coll_count=np.zeros(n, np.int32), contacts=np.zeros(n, np.int64),
            t_last=np.full(n, -np.inf),
            streak=np.zeros(n, np.int32), event_time=np.empty(n),
            event_partner=np.empty(n, np.int32), event_count=np.zeros(n, np.int32),
            links=links, nb_start=list_starts(cap), nb_cap=cap, nb_count=np.zeros(n, np.int32),
            cell_next=minus_one.copy(), cell_prev=minus_one.copy(), cell_of=minus_one.copy(),
            order=np.arange(n, dtype=np.int32), nb=np.full(int(cap.sum()), -1, dtype=np.int32),
            heap=heap, list_head=list_head, calendar=calendar, block_rate=block_rate,
            big=big.astype(np.int32),
            cell_head=np.full(n_cells, -1, dtype=np.int32),
            images=np.zeros((n, 2), dtype=np.int32) if unwrap else None)

    def _effects(self):
        """The scene's effects as the compiled loop takes them (:class:`sim.effects.Effects`)."""
        dissipative = self.restitution is not None or self.wall_restitution is not None
        return Effects(
            restitution=self.restitution, wall_restitution=self.wall_restitution,
            collapse=(CollapseWatch(self.collapse_interval, self.collapse_streak)
                      if dissipative else None),
            tc=self.tc, gravity=self.gravity, wall_motion=self.wall_motion,
            wall_temperature=self.wall_temperature, seed=self.seed, images=self.disks.images,
            virial_tensor=self.virial_tensor,
            event_log=None if self.event_log is None else (self.event_log, self.log_fill))

    def _per_disk_parameters(self):
        """Shell radius, mass and species as the compiled loop takes them: the number every
        disk shares, else the array (:func:`sim.engine.parameters.per_disk`)."""
        return tuple(getattr(self.disks, name) if value is None else value
                     for name, value in self._common.items())

    def _list_layout(self):
        """``nb_start, nb_cap`` as the compiled code takes them: the capacity every list
        shares, twice (a list then starts at i × capacity,
        :func:`sim.engine.neighbours.list_start`), else both arrays."""
        if self._common_capacity is None:
            return self.disks.nb_start, self.disks.nb_cap
        return self._common_capacity, self._common_capacity

    def _grow_lists(self, full):
        """Enlarge the lists after ``full`` overflowed. Lists of one common capacity all grow
        by LIST_GROWTH entries, so that they stay alike (the loop's fast layout, see
        :func:`sim.engine.neighbours.list_start`); otherwise every full list doubles."""
        d = self.disks
        if self._common_capacity is None:
            new_cap = d.nb_cap.copy()
            new_cap[np.union1d([full], np.flatnonzero(d.nb_count >= d.nb_cap))] *= 2
        else:
            new_cap = d.nb_cap + np.int32(LIST_GROWTH)
        d.nb_start, d.nb = grow_lists(d.nb_start, d.nb_count, d.nb, new_cap)
        d.nb_cap = new_cap
        d.pack()
        self._common_capacity = common_value(d.nb_cap)

    def reorder(self):
        """Renumber disks in row order of their grid cells (big disks last) for locality."""
        cell = self.disks.cell_of.astype(np.int64)
        cell[cell < 0] = self.disks.cell_head.size
        self.disks.permute(np.argsort(cell, kind="stable"))

    # -- running --------------------------------------------------------------------------
    def _run_chunk(self, max_events, max_contacts, max_collisions, t_stop, dissipation_limit):
        while True:
            d = self.disks
            reorder_at = (self.counters[loop.EVENTS] // self.reorder_every + 1) * self.reorder_every
            status, disk = loop.run_events(
                Disks(d.table, *self._per_disk_parameters(), d.coll_count, d.contacts,
                      d.t_last, d.streak),
                Schedule(d.event_time, d.event_partner, d.event_count, *d.queue),
                Neighbours(*self._list_layout(), d.nb_count, d.nb, d.cell_head, d.cell_next,
                           d.cell_prev, d.cell_of, d.big),
                Box(self.geometry, self.grid),
                self._effects(),
                Tallies(self.counters, self.accumulators, self.pair_collisions,
                        self.wall_impulse, self.stall_watch),
                Limits(min(max_events, reorder_at), max_contacts, max_collisions, t_stop,
                       dissipation_limit, self.stall_dt, self.rebase_every, self.lookahead))
            self.drain_event_log()
            if status == loop.STATUS_LOG_FULL:
                continue
            if status == loop.STATUS_EVENT_LIMIT and self.counters[loop.EVENTS] == reorder_at:
                self.reorder()
                if reorder_at < max_events:
                    continue
            if status == loop.STATUS_LIST_FULL:
                self._grow_lists(disk)
                continue
            if status == loop.STATUS_STALLED:
                self._check_piston()  # a jammed piston stalls the clock too: say so
                raise StalledError(
                    f"the clock has stalled at t = {self.time:.17g}: more than 16 N + 1000 "
                    f"events in a row, each within {self.stall_dt:.3g} (float64 resolution) of "
                    f"the one before, last for disk {d.order[disk]} at position "
                    f"{d.table[disk, X:Y + 1].tolist()} with velocity "
                    f"{d.table[disk, VX:VY + 1].tolist()}; the state is beyond float64 "
                    f"resolution: for inelastic disks, and for disks resting on a wall under "
                    f"gravity, switch on the TC model (tc.time); a chain of disks touching all "
                    f"round a periodic box needs room between its disks")
            if status == loop.STATUS_COLLAPSE:
                cluster = set(np.flatnonzero(d.streak >= 2).tolist()) | {int(disk)}
                raise InelasticCollapseError(sorted(int(d.order[k]) for k in cluster),
                                             self.time, self.collisions)
            return status

    def run(self, *, events=None, collisions=None, time=None, energy_fraction=None,
            wall_seconds=None, until=None, chunk_events=200_000):
        """Advance until the first stop condition holds; returns its name.

        events : disk and wall contacts since the start of the engine
        collisions : disk–disk contacts since the start of the engine
        time : absolute simulated time; the run stops at the last event not after it
        energy_fraction : stop once the kinetic energy is this fraction of the initial one
        wall_seconds : wall-clock budget of this call, checked between chunks, which are then
            sized to take about :data:`TIMED_CHUNK_SECONDS` each (from the rate of the chunk
            before; the first has :data:`TIMED_FIRST_CHUNK` events)
        until : predicate ``until(engine) -> bool`` asked every ``chunk_events`` events from
            the start of the call, whatever the chunks a wall budget makes: the same inputs
            stop at the same event
        chunk_events : events per compiled call (the most, with ``wall_seconds``)

        The piston-jam guard (:meth:`_check_piston`) runs after every chunk, whatever ended
        it. Chunk sizes change no result: the same inputs give the same bits.
        """
        if all(x is None for x in (events, collisions, time, energy_fraction, wall_seconds,
                                   until)):
            raise ValueError("run() needs at least one stop condition")
        big = np.iinfo(np.int64).max
        max_contacts = big if events is None else int(events)
        max_collisions = big if collisions is None else int(collisions)
        t_stop = math.inf if time is None else float(time)
        closing = t_stop > self.closing_time
        t_stop = min(t_stop, self.closing_time)
        dissipation_limit = (math.inf if energy_fraction is None
                             else self.initial_energy * (1.0 - float(energy_fraction)))
        started = wallclock.perf_counter()
        reasons = {loop.STATUS_COLLISION_LIMIT: "collisions", loop.STATUS_CONTACT_LIMIT: "events",
                   loop.STATUS_TIME_REACHED: "time",
                   loop.STATUS_ENERGY_REACHED: "energy_fraction",
                   loop.STATUS_NO_EVENTS: "no_events"}
        chunk = int(chunk_events) if wall_seconds is None else min(int(chunk_events),
                                                                   TIMED_FIRST_CHUNK)
        ask_at = self.steps + int(chunk_events)  # where ``until`` is asked next
        while True:
            chunk_started = wallclock.perf_counter()
            steps = self.steps
            status = self._run_chunk(min(steps + chunk, ask_at), max_contacts, max_collisions,
                                     t_stop, dissipation_limit)
            self._check_piston()
            if status != loop.STATUS_EVENT_LIMIT:
                if closing and status == loop.STATUS_TIME_REACHED:
                    raise ClosedBoxError(
                        f"at t = {self.closing_time:.6g} the moving walls come within the "
                        f"largest disk diameter ({2 * self.radius.max():.6g}) of the opposite "
                        f"wall: stop the run earlier (stop.time) or slow the piston")
                return reasons[status]
            if wall_seconds is not None:
                now = wallclock.perf_counter()
                if now - started >= wall_seconds:
                    return "wall_seconds"
                rate = (self.steps - steps) / max(now - chunk_started, 1e-6)
                chunk = int(np.clip(rate * TIMED_CHUNK_SECONDS, TIMED_MIN_CHUNK, chunk_events))
            if self.steps >= ask_at:
                ask_at += int(chunk_events)
                if until is not None and until(self):
                    return "predicate"

    def _check_piston(self):
        """Raise :class:`ClosedBoxError` when a piston has jammed the disks (see
        :data:`PISTON_ENERGY_LIMIT`); checked after every chunk, so within one chunk of the
        jam."""
        if self.wall_motion is None or not np.any(self.wall_motion[:, 0]):
            return
        speed = float(np.abs(self.wall_motion[:, 0]).max())
        scale = max(self.initial_energy, float(self.mass.sum()) * speed**2)
        energy = self.kinetic_energy()
        if energy > PISTON_ENERGY_LIMIT * scale:
            raise ClosedBoxError(
                f"at t = {self.time:.6g} the piston has jammed the disks: their kinetic energy "
                f"{energy:.3g} is {energy / scale:.3g} times max(initial energy, N m U²), and "
                f"a wall driven at constant speed makes it diverge; stop the run earlier "
                f"(stop.time) or slow the piston")

    # -- observables ----------------------------------------------------------------------
    @property
    def time(self):
        """Absolute time of the last processed event."""
        return float(self.accumulators[loop.T_ORIGIN] + self.accumulators[loop.T_NOW])

    @property
    def collisions(self):
        return int(self.counters[loop.COLLISIONS])

    @property
    def wall_collisions(self):
        return int(self.counters[loop.WALL_CONTACTS])

    @property
    def events(self):
        """Disk–disk and disk–wall contacts so far."""
        return self.collisions + self.wall_collisions

    @property
    def steps(self):
        """Events the engine applied: contacts and neighbour-shell exits."""
        return int(self.counters[loop.EVENTS])

    @property
    def dissipated_energy(self):
        return float(self.accumulators[loop.DISSIPATED_DISKS]
                     + self.accumulators[loop.DISSIPATED_WALLS])

    @property
    def virial(self):
        """Σ r_ij·Δp_i over all disk–disk contacts so far."""
        return float(self.accumulators[loop.VIRIAL])

    # -- checkpoints ----------------------------------------------------------------------
    def state_dict(self):
        """Every array that evolves, by name: restoring it into an engine built from the same
        inputs continues the run to the same bits."""
        loop.count_all_contacts(self.disks.coll_count, self.disks.contacts)
        self.drain_event_log()
        state = {f"disks/{name}": value for name, value in vars(self.disks).items()
                 if value is not None}
        state.update(counters=self.counters, accumulators=self.accumulators,
                     pair_collisions=self.pair_collisions, wall_impulse=self.wall_impulse,
                     initial_energy=np.array(self.initial_energy))
        if self.virial_tensor is not None:
            state["virial_tensor"] = self.virial_tensor
        return state

    def load_state_dict(self, state):
        """Replace the evolving arrays by those of :meth:`state_dict` (copied). A state of
        another scene — other arrays, or arrays of other shapes than this engine's (the
        neighbour lists ``disks/nb`` aside, which grow) — is refused with a ValueError before
        anything is replaced."""
        mine = {key: np.shape(value) for key, value in self.state_dict().items()}
        missing, unknown = sorted(set(mine) - set(state)), sorted(set(state) - set(mine))
        if missing or unknown:
            raise ValueError(f"the checkpoint is not one of this scene's engine: arrays "
                             f"missing {missing}, unknown {unknown}")
        for key, value in state.items():
            if key != "disks/nb" and np.shape(value) != mine[key]:
                raise ValueError(f"the checkpoint's {key} has shape {np.shape(value)}, this "
                                 f"scene's engine {mine[key]}")
        for key, value in state.items():
            value = np.array(value)
            if key.startswith("disks/"):
                setattr(self.disks, key.removeprefix("disks/"), value)
            elif key == "initial_energy":
                self.initial_energy = float(value)
            else:
                setattr(self, key, value)
        self._common_capacity = common_value(self.disks.nb_cap)
        self.stall_watch[:] = (-math.inf, 0.0)  # its times ran on the clock it replaced

    def _user_order(self, values):
        out = np.empty_like(values)
        out[self.disks.order] = values
        return out

    def _relative_time(self, t):
        return (self.accumulators[loop.T_NOW] if t is None
                else float(t) - self.accumulators[loop.T_ORIGIN])

    def _state(self, t):
        return loop.state_at(self._relative_time(t), self.disks.table, self.geometry,
                             self.grid, self.gravity)

    def positions(self, t=None):
        """Positions float64[n, 2] of every disk at absolute time ``t`` (default: the time of
        the last event); ``t`` must not precede the last event."""
        return self._user_order(self._state(t)[0])

    def velocities(self, t=None):
        """Velocities float64[n, 2] at absolute time ``t`` (default: the last event); they
        change between events only under gravity."""
        return self._user_order(self._state(t)[1])

    def unwrapped_positions(self, t=None):
        """Positions float64[n, 2] at time ``t`` continued across periodic boundaries
        (r + windings · L), for mean squared displacements; needs ``unwrap=True``."""
        if self.disks.images is None:
            raise ValueError("unwrapped positions need an engine made with unwrap=True")
        d = self.disks
        dt = (self._relative_time(t) - d.table[:, T_OWN])[:, None]
        acceleration = 0.0 if self.gravity is None else self.gravity
        flown = (d.table[:, VX:VY + 1] + 0.5 * acceleration * dt) * dt
        return self._user_order(d.table[:, X:Y + 1] + d.images * self.box + flown)

    def wall_positions(self, t=None):
        """Positions float64[4] of the walls (left, right, bottom, top) at absolute time t."""
        t_abs = self.time if t is None else float(t)
        return np.array([wall_state(self.wall_motion, w, t_abs, self.geometry)[0]
                         for w in range(4)])

    def collisions_by_disk(self):
        """Contacts (disk and wall) of each disk so far: int64[n]."""
        loop.count_all_contacts(self.disks.coll_count, self.disks.contacts)
        return self._user_order(self.disks.contacts)

    def next_event_time(self):
        """Absolute time of the next scheduled event (possibly stale)."""
        d = self.disks
        return float(d.event_time.min() + self.accumulators[loop.T_ORIGIN])

    def kinetic_energy_by_species(self, t=None):
        """Σ m v²/2 per species at time t: float64[n_species]."""
        d = self.disks
        energy = 0.5 * d.mass * np.sum(self._state(t)[1] ** 2, axis=1)
        return np.bincount(d.species, weights=energy, minlength=self.n_species)

    def kinetic_energy(self, t=None):
        """Σ m v²/2 at time t (default: the last event)."""
        d = self.disks
        return float(np.sum(0.5 * d.mass * np.sum(self._state(t)[1] ** 2, axis=1)))

    def potential_energy(self, t=None):
        """Σ −m g·r at time t (zero without gravity)."""
        return potential_energy(self._state(t)[0], self.disks.mass, self.gravity)

    @property
    def wall_work(self):
        """Work done on the disks by moving and thermal walls so far."""
        return float(self.accumulators[loop.WALL_WORK])

    def momentum(self, t=None):
        d = self.disks
        return (d.mass[:, None] * self._state(t)[1]).sum(axis=0)

    # -- event log ------------------------------------------------------------------------
    def drain_event_log(self):
        """Hand the rows of the compiled log to :attr:`event_sink` (else keep them for
        :meth:`take_event_log`), disks renamed to the user's numbering (the engine's own
        numbering changes when it reorders)."""
        if self.event_log is None or self.log_fill[0] == 0:
            return
        rows = self.event_log[:self.log_fill[0]].copy()
        order = self.disks.order
        rows[:, LOG_DISK] = order[rows[:, LOG_DISK].astype(np.int64)]
        partner = rows[:, LOG_PARTNER].astype(np.int64)
        disk = partner >= 0
        rows[disk, LOG_PARTNER] = order[partner[disk]]
        self.log_fill[0] = 0
        if self.event_sink is None:
            self._logged.append(rows)
        else:
            self.event_sink(rows)

    def take_event_log(self):
        """The contacts logged since the last call: float64[k, 6], columns as in
        :mod:`sim.effects.event_log` (disks in the user's numbering)."""
        self.drain_event_log()
        rows = (np.concatenate(self._logged) if self._logged
                else np.zeros((0, LOG_COLUMNS)))
        self._logged = []
        return rows
