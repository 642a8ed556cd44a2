"""Initial states: where the disks start and how fast they go.

* :func:`random_sequential` — random sequential addition (RSA), compiled, with a cell grid for
  the overlap test; equal disks jam near φ ≈ 0.547 (Hinrichsen, Feder & Jøssang,
  J. Stat. Phys. 44, 793 (1986)), so denser packings need :func:`hexagonal_lattice`.
* :func:`hexagonal_lattice` — triangular lattice up to φ = π/(2√3) ≈ 0.907 with a small random
  displacement that never creates an overlap.
* :func:`melted_lattice` — that lattice melted by an elastic run of its own: a random, fluid
  arrangement at packings random addition cannot reach (equal hard disks are fluid below
  φ ≈ 0.70; Bernard & Krauth, Phys. Rev. Lett. 107, 155704 (2011)).
* :func:`compressed` — a random gas compressed to the packing by growing its disks
  (Lubachevsky–Stillinger, :mod:`sim.effects.growth`): random at any density up to
  jamming, with no memory of a lattice, and for any radii.
* :func:`fixed_speed` (equal speeds, random directions) and
  :func:`maxwellian` (components drawn from N(0, T/m)); :func:`remove_drift` zeroes the total
  momentum.

Positions are float64[n, 2] in box units. Every argument is checked before any work, a bad
one a ValueError naming it: ``box`` two finite sides (Lx, Ly) > 0, ``region`` ((x0, x1),
(y0, y1)) inside the box with x0 < x1, y0 < y1 (default: the box), ``periodic`` a bool or a
pair (x, y) of them, ``seed`` a whole number from 0 to 2^64 − 1 (the command line's seed,
at most 2^63 − 1, and the next ones it draws velocities and species with).
"""

import math

import numpy as np
from numba import njit

from sim.effects.values import MAX_DISKS
from sim.engine.inputs import (
    box_sides,
    periodic_pair,
    real_array,
    real_number,
    refused,
    whole_count,
)

RSA_JAMMING = 0.547

#: Largest seed of the helpers here: numpy seeds a generator with any whole number ≥ 0; one
#: 64-bit word holds the command line's seed and the next ones its scenes draw with.
MAX_HELPER_SEED = 2**64 - 1

#: Most attempts :func:`random_sequential` may make to place one disk (a bound on the time a
#: packing it cannot reach takes to be refused).
MAX_ATTEMPTS = 10**9


def _count(call, n):
    """The number of disks ``n`` of ``call``, whole and in [1, MAX_DISKS]."""
    return whole_count(call, "n", n, low=1, high=MAX_DISKS)


def _radii(call, radius):
    """The radii of ``call`` (a number or a 1-D array of one or more) as float64[k], each
    finite and > 0."""
    radii = real_array(call, "radius", radius, lambda r: (r > 0.0) & (r < math.inf),
                       "radii finite and > 0")
    if radii.ndim > 1 or radii.size == 0:
        raise refused(call, "radius", radius, "a radius, or a 1-D array of one or more")
    return np.atleast_1d(radii)


def _lattice_radii(call, n, radius):
    """:func:`_radii` of ``call``, one radius or one for each of the ``n`` disks."""
    radii = _radii(call, radius)
    if radii.size not in (1, n):
        raise refused(call, "radius", radius, f"one radius, or one for each of the n = {n} "
                                              f"disks")
    return radii


def _seed(call, seed):
    """The ``seed`` of ``call`` as an int from 0 to :data:`MAX_HELPER_SEED`."""
    return whole_count(call, "seed", seed, high=MAX_HELPER_SEED)


class PlacementError(ValueError):
    """Disks that cannot be placed as asked: the message names the argument of the call
    (``call(name=…) is not allowed: reason``); ``reason`` alone says why."""

    def __init__(self, call, name, value, reason):
        super().__init__(str(refused(call, name, value, reason)))
        self.reason = reason


@njit(cache=True)
def _rsa(radius, lo, hi, box, periodic, rng, max_attempts):
    n = radius.shape[0]
    position = np.zeros((n, 2))
    # cells of at least one largest diameter; a periodic axis is cut into whole cells of
    # [lo, hi) so that cell indices wrap, a walled one is padded by a radius on each side
    cell = 2.0 * radius.max()
    pad_x = 0.0 if periodic[0] else radius.max()
    pad_y = 0.0 if periodic[1] else radius.max()
    ncx = max(1, int((hi[0] - lo[0] + 2 * pad_x) / cell))
    ncy = max(1, int((hi[1] - lo[1] + 2 * pad_y) / cell))
    wx = (hi[0] - lo[0] + 2 * pad_x) / ncx
    wy = (hi[1] - lo[1] + 2 * pad_y) / ncy
    ox = lo[0] - pad_x
    oy = lo[1] - pad_y
    head = np.full(ncx * ncy, -1, np.int64)
    nxt = np.full(n, -1, np.int64)
    for i in range(n):
        r = radius[i]
        placed = False
        for _ in range(max_attempts):
            x = lo[0] + r + (hi[0] - lo[0] - 2 * r) * rng.random()
            y = lo[1] + r + (hi[1] - lo[1] - 2 * r) * rng.random()
            if periodic[0]:
                x = lo[0] + (hi[0] - lo[0]) * rng.random()
            if periodic[1]:
                y = lo[1] + (hi[1] - lo[1]) * rng.random()
            cx = min(max(int((x - ox) / wx), 0), ncx - 1)
            cy = min(max(int((y - oy) / wy), 0), ncy - 1)
            free = True
            for ay in range(cy - 1, cy + 2):
                if not free:
                    break
                if periodic[1]:
                    ay = ay % ncy
                elif ay < 0 or ay >= ncy:
                    continue
                for ax in range(cx - 1, cx + 2):
                    if periodic[0]:
                        ax = ax % ncx
                    elif ax < 0 or ax >= ncx:
                        continue
                    j = head[ay * ncx + ax]
                    while j >= 0:
                        dx = x - position[j, 0]
                        dy = y - position[j, 1]
                        if periodic[0]:
                            dx -= box[0] * np.round(dx / box[0])
                        if periodic[1]:
                            dy -= box[1] * np.round(dy / box[1])
                        s = r + radius[j]
                        if dx * dx + dy * dy < s * s:
                            free = False
                            break
                        j = nxt[j]
                    if not free:
                        break
            if free:
                position[i, 0] = x
                position[i, 1] = y
                c = cy * ncx + cx
                nxt[i] = head[c]
                head[c] = i
                placed = True
                break
        if not placed:
            return position, i
    return position, -1


def radius_for_packing(n, packing_fraction, area=1.0):
    """Radius of n equal disks that cover ``packing_fraction`` of ``area``: φ = n π R²/A."""
    n = _count("radius_for_packing", n)
    packing_fraction = real_number("radius_for_packing", "packing_fraction", packing_fraction,
                                   lambda phi: 0.0 < phi < 1.0, "a packing fraction in (0, 1)")
    area = real_number("radius_for_packing", "area", area, lambda a: 0.0 < a < math.inf,
                       "a finite area > 0")
    return float(np.sqrt(packing_fraction * area / (n * np.pi)))


def _region(call, region, box):
    """The corners (x0, y0), (x1, y1) float64[2] of ``region`` ((x0, x1), (y0, y1)) of
    ``call``, finite, 0 ≤ x0 < x1 ≤ Lx and 0 ≤ y0 < y1 ≤ Ly (the box sides ``box``); the
    whole box when None."""
    if region is None:
        return np.zeros(2), np.array(box, float)
    try:
        bounds = real_array(call, "region", region)
    except ValueError:
        bounds = None
    if (bounds is None or bounds.shape != (2, 2)
            or not np.all((0.0 <= bounds[:, 0]) & (bounds[:, 0] < bounds[:, 1])
                          & (bounds[:, 1] <= box))):
        raise refused(call, "region", region, f"((x0, x1), (y0, y1)) inside the box: 0 ≤ x0 < "
                      f"x1 ≤ {box[0]:g}, 0 ≤ y0 < y1 ≤ {box[1]:g}", show=True)
    return bounds[:, 0].copy(), bounds[:, 1].copy()


def _layout(call, radius, box, region, periodic):
    """The checked ``box``, corners of ``region`` (:func:`_region`) and ``periodic`` of
    ``call``, and which axes wrap (periodic and spanned by the region); a
    :class:`PlacementError` naming ``radius`` when the widest disk is not narrower than the
    region along an axis."""
    box = box_sides(call, "box", box)
    lo, hi = _region(call, region, box)
    periodic = periodic_pair(call, "periodic", periodic)
    wraps = tuple(periodic[a] and lo[a] == 0.0 and hi[a] == box[a] for a in range(2))
    widest = 2.0 * float(np.max(radius))
    for axis in range(2):
        if widest >= hi[axis] - lo[axis]:
            raise PlacementError(
                call, "radius", radius,
                f"disks narrower than the region: a diameter {widest:g} does not fit in its "
                f"side {hi[axis] - lo[axis]:g} along {'xy'[axis]} (the box's unless region "
                f"is given)")
    return box, lo, hi, wraps


def random_sequential(radius, box=(1.0, 1.0), region=None, periodic=(False, False), seed=0,
                      max_attempts=20_000):
    """Place disks of the given radii (a number or a 1-D array; largest first) uniformly at
    random without overlap, each diameter less than the region's sides; ``max_attempts``
    per disk, whole from 1 to :data:`MAX_ATTEMPTS`.

    Raises :class:`PlacementError` with the packing reached when a disk finds no room.
    """
    call = "random_sequential"
    radius = _radii(call, radius)
    box, lo, hi, wraps = _layout(call, radius, box, region, periodic)
    seed = _seed(call, seed)
    max_attempts = whole_count(call, "max_attempts", max_attempts, low=1, high=MAX_ATTEMPTS)
    order = np.argsort(-radius, kind="stable")
    placed, failed = _rsa(radius[order], lo, hi, box, np.array(wraps),
                          np.random.default_rng(seed), max_attempts)
    if failed >= 0:
        area = float(np.prod(hi - lo))
        reached = float(np.pi * np.sum(radius[order][:failed] ** 2) / area)
        wanted = float(np.pi * np.sum(radius**2) / area)
        raise PlacementError(
            call, "radius", radius,
            f"disks that random placement fits in the region: it stopped at packing fraction "
            f"{reached:.3f} of the requested {wanted:.3f} ({failed} of {radius.size} disks "
            f"placed), and random sequential addition jams near φ ≈ {RSA_JAMMING}; use the "
            f"hexagonal lattice (disks.placement=lattice) for dense packings")
    position = np.empty_like(placed)
    position[order] = placed
    return position


def hexagonal_lattice(n, radius, box=(1.0, 1.0), region=None, periodic=(False, False),
                      jitter=0.5, seed=0):
    """n disks on a triangular lattice filling the region, each displaced at random by at
    most ``jitter`` × half the gap between neighbours (so never overlapping).

    On a periodic axis spanning the whole box the lattice wraps around (an even number of
    rows along y); along walls the outermost centres stay a radius from the wall.
    ``radius`` may be an array (one radius or n); the lattice is spaced for the largest disk.
    """
    call = "hexagonal_lattice"
    n = _count(call, n)
    radii = _lattice_radii(call, n, radius)
    r_max = float(np.max(radii))
    box, lo, hi, wraps = _layout(call, radii, box, region, periodic)
    real_number(call, "jitter", jitter, lambda j: 0.0 <= j <= 1.0,
                "a fraction of half the gap in [0, 1]")
    seed = _seed(call, seed)
    width, height = (hi - lo) - np.where(wraps, 0.0, 2.0 * r_max)
    best = None
    for columns in range(1, n + 1):
        rows = math.ceil(n / columns)
        if wraps[1] and rows % 2:
            rows += 1
        # column spacing a and row spacing h; alternate rows shifted by a/2
        a = width / columns if wraps[0] else (width / (columns - 0.5) if columns > 1 else np.inf)
        h = height / rows if wraps[1] else (height / (rows - 1) if rows > 1 else np.inf)
        nearest = min(a, math.hypot(0.5 * a, h) if rows > 1 else np.inf, 2.0 * h)
        if best is None or nearest > best[0]:
            best = (nearest, a, h, columns, rows)
        if rows <= 2:
            break
    nearest, a, h, columns, rows = best
    if not np.isfinite(nearest):
        nearest = a = h = 4.0 * r_max
    if nearest < 2.0 * r_max * (1.0 - 1e-12):
        phi = n * np.pi * r_max**2 / float(np.prod(hi - lo))
        raise PlacementError(
            call, "radius", radius,
            f"disks that fit on a hexagonal lattice in the region: {n} of radius {r_max} do "
            f"not (φ = {phi:.3f}; a lattice of {columns} × {rows} sites is the best fit; the "
            f"ideal limit π/(2√3) ≈ 0.9069 needs a box whose sides match the lattice)")
    sites = np.arange(columns * rows)
    row, col = sites // columns, sites % columns
    x = a * (col + 0.5 * (row % 2))
    y = h * row
    # spread the n occupied sites evenly over the lattice, then centre it in the region
    take = np.round(np.linspace(0, sites.size - 1, n)).astype(np.int64)
    x, y = x[take], y[take]
    if not wraps[0]:
        x += lo[0] + r_max + 0.5 * (width - (x.max() - x.min())) - x.min()
    if not wraps[1]:
        y += lo[1] + r_max + 0.5 * (height - (y.max() - y.min())) - y.min()
    position = np.stack([x, y], axis=1)
    gap = max(nearest - 2.0 * r_max, 0.0)
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    step = jitter * 0.5 * gap * np.sqrt(rng.uniform(0.0, 1.0, n)) * (1.0 - 1e-9)
    position += step[:, None] * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    # a clipped coordinate moves the disk back towards its site: still no overlap
    clipped = np.clip(position, lo + r_max, hi - r_max)
    return np.where(wraps, position % box, clipped)


#: Collisions per disk of the elastic run that melts a lattice (:func:`melted_lattice`):
#: tests/test_initial.py checks that the crater bed's global bond-orientational order |ψ₆|
#: (0.9 on the lattice) is then a fluid's, below 3/√n.
MELT_COLLISIONS_PER_DISK = 10

#: Most collisions per disk a melt may be asked for (:func:`melted_lattice`): a thousand
#: times the default, and a bound on its run.
MAX_MELT_COLLISIONS_PER_DISK = 10**4

#: the stream of random numbers of a melt's velocities, apart from the scene's own
MELT_STREAM = 7


def melted_lattice(n, radius, box=(1.0, 1.0), region=None, periodic=(False, False), seed=0,
                   collisions_per_disk=MELT_COLLISIONS_PER_DISK):
    """Positions float64[n, 2] of n disks placed on :func:`hexagonal_lattice` and melted by
    an elastic run confined to the region (Maxwellian velocities at T = 1, zero momentum,
    ``collisions_per_disk`` × n disk–disk collisions, ``collisions_per_disk`` from 0 to
    :data:`MAX_MELT_COLLISIONS_PER_DISK`): hard walls at the region's edges, periodic along
    an axis the region spans in a periodic box. One disk, which has nothing to collide
    with, stays on its site. Deterministic in ``seed``."""
    from sim.engine.core import Engine
    from sim.engine.inputs import Boundary  # the engine prepares, it does not place

    call = "melted_lattice"
    collisions_per_disk = real_number(
        call, "collisions_per_disk", collisions_per_disk,
        lambda c: 0.0 <= c <= MAX_MELT_COLLISIONS_PER_DISK,
        f"a number of collisions per disk from 0 to {MAX_MELT_COLLISIONS_PER_DISK}")
    n = _count(call, n)
    _, lo, hi, wraps = _layout(call, _lattice_radii(call, n, radius), box, region, periodic)
    seed = _seed(call, seed)
    position = hexagonal_lattice(n, radius, box=box, region=region, periodic=periodic, seed=seed)
    if n == 1:
        return position
    mass = np.ones(n)
    rng = np.random.default_rng(np.random.SeedSequence((seed, MELT_STREAM)))
    velocity = remove_drift(_gaussian(mass, 1.0, rng), mass)
    collisions = round(collisions_per_disk * n)
    try:
        engine = Engine(position - lo, velocity, radius, mass,
                        boundary=Boundary(size=tuple(float(x) for x in hi - lo),
                                          periodic=wraps))
        reason = engine.run(collisions=collisions)
    except ValueError as error:
        raise PlacementError(call, "radius", radius, f"disks whose lattice an elastic run "
                             f"can melt: {error}") from error
    if reason != "collisions":
        raise PlacementError(call, "radius", radius, f"disks whose lattice an elastic run can "
                             f"melt: it stopped after {engine.collisions} of {collisions} "
                             f"collisions ({reason}); use disks.placement=lattice")
    return engine.positions() + lo


def two_sizes(n, packing_fraction, radius_ratio, large_fraction, area=1.0, seed=0):
    """Radii float64[n] and species int32[n] of a mixture of two sizes: round(``large_fraction``
    × n) large disks (species 1) ``radius_ratio`` times the small ones' radius (species 0),
    in an order shuffled by ``seed``, all together covering ``packing_fraction`` of ``area``."""
    call = "two_sizes"
    n = _count(call, n)
    large = round(real_number(call, "large_fraction", large_fraction,
                              lambda f: 0.0 <= f <= 1.0, "a number fraction in [0, 1]") * n)
    species = np.random.default_rng(_seed(call, seed)).permutation(
        np.repeat(np.array([0, 1], np.int32), [n - large, large]))
    relative = np.where(species == 1, real_number(call, "radius_ratio", radius_ratio,
                                                  lambda r: 1.0 <= r < math.inf,
                                                  "a finite ratio ≥ 1"), 1.0)
    small = radius_for_packing(1, packing_fraction, area / float(np.sum(relative**2)))
    return small * relative, species


#: The packing fraction a compression starts from (:func:`compressed`): random sequential
#: addition reaches it at once, far below its jamming at φ ≈ 0.547.
COMPRESSION_START = 0.3

#: The growth rate of a compression (:func:`compressed`) in units of √(T/m)/⟨σ⟩: the
#: contacts grow at 1 % of the thermal speed. Released at φ = 0.68 (N = 2000 equal disks),
#: its pressure starts 4 % above the fluid's (Kolafa–Rottner) and is within 1 % after 20
#: collisions per disk; ten times slower compressions follow the equation of state on the
#: way (:func:`sim.checks.jamming.compression_eos`), at ten times the cost.
COMPRESSION_RATE = 0.01

#: the stream of random numbers of a compression's velocities
COMPRESSION_STREAM = 8


def compressed(radius, box=(1.0, 1.0), region=None, periodic=(False, False), seed=0,
               rate=COMPRESSION_RATE):
    """Positions float64[n, 2] of disks of the given radii (a 1-D array, one per disk)
    compressed to their packing fraction in the region from a random gas: placed by
    :func:`random_sequential` at radii shrunk to φ = min(φ, :data:`COMPRESSION_START`), then
    grown at ``rate`` (units of √(T/m)/⟨σ⟩, :mod:`sim.effects.growth`) by an elastic run
    at T = 1 (unit masses, zero momentum) confined to the region as :func:`melted_lattice`
    is, until they fill the packing fraction (to round-off, from above: the disks returned
    have a gap ≥ 0 at the radii asked). No lattice is ever made. A packing the disks jam
    before reaching (a :class:`PlacementError` naming ``radius``), and one above π/√12 for
    disks of one size, cannot be made. Deterministic in ``seed``."""
    from sim.effects.growth import growth_rate
    from sim.engine.core import Engine
    from sim.engine.inputs import Boundary
    from sim.engine.running import CLOSE_PACKING

    call = "compressed"
    radius = _radii(call, radius)
    _, lo, hi, wraps = _layout(call, radius, box, region, periodic)
    seed = _seed(call, seed)
    rate = real_number(call, "rate", rate, lambda g: 0.0 < g < math.inf, "a finite rate > 0")
    phi = float(np.pi * np.sum(radius**2) / np.prod(hi - lo))
    if np.all(radius == radius[0]) and phi > CLOSE_PACKING:
        raise PlacementError(call, "radius", radius, f"disks of one size at most at φ = π/√12 = "
                             f"{CLOSE_PACKING:.4f}, their densest packing (asked: {phi:.4f})")
    start = np.sqrt(min(phi, COMPRESSION_START) / phi) * radius
    position = random_sequential(start, box=box, region=region, periodic=periodic, seed=seed)
    if phi <= COMPRESSION_START:
        return position
    n = radius.size
    mass = np.ones(n)
    rng = np.random.default_rng(np.random.SeedSequence((seed, COMPRESSION_STREAM)))
    velocity = remove_drift(_gaussian(mass, 1.0, rng), mass)
    # alternate disks labelled as two species, which changes nothing here: the compression
    # then runs the compiled loop of the compress scene (two species), not one of its own
    engine = Engine(position - lo, velocity, start, mass, np.arange(n) % 2,
                    boundary=Boundary(size=tuple(float(x) for x in hi - lo), periodic=wraps),
                    growth_rate=growth_rate(rate, start, 1.0))
    target = phi * (1.0 + 8.0 * np.finfo(float).eps)
    reason = engine.run(packing_fraction=target)
    if reason != "packing_fraction":
        raise PlacementError(call, "radius", radius, f"a packing the disks reach before they "
                             f"jam: compressed at this rate they jam at φ = "
                             f"{engine.packing_fraction():.4f}, below the {phi:.4f} asked")
    return engine.positions(engine.packing_fraction_time(target)) + lo


def fixed_speed(n, speed, seed=0):
    """Velocities of equal magnitude ``speed`` (finite, ≥ 0) in uniformly random directions:
    float64[n, 2]."""
    n = _count("fixed_speed", n)
    speed = real_number("fixed_speed", "speed", speed, lambda v: 0.0 <= v < math.inf,
                        "a finite speed ≥ 0")
    angle = np.random.default_rng(_seed("fixed_speed", seed)).uniform(0.0, 2.0 * np.pi, n)
    return speed * np.stack([np.cos(angle), np.sin(angle)], axis=1)


def _masses(call, mass, n=None):
    """The masses of ``call`` (a number, or a 1-D array of one or more, or of ``n`` when
    given) as float64[k], each finite and > 0."""
    masses = real_array(call, "mass", mass, lambda m: (m > 0.0) & (m < math.inf),
                        "masses finite and > 0")
    if masses.ndim > 1 or masses.size == 0 or (n is not None and masses.size not in (1, n)):
        count = "one or more" if n is None else f"one for each of the n = {n} disks"
        raise refused(call, "mass", mass, f"a mass, or a 1-D array of masses ({count})")
    return np.atleast_1d(masses)


def maxwellian(mass, temperature, seed=0):
    """Velocities with components drawn from N(0, T/m) (k_B = 1): float64[n, 2] for the n
    masses ``mass`` (a number or a 1-D array, each finite and > 0), ``temperature`` finite
    and ≥ 0."""
    mass = _masses("maxwellian", mass)
    temperature = real_number("maxwellian", "temperature", temperature,
                              lambda t: 0.0 <= t < math.inf, "a finite temperature ≥ 0")
    return _gaussian(mass, temperature, np.random.default_rng(_seed("maxwellian", seed)))


def _gaussian(mass, temperature, rng):
    """:func:`maxwellian` of checked values, drawn from the generator ``rng``."""
    return rng.normal(size=(mass.size, 2)) * np.sqrt(temperature / mass)[:, None]


def remove_drift(velocity, mass):
    """``velocity`` (n, 2), finite, less the centre-of-mass velocity of the disks of masses
    ``mass`` (a number or n, each finite and > 0): float64[n, 2] of zero total momentum."""
    velocity = real_array("remove_drift", "velocity", velocity, np.isfinite,
                          "velocities finite")
    if velocity.ndim != 2 or velocity.shape[1:] != (2,) or velocity.shape[0] == 0:
        raise refused("remove_drift", "velocity", velocity, "an array (n, 2) with n ≥ 1")
    mass = np.broadcast_to(_masses("remove_drift", mass, velocity.shape[0]),
                           (velocity.shape[0],))
    return velocity - (mass[:, None] * velocity).sum(axis=0) / mass.sum()
