"""Thermal walls: a disk leaving a wall at temperature T_w forgets its velocity.

``temperature`` float64[4] holds T_w per wall (NaN for a wall that is not thermal), or None
when no wall of the scene is thermal, and then none of this code is compiled
(:mod:`sim.effects.rules`). A disk leaving a thermal wall (Tehver, Toigo, Koplik & Banavar,
Phys. Rev. E 57, R17 (1998)) has the normal speed of the flux density
(m v/T_w) exp(−m v²/(2T_w)) and a tangential velocity Gaussian with variance T_w/m, in the
frame of the wall.

The draws come from a counter-based generator (SplitMix64, Steele, Lea & Flood, OOPSLA 2014)
keyed by the run's seed and the number of wall contacts so far, so a resumed run draws the same
numbers as one never interrupted.
"""

import math

import numpy as np
from numba import njit

from sim.effects.rules import effect_rule
from sim.effects.values import positive, walled
from sim.engine.box import WALL_NAMES
from sim.engine.inputs import WALLS, wall_keyword, whole_count
from sim.engine.kinematics import INF, VX

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX_1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX_2 = np.uint64(0x94D049BB133111EB)


KEYWORDS = {"seed": (0, "a whole number from 0 to 2^63 - 1 that keys the random draws of "
                        "thermal walls and of the initial spins (same seed, same bits); the "
                        "walls' temperatures are given with ``walls``")}


def check_config(cfg):
    """Per wall: a temperature > 0 or null, and no thermal wall in a periodic box."""
    for name in WALLS:
        temperature = cfg.walls[name].temperature
        positive(f"walls.{name}.temperature", temperature)
        if temperature is not None:
            walled(cfg, name)


def engine_arguments(cfg):
    """The run's seed (the temperatures go with the walls, :mod:`sim.effects.walls`)."""
    return {"seed": int(cfg.seed)}


def loop_values(keywords, context):
    """T_w per wall (None when no wall is thermal), and the seed."""
    temperature = wall_temperature(wall_keyword(keywords["walls"], context["periodic"]))
    return {"wall_temperature": temperature, "seed": seed_value(keywords["seed"])}


def seed_value(seed):
    """The seed as the compiled generator takes it (int64 ≥ 0): a whole number from 0 to
    2^63 − 1 (a float that is one too, such as 1e6); the ValueError of ``Engine(seed=…)``
    otherwise (:func:`sim.engine.inputs.whole_count`)."""
    return whole_count("Engine", "seed", seed, high=int(np.iinfo(np.int64).max))


def wall_temperature(walls):
    """float64[4] of wall temperatures (NaN: not thermal), or None when no wall is thermal.
    ``walls`` maps wall numbers to dicts whose key temperature, when given, is finite and > 0."""
    temperature = np.full(4, np.nan)
    for wall, spec in walls.items():
        if spec.get("temperature") is not None:
            t_wall = float(spec["temperature"])
            if not 0.0 < t_wall < INF:
                raise ValueError(f"{WALL_NAMES[wall]} wall: temperature {t_wall} must be finite "
                                 f"and > 0")
            temperature[wall] = t_wall
    return temperature if not np.all(np.isnan(temperature)) else None


@njit(cache=True, inline="always")
def _splitmix64(z):
    z = z + _GOLDEN
    z = (z ^ (z >> np.uint64(30))) * _MIX_1
    z = (z ^ (z >> np.uint64(27))) * _MIX_2
    return z ^ (z >> np.uint64(31))


@njit(cache=True, inline="always")
def uniform(key, k):
    """The k-th uniform number in (0, 1] of the stream ``key`` (uint64)."""
    z = _splitmix64(key + np.uint64(k) * _GOLDEN)
    return (np.float64(z >> np.uint64(11)) + 1.0) * (1.0 / 9007199254740992.0)


def _no_key(temperature, seed, contact):
    return np.uint64(0)


@effect_rule(_no_key)
def contact_key(temperature, seed, contact):
    """Stream key of the ``contact``-th wall contact of the run seeded ``seed``."""
    return _splitmix64(np.uint64(seed) ^ _splitmix64(np.uint64(contact)))


def _no_thermal_wall(temperature, wall):
    return False


@effect_rule(_no_thermal_wall)
def is_thermal(temperature, wall):
    """Whether ``wall`` is thermal."""
    return temperature[wall] == temperature[wall]  # NaN: not thermal


def _not_thermal(temperature, key, wall, u, sign, m, disks, i, v_n, v_t):
    return False, 0.0, 0.0


@effect_rule(_not_thermal)
def thermal_redraw(temperature, key, wall, u, sign, m, disks, i, v_n, v_t):
    """Give disk i (mass m, velocity v_n normal to ``wall`` and v_t along it) the velocity of
    a disk leaving the wall, when the wall is thermal. Returns (redrawn, momentum given to the
    wall along its axis, work done by the wall on the disk)."""
    t_wall = temperature[wall]
    if t_wall != t_wall:  # NaN: this wall is not thermal
        return False, 0.0, 0.0
    axis = wall >> 1
    scale = math.sqrt(t_wall / m)
    normal = scale * math.sqrt(-2.0 * math.log(uniform(key, 0)))
    tangential = (scale * math.sqrt(-2.0 * math.log(uniform(key, 1)))
                  * math.cos(2.0 * math.pi * uniform(key, 2)))
    disks[i, VX + axis] = u + sign * normal
    disks[i, VX + 1 - axis] = tangential
    work = 0.5 * m * (disks[i, VX + axis] ** 2 + tangential**2 - v_n * v_n - v_t * v_t)
    return True, m * (v_n - disks[i, VX + axis]), work
