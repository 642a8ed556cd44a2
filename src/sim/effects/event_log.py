"""The log of every contact, kept when a scene asks for it (``observe.event_log``).

``event_log`` is a pair (rows float64[capacity, 6], fill int64[1]) — one row per contact:
absolute time, disk i, partner j (a disk, or −1 − wall for a wall contact, walls numbered as
in :mod:`sim.engine.box`), normal impulse |Δp| on i, energy dissipated, contacts so far;
``fill`` is the number of rows in use — or None, and then no code of it is compiled. A full
log stops the loop, which the engine drains and resumes: rows are in engine order and the
engine renames the disks.
"""

import numpy as np

from sim.effects.rules import effect_rule
from sim.engine.inputs import whole_count

#: columns of the event log
LOG_TIME, LOG_DISK, LOG_PARTNER, LOG_IMPULSE, LOG_DISSIPATED, LOG_CONTACT = range(6)
LOG_COLUMNS = 6

#: rows of the compiled event log between drains when a run logs events (6 float64 each)
EVENT_LOG_ROWS = 1 << 16

#: the most rows an engine may buffer (48 bytes each: 768 MiB); more only delays the drains
EVENT_LOG_MAX_ROWS = 1 << 24

KEYWORDS = {"event_log": (None, "rows buffered in the loop for the log of every contact, a "
                                "whole number from 1 to 2^24; None = no log. Full buffers go "
                                "to :attr:`event_sink` (a callable taking float64[k, 6], e.g. "
                                "the run file's writer) or else are kept for "
                                ":meth:`take_event_log`")}


def check_config(cfg):
    """A boolean switch: its type is the schema's."""


def engine_arguments(cfg):
    """:data:`EVENT_LOG_ROWS` when the scene logs events, else None."""
    return {"event_log": EVENT_LOG_ROWS if cfg.observe.event_log else None}


def loop_values(keywords, context):
    """The empty log (rows, fill), or None; ``event_log`` None or a whole number of rows from
    1 to :data:`EVENT_LOG_MAX_ROWS` (booleans refused)."""
    rows = keywords["event_log"]
    if rows is None:
        return {"event_log": None}
    rows = whole_count("Engine", "event_log", rows, low=1, high=EVENT_LOG_MAX_ROWS)
    return {"event_log": (np.zeros((rows, LOG_COLUMNS)), np.zeros(1, dtype=np.int64))}


def _not_logged(event_log, t_abs, i, partner, impulse, lost, contact):
    return False


@effect_rule(_not_logged)
def log_contact(event_log, t_abs, i, partner, impulse, lost, contact):
    """Append one contact; returns True when the log is full afterwards."""
    rows, fill = event_log
    row = fill[0]
    rows[row, LOG_TIME] = t_abs
    rows[row, LOG_DISK] = i
    rows[row, LOG_PARTNER] = partner
    rows[row, LOG_IMPULSE] = impulse
    rows[row, LOG_DISSIPATED] = lost
    rows[row, LOG_CONTACT] = contact
    fill[0] = row + 1
    return row + 1 >= rows.shape[0]
