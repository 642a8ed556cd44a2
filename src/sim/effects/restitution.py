"""Normal restitution: inelastic contacts, and the inelastic collapse they can end in.

A contact reverses the normal relative velocity and shrinks it by ξ: v_n' = −ξ v_n
(Brilliantov & Pöschel, *Kinetic Theory of Granular Gases*, §1; the smooth contact rule is
:func:`sim.engine.contact.collide_disks`), losing (1 − ξ²) μ v_n²/2 of kinetic energy (μ the
reduced mass). A scene gives ξ per species pair (``restitution`` float64[s, s]) and ξ_w for
the walls (``wall_restitution`` float); each is None when elastic, and then no code of it is
compiled (:mod:`sim.effects.rules`).

Inelastic collapse (McNamara & Young, Phys. Fluids A 4, 496 (1992)): a group of disks that
collide infinitely often in finite time. It is watched for whenever a contact may dissipate
(``collapse`` = :class:`CollapseWatch`, else None): a disk with more than ``longest``
consecutive dissipative contacts, each less than ``interval`` after its previous contact,
ends the run with :class:`sim.engine.errors.InelasticCollapseError`. The watch keeps the time of
each disk's last contact (``t_last``), which the TC model (:mod:`sim.effects.tc`) reads.
"""

import math
from typing import NamedTuple

import numpy as np

from sim.effects.rotation import dissipates
from sim.effects.rules import effect_rule
from sim.effects.values import within
from sim.engine.inputs import real_number, refused, shaped_reals, whole_count
from sim.engine.parameters import per_disk

KEYWORDS = {
    "restitution": (None, "scalar or (s, s) symmetric normal restitution ξ per species pair, in "
                          "[0, 1]; 1 = elastic"),
    "wall_restitution": (None, "ξ_w in [0, 1] for every wall; 1 = elastic"),
    "collapse_interval": (None, "inelastic-collapse detector, a finite time > 0: dissipative "
                          "contacts of one disk each within this time of the one before make "
                          "a streak. The default "
                          "is 1e-6 of the time a disk at the initial rms speed takes to cross "
                          "its own diameter; in a gas, even a dense one, a run of ten such "
                          "intervals is far too unlikely ever to be seen, while a collapsing "
                          "cluster shrinks its intervals geometrically through that scale"),
    "collapse_streak": (10, "a streak longer than this many contacts (a whole number from 0 "
                            "to 2^62) is inelastic collapse "
                            "(:class:`sim.engine.errors.InelasticCollapseError`)"),
}


def check_config(cfg):
    """restitution.disk and restitution.wall in [0, 1]."""
    within("restitution.disk", cfg.restitution.disk, 0.0, 1.0, "between 0 and 1 (1 = elastic)")
    within("restitution.wall", cfg.restitution.wall, 0.0, 1.0, "between 0 and 1 (1 = elastic)")


def engine_arguments(cfg):
    """ξ and ξ_w of the config."""
    return {"restitution": float(cfg.restitution.disk),
            "wall_restitution": float(cfg.restitution.wall)}


def loop_values(keywords, context):
    """ξ per species pair, ξ_w, and the collapse watch when a contact dissipates (normal
    restitution, or rough contacts: :func:`sim.effects.rotation.dissipates`, of the effect
    before it); its default interval from the scene's initial rms speed and median radius."""
    restitution = restitution_matrix(keywords["restitution"], context["n_species"])
    wall_restitution = wall_restitution_value(keywords["wall_restitution"])
    interval, longest = keywords["collapse_interval"], keywords["collapse_streak"]
    if interval is not None:
        interval = real_number("Engine", "collapse_interval", interval,
                               lambda t: 0.0 < t < math.inf,
                               "a finite time > 0, or None (from the initial rms speed)")
    longest = whole_count("Engine", "collapse_streak", longest)
    collapse = None
    if (restitution is not None or wall_restitution is not None
            or dissipates(context["roughness"], context["friction"])):
        energy, mass = context["initial_energy"], context["mass"]
        v_rms = math.sqrt(2.0 * energy / mass.sum()) if energy else 1.0
        crossing_time = 2.0 * float(np.median(context["radius"])) / v_rms
        collapse = CollapseWatch(1e-6 * crossing_time if interval is None else interval,
                                 longest)
    return {"restitution": restitution, "wall_restitution": wall_restitution,
            "collapse": collapse}


def restitution_matrix(restitution, n_species):
    """ξ per species pair for the compiled loop: None for elastic contacts (the effect is
    dropped), else a symmetric float64[s, s] with entries in [0, 1]."""
    if restitution is None:
        return None
    s = n_species
    xi = shaped_reals("Engine", "restitution", restitution, ((), (s, s)),
                      lambda x: (x >= 0.0) & (x <= 1.0),
                      f"one number or a symmetric {s} × {s} matrix (a row and a column per "
                      f"species) of values in [0, 1] (1 = elastic), or None")
    xi = np.broadcast_to(xi, (s, s))
    if not np.array_equal(xi, xi.T):
        raise refused("Engine", "restitution", restitution,
                      f"a symmetric {s} × {s} matrix: ξ of the pair (a, b) is that of (b, a)",
                      show=xi.size <= 4)
    if np.all(xi == 1.0):
        return None
    # always a fresh writable copy: numba types read-only arrays apart, so a view passed on
    # for some inputs would compile the event loop a second time for the same effects
    return np.array(xi)


def wall_restitution_value(wall_restitution):
    """ξ_w for the compiled loop: None for elastic walls, else a float in [0, 1)."""
    if wall_restitution is None:
        return None
    xi = real_number("Engine", "wall_restitution", wall_restitution,
                     lambda x: 0.0 <= x <= 1.0, "a number in [0, 1] (1 = elastic), or None")
    return None if xi == 1.0 else xi


class CollapseWatch(NamedTuple):
    """The inelastic-collapse detector: more than ``longest`` consecutive dissipative contacts
    of one disk, each less than ``interval`` (time units) after its previous contact."""
    interval: float
    longest: int


def _elastic(restitution, species, i, j):
    return 1.0


@effect_rule(_elastic)
def disk_restitution(restitution, species, i, j):
    """ξ of a contact between disks i and j: that of their species pair."""
    return restitution[per_disk(species, i), per_disk(species, j)]


def _elastic_wall(wall_restitution):
    return 1.0


@effect_rule(_elastic_wall)
def wall_restitution_of(wall_restitution):
    """ξ_w of a wall contact."""
    return wall_restitution


def _unwatched(collapse, t_last, streak, d, xi, t):
    return False


@effect_rule(_unwatched)
def collapsing(collapse, t_last, streak, d, xi, t):
    """Record a contact of disk d with restitution ξ at time t; True when d has now made more
    than ``collapse.longest`` dissipative contacts in a row, each within
    ``collapse.interval`` of the one before."""
    if xi < 1.0 and t - t_last[d] < collapse.interval:
        streak[d] += 1
    else:
        streak[d] = 0
    t_last[d] = t
    return streak[d] > collapse.longest
