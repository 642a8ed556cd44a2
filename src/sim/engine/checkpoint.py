"""Checkpoints: every array that evolves, by name, and its restoration into an engine built
from the same inputs, which then continues to the same bits (:class:`Checkpoints`, a part of
:class:`sim.engine.core.Engine`)."""

import math

import numpy as np

from sim.engine.parameters import common_value
from sim.engine.stamps import count_all_contacts

#: the arrays of a checkpoint of sim 0.1.0 by their names now (the staleness stamps were its
#: collision counts, :mod:`sim.engine.stamps`)
RENAMED_ARRAYS = {"disks/coll_count": "disks/stamp", "disks/event_count": "disks/event_stamp"}


def upgraded(state):
    """A checkpoint of sim 0.1.0 as one of today: its arrays renamed (:data:`RENAMED_ARRAYS`),
    and those it lacks with the values they had then: every stamp counted (it was saved
    after a count), no system event. Today's checkpoints are returned as they are."""
    state = dict(state)
    for old, new in RENAMED_ARRAYS.items():
        if old in state:
            state.setdefault(new, state.pop(old))
    if "disks/counted" not in state and "disks/stamp" in state:
        state["disks/counted"] = np.array(state["disks/stamp"])
    state.setdefault("disks/system_time", np.array([np.inf]))
    return state


#: arrays whose size changes as the neighbour lists grow
GROWING = ("disks/nb", "disks/pair_state")


class Checkpoints:
    """Save and restore the evolving state (the engine's checkpointing part)."""

    def state_dict(self):
        """Every array that evolves, by name: restoring it into an engine built from the same
        inputs continues the run to the same bits."""
        count_all_contacts(self.disks.stamp, self.disks.counted, self.disks.contacts)
        self.drain_event_log()
        state = {f"disks/{name}": value for name, value in vars(self.disks).items()
                 if value is not None}
        state.update(counters=self.counters, accumulators=self.accumulators,
                     pair_collisions=self.pair_collisions, wall_impulse=self.wall_impulse,
                     initial_energy=np.array(self.initial_energy))
        if self.virial_tensor is not None:
            state["virial_tensor"] = self.virial_tensor
        if getattr(self.system_event, "state", None) is not None:
            state["system_state"] = self.system_event.state  # a system kind's own state
        return state

    def load_state_dict(self, state):
        """Replace the evolving arrays by those of :meth:`state_dict` (copied). A state of
        another scene — other arrays, or arrays of other shapes than this engine's (the
        neighbour lists ``disks/nb`` and their pairs' states ``disks/pair_state`` aside, which
        grow) — is refused with a ValueError before anything is replaced. A checkpoint of
        sim 0.1.0 is read as one of today (:func:`upgraded`)."""
        state = upgraded(state)
        mine = {key: np.shape(value) for key, value in self.state_dict().items()}
        missing, unknown = sorted(set(mine) - set(state)), sorted(set(state) - set(mine))
        if missing or unknown:
            raise ValueError(f"the checkpoint is not one of this scene's engine: arrays "
                             f"missing {missing}, unknown {unknown}")
        if "disks/pair_state" in state and (np.shape(state["disks/pair_state"])
                                            != np.shape(state["disks/nb"])):
            raise ValueError(f"the checkpoint's disks/pair_state has shape "
                             f"{np.shape(state['disks/pair_state'])}, its neighbour lists "
                             f"disks/nb {np.shape(state['disks/nb'])}: they must be alike")
        for key, value in state.items():
            if key not in GROWING and np.shape(value) != mine[key]:
                raise ValueError(f"the checkpoint's {key} has shape {np.shape(value)}, this "
                                 f"scene's engine {mine[key]}")
        for key, value in state.items():
            value = np.array(value)
            if key.startswith("disks/"):
                setattr(self.disks, key.removeprefix("disks/"), value)
            elif key == "initial_energy":
                self.initial_energy = float(value)
            elif key == "system_state":
                self.system_event.state[:] = value
            else:
                setattr(self, key, value)
        self._common_capacity = common_value(self.disks.nb_cap)
        self.stall_watch[:] = (-math.inf, 0.0)  # its times ran on the clock it replaced
