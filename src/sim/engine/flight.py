"""Free flight between events: straight lines, or parabolas under gravity.

A disk stored at position r and velocity v at its own time t_d (lazy update, columns of the
disk table in :mod:`sim.engine.kinematics`) is at time t, with dt = t − t_d, at

    r(t) = r + v dt + g dt²/2,    v(t) = v + g dt,

where g float64[2] is the uniform acceleration of :mod:`sim.effects.gravity`, or None (then g = 0
and its terms are not compiled). Every disk falls alike, so the relative motion of two disks stays
a straight line and pair contacts keep their exact quadratic roots.

On a periodic axis a position is folded back into the box; ``images`` int32[n, 2], when given
(None otherwise, and no code is compiled for it), counts the times each disk has been folded
(+1 for leaving through the high side), so that r + images · L is the unwrapped position that
mean squared displacements need.
"""

from numba import njit

from sim.engine.kinematics import T_OWN, VX, X, wrap


@njit(cache=True, inline="always")
def displacement(i, axis, dt, disks, gravity):
    """How far disk i moves along ``axis`` in the time ``dt`` after its own time."""
    if gravity is None:
        return disks[i, VX + axis] * dt
    return (disks[i, VX + axis] + 0.5 * gravity[axis] * dt) * dt


@njit(cache=True, inline="always")
def position_at(i, axis, dt, disks, gravity):
    """Coordinate ``axis`` of disk i, ``dt`` after its own time, not folded into the box."""
    return disks[i, X + axis] + displacement(i, axis, dt, disks, gravity)


@njit(cache=True, inline="always")
def velocity_at(i, axis, dt, disks, gravity):
    """Velocity component ``axis`` of disk i, ``dt`` after its own time."""
    if gravity is None:
        return disks[i, VX + axis]
    return disks[i, VX + axis] + gravity[axis] * dt


@njit(cache=True, inline="always")
def fly(i, t, disks, geometry, grid, gravity, images):
    """Move disk i to time t along its path and store it there (position folded into the
    box on periodic axes, windings counted in ``images`` when given)."""
    dt = t - disks[i, T_OWN]
    for axis in range(2):
        x = position_at(i, axis, dt, disks, gravity)
        folded = wrap(x, geometry[axis], grid[2 + axis] != 0)
        if images is not None:
            if folded != x:
                images[i, axis] += 1 if x > folded else -1
        disks[i, X + axis] = folded
        if gravity is not None:
            disks[i, VX + axis] = velocity_at(i, axis, dt, disks, gravity)
    disks[i, T_OWN] = t
