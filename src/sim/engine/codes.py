"""The event loop's vocabulary, shared with the Python that drives it.

Words: a *contact* is a disk touching a disk (a *collision*) or a wall (a *wall contact*); an
*event* is what the loop applies: a contact or a shell exit. Stale events and first
predictions are popped from the queue but are no events.
"""

# event partners other than a disk
NO_EVENT = -1
SHELL_EXIT = -2
WALL_X_LOW = -3  # wall codes: WALL_X_LOW - (2 * axis + side)
WALL_X_HIGH = -4
WALL_Y_LOW = -5
WALL_Y_HIGH = -6
UNPREDICTED = -7  # a disk awaiting its first prediction, queued at the current time

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
EVENTS = 0  # applied events: contacts and shell exits
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
