"""Free flight between events.

A disk stored at position r and velocity v at its own time t_d (lazy update, columns of the
disk table in :mod:`sim.engine.kinematics`) is at time t, with dt = t − t_d, at
r + v dt: a straight line, or under gravity the parabola of :mod:`sim.effects.gravity`
(r + v dt + g dt²/2, v + g dt). Every disk falls alike, so the relative motion of two disks
stays a straight line and pair contacts keep their exact quadratic roots.

On a periodic axis a position is folded back into the box; the folds are counted when a scene
observes unwrapped positions (:mod:`sim.effects.unwrap`).
"""

from numba import njit

from sim.effects.gravity import displacement, fall, velocity_at
from sim.effects.unwrap import count_winding
from sim.engine.box import fold
from sim.engine.kinematics import T_OWN, VX, X


@njit(cache=True, inline="always")
def flown(i, axis, dt, disks, gravity):
    """How far disk i moves along ``axis`` in the time ``dt`` after its own time."""
    return displacement(gravity, axis, disks[i, VX + axis], dt)


@njit(cache=True, inline="always")
def position_at(i, axis, dt, disks, gravity):
    """Coordinate ``axis`` of disk i, ``dt`` after its own time, not folded into the box."""
    return disks[i, X + axis] + flown(i, axis, dt, disks, gravity)


@njit(cache=True, inline="always")
def velocity_of(i, axis, dt, disks, gravity):
    """Velocity component ``axis`` of disk i, ``dt`` after its own time."""
    return velocity_at(gravity, axis, disks[i, VX + axis], dt)


@njit(cache=True, inline="always")
def fly(i, t, disks, box, gravity, images):
    """Move disk i to time t along its path and store it there (position folded into the
    box on periodic axes, :func:`sim.engine.box.fold`; windings counted in ``images`` when
    given)."""
    dt = t - disks[i, T_OWN]
    for axis in range(2):
        x = position_at(i, axis, dt, disks, gravity)
        folded = fold(box, x, axis)
        count_winding(images, i, axis, x, folded)
        disks[i, X + axis] = folded
        fall(gravity, disks, i, axis, dt)
    disks[i, T_OWN] = t
