"""The TC model (Luding & McNamara, Granular Matter 1, 113 (1998)): a contact is elastic when
either partner touched anything — disk or wall — less than t_c ago.

Inelastic disks can collapse (:mod:`sim.effects.restitution`): infinitely many contacts in
finite time. Real grains in lasting contact do not dissipate as in a binary collision; the
model makes contacts within a contact duration t_c of the one before elastic, which keeps
dense or resting inelastic matter simulable. Wall contacts count, so a disk trapped between a
wall and its neighbours cannot collapse against the wall either, and a disk resting on a
floor under gravity leaves it as from a bounce lasting t_c
(:func:`sim.effects.gravity.resting_lift`).

``tc`` is a float, or None when the model is off or nothing dissipates (no code compiled,
:mod:`sim.effects.rules`); it reads the contact times the collapse watch keeps.
"""

import math

from sim.effects.rules import effect_rule
from sim.effects.values import positive
from sim.engine.inputs import real_number

KEYWORDS = {"tc": (None, "TC-model time t_c, finite and ≥ 0 (None or 0 = off)")}


def check_config(cfg):
    """tc.time ≥ 0 or null."""
    positive("tc.time", cfg.tc.time, zero=True)


def engine_arguments(cfg):
    """t_c of the config."""
    return {"tc": cfg.tc.time}


def loop_values(keywords, context):
    """t_c, None unless a contact dissipates: then the collapse watch, which keeps the
    contact times the model reads, is on (:mod:`sim.effects.restitution`)."""
    return {"tc": tc_time(keywords["tc"], context["collapse"] is not None)}


def tc_time(tc, dissipative):
    """t_c for the compiled loop: None when the model is off (None or 0) or no contact
    dissipates, else a finite float > 0."""
    if tc is not None:
        tc = real_number("Engine", "tc", tc, lambda t: 0.0 <= t < math.inf,
                         "the TC-model time t_c, finite and ≥ 0, or None (None or 0 = off)")
    return tc if (tc and dissipative) else None


def _off(tc, xi, t, t_last_i, t_last_j):
    return xi


@effect_rule(_off)
def tc_restitution(tc, xi, t, t_last_i, t_last_j):
    """The restitution of a contact at time t whose partners last touched anything at
    ``t_last_i`` and ``t_last_j`` (the same for a wall contact): 1 within t_c, else ξ."""
    if t - t_last_i < tc or t - t_last_j < tc:
        return 1.0
    return xi
