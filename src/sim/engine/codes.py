"""The event loop's vocabulary, shared with the Python that drives it.

Words: a *contact* is a disk touching a disk (a *collision*) or a wall (a *wall contact*); an
*event* is what the loop applies: a contact, another event of a pair interaction
(:mod:`sim.engine.pairs`) or a shell exit. Stale events and first predictions are popped from
the queue but are no events; a *system event* (:mod:`sim.engine.system`) is applied to the
whole system and is not counted among them.
"""

# The kinds of event, by their code in Schedule.event_partner: a code ≥ 0 is a pair event
# with that disk; the others are the codes below, named in KINDS. Each disk owns one event;
# a system event is no disk's (the schedule's slot) and SYSTEM names it where a code is
# asked for (stop_status).
NO_EVENT = -1
SHELL_EXIT = -2
WALL_X_LOW = -3  # wall codes: WALL_X_LOW - (2 * axis + side)
WALL_X_HIGH = -4
WALL_Y_LOW = -5
WALL_Y_HIGH = -6
UNPREDICTED = -7  # a disk awaiting its first prediction, queued at the current time
SYSTEM = -8

#: code → what the event is
KINDS = {NO_EVENT: "nothing", SHELL_EXIT: "shell exit", WALL_X_LOW: "wall contact (x low)",
         WALL_X_HIGH: "wall contact (x high)", WALL_Y_LOW: "wall contact (y low)",
         WALL_Y_HIGH: "wall contact (y high)", UNPREDICTED: "first prediction",
         SYSTEM: "system event"}


def kind(code):
    """What an event of the code ``code`` is: a collision for a pair event (``code`` ≥ 0),
    else as :data:`KINDS` says."""
    return "collision" if code >= 0 else KINDS[code]


# loop status
STATUS_EVENT_LIMIT = 1
STATUS_COLLISION_LIMIT = 2
STATUS_TIME_REACHED = 3
STATUS_ENERGY_REACHED = 4
STATUS_NO_EVENTS = 5
STATUS_CONTACT_LIMIT = 6
STATUS_LOG_FULL = 7
STATUS_COLLAPSE = -1
STATUS_LIST_FULL = -2
STATUS_STALLED = -3

# counters: int64[N_COUNTERS]
EVENTS = 0  # applied events: contacts, other pair events and shell exits
COLLISIONS = 1  # disk–disk contacts
WALL_CONTACTS = 2
SHELL_EXITS = 3
STALE_EVENTS = 4  # popped, found stale, dropped
N_COUNTERS = 5

# accumulators: float64[N_ACCUMULATORS]
T_ORIGIN = 0  # absolute time of the clock's zero
T_NOW = 1  # time of the last event, relative to T_ORIGIN
DISSIPATED_DISKS = 2
DISSIPATED_WALLS = 3
VIRIAL = 4  # Σ r_ij·Δp_i over collisions
WALL_WORK = 5  # work done by moving and thermal walls on the disks
N_ACCUMULATORS = 6
