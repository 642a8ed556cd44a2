"""What the engine accepts: the box, the disks, the walls and the numbers of a scene, each
checked before anything is built; a bad one is a ValueError whose one line names it and what
is allowed."""

import math
import operator
from collections.abc import Mapping
from dataclasses import dataclass
from numbers import Real

import numpy as np

from sim.engine.box import WALL_NAMES

#: wall numbers of :mod:`sim.effects.walls` by name
WALLS = {name: wall for wall, name in enumerate(WALL_NAMES)}

#: The keys a wall's entry in ``walls`` may have.
WALL_KEYS = ("temperature", "speed", "amplitude", "frequency")


@dataclass(frozen=True)
class Boundary:
    """Box [0, Lx] × [0, Ly]; each axis has hard walls or is periodic."""

    size: tuple = (1.0, 1.0)
    periodic: tuple = (False, False)


def first_index(mask):
    """Index of the first True entry of the bool array ``mask``, or None."""
    bad = np.flatnonzero(mask)
    return int(bad[0]) if bad.size else None


def check_disks(position, velocity, radius, mass, species):
    """Refuse non-finite positions and velocities (n, 2), radii and masses (n,) that are not
    finite and > 0, and negative species, naming the first disk at fault."""
    for name, values in (("radius", radius), ("mass", mass)):
        bad = first_index(~((values > 0.0) & (values < math.inf)))
        if bad is not None:
            raise ValueError(f"disk {bad} has {name} {values[bad]}: a {name} must be finite "
                             f"and > 0")
    for name, values in (("position", position), ("velocity", velocity)):
        bad = first_index(~np.isfinite(values.ravel()))
        if bad is not None:
            raise ValueError(f"disk {bad // 2} has {name} {values[bad // 2].tolist()}: "
                             f"positions and velocities must be finite")
    bad = first_index(species < 0)
    if bad is not None:
        raise ValueError(f"disk {bad} has species {species[bad]}: species are integers ≥ 0")


def box_size(boundary):
    """The box sides float64[2] of a :class:`Boundary`, each finite and > 0
    (:func:`box_sides`); a ValueError for what is no :class:`Boundary`."""
    if not isinstance(boundary, Boundary):
        raise refused("Engine", "boundary", boundary,
                      "a sim.engine.Boundary(size=(Lx, Ly), periodic=…)", show=True)
    return box_sides("Boundary", "size", boundary.size)


def box_sides(call, name, size):
    """The sides (Lx, Ly) of a box as float64[2], each finite and > 0; a ValueError naming
    ``name`` of ``call`` otherwise."""
    try:
        box = real_array(call, name, size)
    except ValueError:
        box = None
    if box is None or box.shape != (2,) or not np.all((box > 0.0) & (box < math.inf)):
        raise refused(call, name, size, "two finite sides (Lx, Ly) > 0", show=True)
    return box


def periodic_pair(call, name, periodic):
    """``periodic``, one boolean for both axes or a pair (x, y) of booleans, as a tuple of two
    bools; a ValueError naming ``name`` of ``call`` for anything else (0, 1 and text
    included)."""
    flags = (periodic, periodic) if isinstance(periodic, bool | np.bool_) else periodic
    try:
        pair = tuple(flags)
    except TypeError:
        pair = ()
    if len(pair) != 2 or not all(isinstance(flag, bool | np.bool_) for flag in pair):
        raise refused(call, name, periodic, "True or False (both axes), or a pair (x, y) of "
                                            "them", show=True)
    return bool(pair[0]), bool(pair[1])


def check_inside(given, position, radius, box, periodic):
    """Refuse a disk as wide as the box or wider (2R < L on a walled axis: a disk touching
    both walls at once would touch them for ever), or reaching beyond a wall (R ≤ x ≤ L − R),
    naming the first; ``given`` are the positions as the caller gave them, ``position``
    wrapped."""
    for axis in range(2):
        if not periodic[axis]:
            too_wide = first_index(2.0 * radius >= box[axis])
            if too_wide is not None:
                raise ValueError(f"disk {too_wide} of radius {radius[too_wide]:g} does not fit "
                                 f"between the walls {box[axis]:g} apart along "
                                 f"{'xy'[axis]}: a disk's diameter must be less than the "
                                 f"box side")
            bad = first_index((position[:, axis] - radius < 0.0)
                         | (position[:, axis] + radius > box[axis]))
            if bad is not None:
                raise ValueError(f"disk {bad} at {given[bad].tolist()} with radius "
                                 f"{radius[bad]} pokes through a wall of the box "
                                 f"{box.tolist()}: along a walled axis of side L a disk of "
                                 f"radius R needs R ≤ x ≤ L − R")


def wall_keyword(walls, periodic):
    """``walls`` as :class:`Engine` takes them (None, or a mapping of wall names to None or
    to {key: value} of :data:`WALL_KEYS`), checked and keyed by wall number: temperature None
    or finite and > 0, speed finite, amplitude and frequency finite and ≥ 0, a frequency > 0
    for an amplitude > 0, no entry on a periodic axis; a ValueError of ``Engine(walls=…)``
    naming the wall and key at fault otherwise. Walls without an entry stay hard and still."""
    def refuse(allowed):
        return refused("Engine", "walls", walls, allowed)

    if walls is None:
        return {}
    if not isinstance(walls, Mapping):
        raise refuse(f"None or a mapping of wall names ({', '.join(WALLS)}) to their keys")
    specs = {}
    for name, spec in walls.items():
        if name not in WALLS:
            raise refuse(f"unknown wall {name!r}: use {', '.join(WALLS)}")
        if spec is not None and not isinstance(spec, Mapping):
            raise refuse(f"{name} wall: None or a mapping of {', '.join(WALL_KEYS)} to numbers")
        spec = dict(spec or {})
        unknown = sorted(set(spec) - set(WALL_KEYS), key=str)
        if unknown:
            raise refuse(f"{name} wall: unknown keys {unknown}, use {', '.join(WALL_KEYS)}")
        if spec and periodic[WALLS[name] >> 1]:
            raise refuse(f"{name} wall is given on a periodic axis, which has no walls")
        checked = {}
        for key, accept, allowed in (
                ("temperature", lambda t: 0.0 < t < math.inf, "must be finite and > 0, or None"),
                ("speed", math.isfinite, "must be finite"),
                ("amplitude", lambda a: 0.0 <= a < math.inf, "must be finite and ≥ 0"),
                ("frequency", lambda w: 0.0 <= w < math.inf, "must be finite and ≥ 0")):
            if key not in spec or (key == "temperature" and spec[key] is None):
                continue
            value = spec[key]
            if (isinstance(value, bool | np.bool_) or not isinstance(value, Real)
                    or not accept(float(value))):
                raise refuse(f"{name} wall: {key} {_plain(value)!r} {allowed}")
            checked[key] = float(value)
        if checked.get("amplitude", 0.0) > 0.0 and checked.get("frequency", 0.0) == 0.0:
            raise refuse(f"{name} wall: an angular frequency > 0 for a wall with an amplitude")
        if spec:
            specs[WALLS[name]] = {**spec, **checked}
    return specs


#: float64 squares and multiplies the scales of a scene in its roots, impulses and energies:
#: each length (box sides, radii), speed (the fastest disk, |U| + A ω of a wall, √(|g| L) of
#: gravity, √(T_w/m) of a thermal wall) and mass must lie in [1/SCALE_LIMIT, SCALE_LIMIT], so
#: that their squares and products keep far inside its normal range (1e-308 … 1e308).
SCALE_LIMIT = 1e60

#: The smallest radius must be at least this fraction of the far edge D of the disks (the
#: largest x + R or y + R, the side of a periodic axis): coordinates near D are resolved to
#: 2⁻⁵² D, and the contacts of smaller disks could not be located to 2⁻¹² of their radius.
RESOLUTION_LIMIT = 2.0**-40


def check_scales(box, radius, mass, velocity, extent, gravity, motion, temperature):
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


#: Largest count of collisions, contacts or events a run may be asked for (and the largest
#: chunk): int64 counters, with room to add a chunk.
MAX_COUNT = 2**62


def refused(call, name, value, allowed, show=False):
    """The ValueError of an argument ``name`` of the function ``call``: one line naming it,
    its value (… for an array, a list or a tuple, unless ``show``: for short ones such as a
    box) and what is allowed."""
    if not show and isinstance(value, list | tuple | np.ndarray):
        shown = "…"
    else:
        shown = repr(value.tolist() if isinstance(value, np.ndarray) else _plain(value))
    return ValueError(f"{call}({name}={shown}) is not allowed: {allowed}")


def _plain(value):
    """``value`` with numpy numbers as Python numbers, in its tuples and lists too."""
    if isinstance(value, list | tuple):
        return type(value)(_plain(item) for item in value)
    return value.item() if isinstance(value, np.generic) else value


def _number_text(number):
    """2^k or 2^k - 1 for such numbers from 2^32 on, else the number."""
    for power, text in ((number, ""), (number + 1, " - 1")):
        if power >= 2**32 and power & (power - 1) == 0:
            return f"2^{power.bit_length() - 1}{text}"
    return str(number)


#: The most species an engine holds: per-pair values (restitution) are S × S matrices.
MAX_SPECIES = 1024


def per_disk(call, name, value, n):
    """``value`` as float64[n]: one number for every disk, or one per disk; a ValueError
    naming ``name`` of ``call`` otherwise."""
    array = real_array(call, name, value)
    if array.ndim > 1 or array.size not in (1, n):
        raise refused(call, name, value, f"one number, or one per disk ({n} numbers)")
    return np.array(np.broadcast_to(array, (n,)))


def species_input(species, n):
    """Species numbers int32[n] (one number for every disk, or one per disk); a ValueError
    for what is not whole numbers from 0 to :data:`MAX_SPECIES` − 1."""
    numbers = per_disk("Engine", "species", species, n)
    if not np.all((numbers >= 0) & (numbers < MAX_SPECIES) & (numbers == np.floor(numbers))):
        raise refused("Engine", "species", species,
                      f"whole numbers from 0 to {MAX_SPECIES - 1}")
    return numbers.astype(np.int32)


def whole_count(call, name, value, low=0, high=MAX_COUNT):
    """``value`` (an integer, or a float that is one, such as 1e6) as an int in [low, high];
    a ValueError naming ``name`` of ``call`` otherwise."""
    allowed = f"a whole number from {low} to {_number_text(high)}"
    if isinstance(value, bool | np.bool_):
        raise refused(call, name, value, allowed)
    try:
        number = operator.index(value)
    except TypeError:
        if not (isinstance(value, float | np.floating) and math.isfinite(value)
                and value == math.floor(value)):
            raise refused(call, name, value, allowed) from None
        number = int(value)
    if not low <= number <= high:
        raise refused(call, name, value, allowed)
    return number


def real_number(call, name, value, accept, allowed):
    """``value`` as a float that ``accept`` takes; a ValueError naming ``name`` of ``call``
    otherwise (complex numbers, text and booleans included)."""
    if isinstance(value, bool | np.bool_ | complex | np.complexfloating | str):
        raise refused(call, name, value, allowed)
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise refused(call, name, value, allowed) from None
    if not accept(number):
        raise refused(call, name, value, allowed)
    return number


def real_array(call, name, value, accept=None, allowed=""):
    """``value`` as a C-ordered float64 array; a ValueError naming ``name`` of ``call`` for what
    is not real numbers (complex numbers, text, lists of unequal lengths) and, with ``accept``
    (elementwise, on the array), for the first entry it refuses (``allowed`` says what may
    be)."""
    try:
        kind = np.asarray(value).dtype.kind
    except ValueError:  # lists of unequal lengths
        kind = "O"
    if kind not in "iuf":
        raise refused(call, name, value, "real numbers")
    array = np.array(value, dtype=np.float64, order="C")
    bad = None if accept is None else first_index(~np.ravel(accept(array)))
    if bad is not None:
        raise ValueError(f"{call}({name}=…) is not allowed: entry {bad} is "
                         f"{float(array.ravel()[bad])!r}; {allowed}")
    return array


def shaped_reals(call, name, value, shapes, accept, allowed):
    """``value`` as a float64 array of one of the ``shapes`` (``()`` for one number) whose
    every entry ``accept`` takes (elementwise, on the array); a ValueError naming ``name`` of
    ``call`` and saying ``allowed`` otherwise (text, booleans, complex numbers, lists of
    unequal lengths and other shapes included). Values of up to four numbers are shown."""
    try:
        kind, show = np.asarray(value).dtype.kind, np.size(value) <= 4
    except ValueError:  # lists of unequal lengths
        kind, show = "O", False
    if kind not in "iuf":
        raise refused(call, name, value, allowed, show=show)
    array = np.array(value, dtype=np.float64, order="C")
    if array.shape not in shapes or not np.all(accept(array)):
        raise refused(call, name, value, allowed, show=show)
    return array


def check_stop(contacts, collisions, events, time, energy_fraction, packing_fraction, jamming,
               wall_seconds, until, chunk_events):
    """The arguments of :meth:`sim.engine.Engine.run`, checked as the command line checks its
    ``stop`` keys: counts whole from 0 to 2^62 (targets since the engine started), ``time``
    finite and ≥ 0 (absolute), ``energy_fraction`` in [0, 1], ``packing_fraction`` in (0, 1),
    ``jamming`` a finite reduced pressure > 1, ``wall_seconds`` finite and ≥ 0 (0: spent),
    ``until`` callable, ``chunk_events`` whole from 1; at least one stop condition.
    Returns them with the counts as ints and the numbers as floats (None kept)."""
    if all(x is None for x in (contacts, collisions, events, time, energy_fraction,
                               packing_fraction, jamming, wall_seconds, until)):
        raise ValueError("run() needs at least one stop condition: " + ", ".join(STOP_NAMES))
    counts = [None if value is None else whole_count("run", name, value) for name, value in
              (("contacts", contacts), ("collisions", collisions), ("events", events))]
    if time is not None:
        time = real_number("run", "time", time, lambda t: 0.0 <= t < math.inf,
                           "a finite time ≥ 0 (the absolute time to stop at)")
    if energy_fraction is not None:
        energy_fraction = real_number("run", "energy_fraction", energy_fraction,
                                      lambda f: 0.0 <= f <= 1.0,
                                      "a fraction of the initial kinetic energy in [0, 1]")
    if packing_fraction is not None:
        packing_fraction = real_number("run", "packing_fraction", packing_fraction,
                                       lambda f: 0.0 < f < 1.0, "a packing fraction in (0, 1)")
    if jamming is not None:
        jamming = real_number("run", "jamming", jamming, lambda p: 1.0 < p < math.inf,
                              "a finite reduced pressure βP/ρ > 1")
    if wall_seconds is not None:
        wall_seconds = real_number("run", "wall_seconds", wall_seconds,
                                   lambda w: 0.0 <= w < math.inf,
                                   "a finite number of seconds ≥ 0")
    if until is not None and not callable(until):
        raise refused("run", "until", until, "a function of the engine returning True to stop")
    return (*counts, time, energy_fraction, packing_fraction, jamming, wall_seconds, until,
            whole_count("run", "chunk_events", chunk_events, low=1))


#: the stop conditions of :meth:`sim.engine.Engine.run`, in the order of its signature
STOP_NAMES = ("contacts", "collisions", "events", "time", "energy_fraction", "packing_fraction",
              "jamming", "wall_seconds", "until")


def check_reachable(given, never):
    """Refuse a run of :meth:`sim.engine.Engine.run` none of whose stop conditions can ever
    hold, as the command line refuses such a ``stop``
    (:func:`sim.pipeline.stop_conditions.check_reachable`): ``given`` maps the conditions
    given (as given, which :func:`check_stop` accepted) to their values, ``never`` those
    that can never hold to what is allowed instead."""
    if not given or set(given) - set(never):
        return
    other = ("; add another stop condition ("
             + ", ".join(name for name in STOP_NAMES if name not in given) + ")")
    if len(given) == 1:
        (name, value), = given.items()
        raise refused("run", name, value, never[name] + other)
    shown = ", ".join(f"{name}={value!r}" for name, value in given.items())
    raise ValueError(f"run({shown}) is not allowed: none can hold: "
                     + "; ".join(f"{name}: {never[name]}" for name in given) + other)
