"""Gravity: a uniform acceleration g along any direction.

A scene switches it on with ``gravity: [gx, gy]``; the engine then passes g float64[2] to the
compiled loop, and None otherwise, so that a scene without gravity runs code without it
(:mod:`sim.effects.rules`). Under gravity:
  * disks fly on parabolas r + v τ + g τ²/2, v + g τ (:func:`displacement`,
    :func:`velocity_at`); pairs stay straight in relative motion, so pair contacts keep their
    exact quadratic roots;
  * a wall contact is the first root of a quadratic
    (:func:`sim.engine.kinematics.first_contact_accelerated`, called by
    :mod:`sim.effects.walls`, which takes the acceleration from :func:`acceleration`);
  * leaving the neighbour shell is a quartic root, replaced by a lower bound
    (:func:`sim.engine.kinematics.shell_exit_time_accelerated`): at worst the list is rebuilt
    early.
The mechanical energy Σ (m v²/2 − m g·r) is conserved by elastic contacts.

An inelastic disk bouncing on a floor collides infinitely often in finite time (its bounce
times shrink by ξ_w each bounce): that is inelastic collapse, reported as such, and the TC
model (:mod:`sim.effects.tc`) stops it, since wall contacts count for t_c; a disk resting on
a floor then leaves it as from a bounce lasting t_c (:func:`resting_lift`).
"""

import math

import numpy as np
from numba import types
from numba.extending import overload

from sim.effects.rules import effect_rule
from sim.effects.values import ConfigError
from sim.engine.inputs import refused, shaped_reals
from sim.engine.kinematics import (
    VX,
    shell_exit_time,
    shell_exit_time_accelerated,
    shrinking_shell_exit_time,
    shrinking_shell_exit_time_accelerated,
)

KEYWORDS = {"gravity": (None, "[gx, gy] uniform acceleration, two finite numbers "
                              "(:mod:`sim.effects.gravity`), zero along a periodic axis; None "
                              "or zero = off")}


def check_config(cfg):
    """gravity two finite numbers, zero in a periodic box."""
    g = list(cfg.gravity)
    if len(g) != 2 or not all(math.isfinite(x) for x in g):
        raise ConfigError("gravity", g, "two finite numbers [gx, gy] (acceleration; [0, 0] = "
                          "off)")
    if cfg.box.boundary == "periodic" and any(g):
        raise ConfigError("gravity", g, "[0, 0] in a periodic box, where nothing stops the "
                          "fall: use box.boundary=walls")


def engine_arguments(cfg):
    """g of the config."""
    return {"gravity": list(cfg.gravity)}


def loop_values(keywords, context):
    """g float64[2], None when zero; refused along a periodic axis of the ``context``."""
    gravity = gravity_vector(keywords["gravity"])
    if gravity is not None and np.any(gravity[context["periodic"]] != 0.0):
        raise refused("Engine", "gravity", keywords["gravity"], "no component along a periodic "
                      "axis, where nothing stops the fall; give it walls", show=True)
    return {"gravity": gravity}


def gravity_vector(gravity):
    """float64[2] for the compiled loop, or None when the scene has no gravity."""
    if gravity is None:
        return None
    g = shaped_reals("Engine", "gravity", gravity, ((2,),), np.isfinite,
                     "two finite numbers [gx, gy], or None")
    return None if not np.any(g) else g


def potential_energy(position, mass, gravity):
    """Σ −m g·r over the disks (zero at the origin): float. position float64[n, 2],
    mass float64[n], gravity float64[2] or None."""
    if gravity is None:
        return 0.0
    return float(-np.sum(mass * (position @ np.asarray(gravity, dtype=np.float64))))


def _straight(gravity, axis, v, dt):
    return v * dt


@effect_rule(_straight)
def displacement(gravity, axis, v, dt):
    """How far a disk of velocity v along ``axis`` moves in the time dt: (v + g dt/2) dt."""
    return (v + 0.5 * gravity[axis] * dt) * dt


def _constant(gravity, axis, v, dt):
    return v


@effect_rule(_constant)
def velocity_at(gravity, axis, v, dt):
    """The velocity along ``axis`` a time dt after it was v: v + g dt."""
    return v + gravity[axis] * dt


def _velocity_kept(gravity, disks, i, axis, dt):
    pass


@effect_rule(_velocity_kept)
def fall(gravity, disks, i, axis, dt):
    """Store the velocity of disk i after a fall of duration dt: v + g dt."""
    disks[i, VX + axis] = velocity_at(gravity, axis, disks[i, VX + axis], dt)


def _no_acceleration(gravity, axis):
    return 0.0


@effect_rule(_no_acceleration)
def acceleration(gravity, axis):
    """g along ``axis``."""
    return gravity[axis]


def shell_exit(gravity, dx, dy, vx, vy, delta, rate):
    """Time until a disk at displacement d from its shell centre leaves the shell of radius
    δ, shrinking at ``rate`` for a growing disk (:mod:`sim.effects.growth`; None: a fixed
    shell): exact on a straight path, a lower bound on a parabola
    (:func:`sim.engine.kinematics.shell_exit_time`, :func:`shell_exit_time_accelerated` and
    their shrinking forms). numba picks one of the four by the types of ``gravity`` and
    ``rate``."""
    return _exit_rule(gravity, rate)(gravity, dx, dy, vx, vy, delta, rate)


def _straight_exit(gravity, dx, dy, vx, vy, delta, rate):
    return shell_exit_time(dx, dy, vx, vy, delta)


def _parabola_exit(gravity, dx, dy, vx, vy, delta, rate):
    g = math.sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1])
    return shell_exit_time_accelerated(dx, dy, vx, vy, g, delta)


def _straight_shrinking_exit(gravity, dx, dy, vx, vy, delta, rate):
    return shrinking_shell_exit_time(dx, dy, vx, vy, delta, rate)


def _parabola_shrinking_exit(gravity, dx, dy, vx, vy, delta, rate):
    g = math.sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1])
    return shrinking_shell_exit_time_accelerated(dx, dy, vx, vy, g, delta, rate)


def _exit_rule(gravity, rate):
    """The shell-exit rule for gravity and a shrinking rate, each None or not (in Python or
    as numba types)."""
    straight = gravity is None or gravity is types.none
    if rate is None or rate is types.none:
        return _straight_exit if straight else _parabola_exit
    return _straight_shrinking_exit if straight else _parabola_shrinking_exit


@overload(shell_exit, inline="always")
def _shell_exit(gravity, dx, dy, vx, vy, delta, rate):
    return _exit_rule(gravity, rate)


def resting_lift(gravity, tc, motion, disks, i, axis, sign):
    """A disk at rest on a still wall that gravity presses it against (placed there at rest)
    would touch it again at once, for ever. Under the TC model it leaves with the speed
    g t_c/2 of a bounce lasting t_c (the bounces the model settles resting disks into).
    Returns (lifted, the speed it leaves with); without gravity, TC or with a moving wall,
    (False, 0)."""
    rule = _no_lift if gravity is None or tc is None or motion is not None else _lift
    return rule(gravity, tc, motion, disks, i, axis, sign)


def _lift(gravity, tc, motion, disks, i, axis, sign):
    if disks[i, VX + axis] == 0.0 and sign * gravity[axis] < 0.0:  # w_n = v_n, still wall
        disks[i, VX + axis] = sign * 0.5 * abs(gravity[axis]) * tc
        return True, disks[i, VX + axis]
    return False, 0.0


def _no_lift(gravity, tc, motion, disks, i, axis, sign):
    return False, 0.0


@overload(resting_lift, inline="always")
def _resting_lift(gravity, tc, motion, disks, i, axis, sign):
    if gravity is types.none or tc is types.none or motion is not types.none:
        return _no_lift
    return _lift
