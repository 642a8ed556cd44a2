"""Gravity: a uniform acceleration g along any direction.

A scene switches it on with ``gravity: [gx, gy]``; the engine then passes g float64[2] to the
compiled loop, and None otherwise, so that a scene without gravity runs code without it.
Under gravity (:mod:`sim.engine.flight`):
  * disks fly on parabolas r + v τ + g τ²/2; pairs stay straight in relative motion;
  * a wall contact is the first root of a quadratic
    (:func:`sim.engine.kinematics.first_contact_accelerated`, called by :mod:`sim.effects.walls`);
  * leaving the neighbour shell is a quartic root, replaced by a lower bound
    (:func:`sim.engine.kinematics.shell_exit_time_accelerated`): at worst the list is rebuilt early.
The mechanical energy Σ (m v²/2 − m g·r) is conserved by elastic contacts.

An inelastic disk bouncing on a floor collides infinitely often in finite time (its bounce
times shrink by ξ_w each bounce): that is inelastic collapse, reported as such, and the TC
model (:mod:`sim.engine.contact`) stops it, since wall contacts count for t_c.
"""

import math

import numpy as np
from numba import njit

from sim.engine.kinematics import shell_exit_time, shell_exit_time_accelerated


def gravity_vector(gravity):
    """float64[2] for the compiled loop, or None when the scene has no gravity."""
    if gravity is None:
        return None
    g = np.array(gravity, dtype=np.float64).reshape(-1)
    if g.shape != (2,) or not np.all(np.isfinite(g)):
        raise ValueError(f"gravity must be two finite numbers [gx, gy], got {gravity!r}")
    return None if not np.any(g) else g


@njit(cache=True, inline="always")
def shell_exit(dx, dy, vx, vy, delta, gravity):
    """Time until a disk at displacement d from its shell centre leaves the shell of radius
    δ: exact on a straight path, a lower bound on a parabola."""
    if gravity is None:
        return shell_exit_time(dx, dy, vx, vy, delta)
    g = math.sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1])
    return shell_exit_time_accelerated(dx, dy, vx, vy, g, delta)


def potential_energy(position, mass, gravity):
    """Σ −m g·r over the disks (zero at the origin): float. position float64[n, 2],
    mass float64[n], gravity float64[2] or None."""
    if gravity is None:
        return 0.0
    return float(-np.sum(mass * (position @ np.asarray(gravity, dtype=np.float64))))
