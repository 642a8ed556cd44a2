"""System events: something that happens at a time to the whole system (a rescaling of
velocities, a thermostat's kick, a new epoch of a sliding boundary), not to one disk.

A system event lives outside the disks' calendar, in the schedule's slot
(``Schedule.system_time`` float64[1], on the loop's relative clock; its value is
``Parts.system``, :mod:`sim.engine.groups`): before each event the loop compares the slot's
time with the head of the queue, and a system event comes first at equal times. With no
system event (``system`` None, an argument of the loop, whose branches numba prunes while it
compiles) the comparison is compiled away, and the order of disk events, ties included, is
that of a loop without the slot.

A kind of system event is a NamedTuple class (its value: the constants its handler needs)
and a compiled handler registered for it with :func:`handler`; numba picks the handler by the
value's type while it compiles the loop (a registry filled at import: the loop's cached
variants key on the value's type, and a second start compiles nothing; a kind defined outside
sim runs an uncached loop, :func:`sim.engine.compilation.cacheable`). The first event is
due at the start of the run (t = 0 on the engine's clock); the handler is called as
``f(value, t, t_origin, disks, schedule, neighbours, box, effects)`` with the loop's groups
(:mod:`sim.engine.groups`; ``t`` on the relative clock, ``t_origin`` the absolute time of its
zero) and returns the time of the next one (relative clock; ``math.inf`` for none; a time
before t is taken as t). The disks are at their own times when it is called: it brings them
to t with :func:`advance_all` before it changes their motion, and then says which
predictions no longer hold: :func:`predict_all` for every disk, or for a few disks
:func:`sim.engine.stamps.invalidate` and :func:`repredict` each.
"""

from numba import njit
from numba.core.errors import TypingError
from numba.extending import overload

from sim.engine.codes import UNPREDICTED
from sim.engine.flight import fly
from sim.engine.queue import build_queue, reschedule

#: the handler of each kind of system event (NamedTuple class → compiled function)
HANDLERS = {}


def handler(kind):
    """Decorator: register the compiled function as the handler of system events whose value
    is a ``kind`` (a NamedTuple class)."""
    def register(function):
        HANDLERS[kind] = function
        return function
    return register


def apply_system_event(system, t, t_origin, disks, schedule, neighbours, box, effects):
    """Call the handler of ``system``'s kind; returns the time of the next system event, no
    earlier than t."""
    later = HANDLERS[type(system)](system, t, t_origin, disks, schedule, neighbours, box,
                                   effects)
    return later if later >= t else t


@overload(apply_system_event)
def _apply_system_event(system, t, t_origin, disks, schedule, neighbours, box, effects):
    kind = getattr(system, "instance_class", None)
    if kind not in HANDLERS:
        raise TypingError(f"no system-event handler is registered for {system} "
                          f"(sim.engine.system.handler)")
    function = HANDLERS[kind]

    def apply(system, t, t_origin, disks, schedule, neighbours, box, effects):
        later = function(system, t, t_origin, disks, schedule, neighbours, box, effects)
        return later if later >= t else t
    return apply


@njit(cache=True, inline="always")
def advance_all(t, disks, box, effects):
    """Bring every disk to time t (relative clock) along its path."""
    table = disks.table
    for i in range(table.shape[0]):
        fly(i, t, table, box, effects.gravity, effects.images)


@njit(cache=True, inline="always")
def predict_all(t, schedule):
    """Predict every disk's next event anew: each is queued at time t, the current time, as a
    first prediction, which the loop makes (as at the engine's construction) before any
    event after t."""
    schedule.event_time[:] = t
    schedule.event_partner[:] = UNPREDICTED
    build_queue(schedule.heap, schedule.links, schedule.list_head, schedule.calendar,
                schedule.block_rate, schedule.event_time, t)


@njit(cache=True, inline="always")
def repredict(i, t, schedule):
    """Predict disk i's next event anew, at the current time t."""
    schedule.event_time[i] = t
    schedule.event_partner[i] = UNPREDICTED
    reschedule(schedule.heap, schedule.links, schedule.list_head, schedule.calendar,
               schedule.block_rate, schedule.event_time, i)

