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
from sim.engine.parameters import per_disk
from sim.pipeline.input_checks import within

KEYWORDS = {
    "restitution": (None, "scalar or (s, s) normal restitution ξ per species pair; 1 = elastic"),
    "wall_restitution": (None, "ξ_w for every wall; 1 = elastic"),
    "collapse_interval": (None, "inelastic-collapse detector: dissipative contacts of one disk "
                          "each within this time of the one before make a streak. The default "
                          "is 1e-6 of the time a disk at the initial rms speed takes to cross "
                          "its own diameter; in a gas, even a dense one, a run of ten such "
                          "intervals is far too unlikely ever to be seen, while a collapsing "
                          "cluster shrinks its intervals geometrically through that scale"),
    "collapse_streak": (10, "a streak longer than this many contacts is inelastic collapse "
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
    collapse = None
    if (restitution is not None or wall_restitution is not None
            or dissipates(context["roughness"], context["friction"])):
        energy, mass = context["initial_energy"], context["mass"]
        v_rms = math.sqrt(2.0 * energy / mass.sum()) if energy else 1.0
        crossing_time = 2.0 * float(np.median(context["radius"])) / v_rms
        interval = keywords["collapse_interval"]
        collapse = CollapseWatch(1e-6 * crossing_time if interval is None else float(interval),
                                 int(keywords["collapse_streak"]))
    return {"restitution": restitution, "wall_restitution": wall_restitution,
            "collapse": collapse}


def restitution_matrix(restitution, n_species):
    """ξ per species pair for the compiled loop: None for elastic contacts (the effect is
    dropped), else a symmetric float64[s, s] with entries in [0, 1]."""
    if restitution is None:
        return None
    xi = np.asarray(restitution, dtype=np.float64)
    if xi.ndim != 0 and xi.shape != (n_species, n_species):
        raise ValueError(f"restitution must be one number or a {n_species} × {n_species} "
                         f"matrix (a row and a column per species), got shape {xi.shape}")
    xi = np.broadcast_to(xi, (n_species, n_species))
    if not np.all((xi >= 0.0) & (xi <= 1.0)):
        raise ValueError(f"restitution must lie in [0, 1], got {xi.tolist()}")
    if not np.array_equal(xi, xi.T):
        raise ValueError(f"restitution matrix must be symmetric, got {xi.tolist()}")
    if np.all(xi == 1.0):
        return None
    # always a fresh writable copy: numba types read-only arrays apart, so a view passed on
    # for some inputs would compile the event loop a second time for the same effects
    return np.array(xi)


def wall_restitution_value(wall_restitution):
    """ξ_w for the compiled loop: None for elastic walls, else a float in [0, 1)."""
    if wall_restitution is not None and not 0.0 <= wall_restitution <= 1.0:
        raise ValueError(f"wall_restitution must lie in [0, 1], got {wall_restitution}")
    return (None if wall_restitution is None or wall_restitution == 1.0
            else float(wall_restitution))


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
