"""How the engine sizes itself for a scene: neighbour shells and their lead, cells, list
capacities, big disks, when to renumber and prefetch ahead, and the time scales of the stall
guard and of the queue's first year. Sizes change the cost, never the physics."""

import math

import numpy as np

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


def periodic_room(box, periodic, reaches):
    """(room, axis, a_1, a_2): the room δ ≤ room for neighbour shells that the nearest-image
    rule leaves on the periodic axes, its axis (None without one), and the two largest
    reaches a_1 ≥ a_2 of ``reaches`` float64[n]. Predictions take the nearest image of a
    separation, in which a pair can have an event only while a_1 + a_2 + 4 δ ≤ L/2 (two
    disks whose shells overlap are less than a_i + a_j + 4 δ apart: shell centres within
    a_i + δ + a_j + δ, each disk within δ of its centre): room = (L/2 − a_1 − a_2)/4 on the
    shortest periodic side, ∞ without one; at most 0, the box is too small."""
    a_2, a_1 = np.sort(reaches)[-2:] if reaches.size > 1 else (0.0, float(reaches[0]))
    sides = [(float(box[axis]), axis) for axis in range(2) if periodic[axis]]
    if not sides:
        return math.inf, None, a_1, a_2
    side, axis = min(sides)
    return 0.25 * (0.5 * side - a_1 - a_2), axis, a_1, a_2
