"""What the compiled loop records per contact when a scene asks: an event log and the
collision part of the pressure tensor. Each is None when not asked for, and its code is then
not compiled into the loop.

  event_log float64[capacity, 6] — one row per contact: absolute time, disk i, partner j
      (a disk, or −1 − wall for a wall contact, walls numbered as in :mod:`sim.effects.walls`),
      normal impulse |Δp| on i, energy dissipated, contacts so far; ``log_fill`` int64[1] is
      the number of rows in use. A full log stops the loop, which the engine drains and
      resumes: rows are in engine order and the engine renames the disks.
  virial_tensor float64[3] — Σ r_a Δp_b over disk contacts, as (xx, xy, yy): with the
      kinetic tensor Σ m v_a v_b it gives the pressure tensor
      P_ab = (⟨Σ m v_a v_b⟩ + Σ r_a Δp_b / t)/A (Allen & Tildesley, *Computer Simulation of
      Liquids*, 2nd ed., §2.4 and §3.7), whose trace is twice the pressure.
"""

from numba import njit

#: columns of the event log
LOG_TIME, LOG_DISK, LOG_PARTNER, LOG_IMPULSE, LOG_DISSIPATED, LOG_CONTACT = range(6)
LOG_COLUMNS = 6


@njit(cache=True, inline="always")
def log_contact(event_log, log_fill, t_abs, i, partner, impulse, lost, contact):
    """Append one contact; returns True when the log is full afterwards."""
    row = log_fill[0]
    event_log[row, LOG_TIME] = t_abs
    event_log[row, LOG_DISK] = i
    event_log[row, LOG_PARTNER] = partner
    event_log[row, LOG_IMPULSE] = impulse
    event_log[row, LOG_DISSIPATED] = lost
    event_log[row, LOG_CONTACT] = contact
    log_fill[0] = row + 1
    return row + 1 >= event_log.shape[0]


@njit(cache=True, inline="always")
def add_virial_tensor(virial_tensor, rx, ry, virial):
    """Add r_a Δp_b of one contact: Δp_i is along r = r_i − r_j, and r·Δp_i = ``virial``, so
    r_a Δp_b = virial r_a r_b / r²."""
    scale = virial / (rx * rx + ry * ry)
    virial_tensor[0] += scale * rx * rx
    virial_tensor[1] += scale * rx * ry
    virial_tensor[2] += scale * ry * ry
