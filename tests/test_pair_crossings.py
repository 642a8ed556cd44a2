"""Pair interactions with events of their own, a state per pair and a reach
(:mod:`sim.engine.pairs`): a kind written here, in the test file alone, plugs into the seam.
Hard disks that count how often their pairs cross the distance λ σ_ij, inward and outward:
the pair's state says which side it is on, each crossing is a pair event of its own (no
contact, no change of motion), and the neighbour shells reach λ R_i. The disks move as hard
disks do, so a run stays close to that of hard disks, and at every stop each pair's state must
say whether its disks are closer than λ σ_ij.

One kind, so one compiled variant of the loop, outside the quick suite's canonical set: slow.
"""

from typing import NamedTuple

import numpy as np
import pytest
from numba import njit

from conftest import assert_no_overlap, distances, gas
from sim.engine.codes import SHELL_EXITS
from sim.engine.kinematics import (
    INF,
    RADIUS,
    may_touch_before,
    pair_contact_time,
    pair_exit_time,
)
from sim.engine.pairs import collide, pair_state, rules, set_pair_state

pytestmark = pytest.mark.slow

CORE, INWARD, OUTWARD = 0, 1, 2  # the kind's events
OUTSIDE, INSIDE = 0, 1  # a pair's states


class Crossings(NamedTuple):
    ratio: float  # λ: a pair is inside while closer than λ σ_ij
    counts: np.ndarray  # int64[3]: crossings inward at [INWARD], outward at [OUTWARD], and at
    # [CORE] the crossings whose direction the pair's state contradicts (none)


@njit
def crossing_time(value, i, j, rx, ry, vx, vy, sigma, tau, state, disks):
    if state == OUTSIDE:
        if may_touch_before(rx, ry, vx, vy, value.ratio * sigma, tau):
            return pair_contact_time(rx, ry, vx, vy, value.ratio * sigma), INWARD
        return INF, INWARD
    if may_touch_before(rx, ry, vx, vy, sigma, tau):
        contact = pair_contact_time(rx, ry, vx, vy, sigma)
        if contact < INF:  # the filter passes pairs that miss, too
            return contact, CORE
    return pair_exit_time(rx, ry, vx, vy, value.ratio * sigma), OUTWARD  # no contact first


@njit
def cross(value, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies, contact):
    if event == CORE:
        lost, virial, log_full, culprit = collide(i, j, t, t_origin, disks, box, effects,
                                                  tallies, contact)
        return lost, virial, log_full, culprit, True
    side = pair_state(neighbours, i, j)
    set_pair_state(neighbours, i, j, INSIDE if side == OUTSIDE else OUTSIDE)
    value.counts[event if (side == OUTSIDE) == (event == INWARD) else CORE] += 1
    return 0.0, 0.0, False, -1, False


@njit
def crossing_reach(value, i, disks):
    return value.ratio * disks.table[i, RADIUS]


@njit
def initial_side(value, i, j, rx, ry, sigma, disks):
    reach = value.ratio * sigma
    return INSIDE if rx * rx + ry * ry < reach * reach else OUTSIDE


rules(Crossings, crossing_time, cross, reach=crossing_reach, initial_state=initial_side)

N = 400
#: λ σ = 5 R, beyond the 2 R within which the shells of hard disks at φ = 0.3 (R + δ = 2.6 R,
#: each disk within δ of its shell's centre) surely list a pair: the reach must do it
RATIO = 2.5


def counting_gas(ratio=RATIO):
    """N equal disks at φ = 0.3 in a periodic box of side 1, counting their crossings."""
    return gas(N, 0.3, periodic=(True, True), seed=5,
               pair_interaction=Crossings(ratio, np.zeros(3, np.int64)))


def inside_by_state(engine):
    """The pairs (i < j, the user's numbering) whose state is INSIDE, read from the lists."""
    d = engine.disks
    pairs = set()
    for i in range(engine.n):
        for k in range(d.nb_start[i], d.nb_start[i] + d.nb_count[i]):
            assert d.pair_state[k] in (OUTSIDE, INSIDE)
            if d.pair_state[k] == INSIDE:
                a, b = int(d.order[i]), int(d.order[d.nb[k]])
                pairs.add((min(a, b), max(a, b)))
    return pairs


def inside_by_distance(engine, slack):
    """The pairs (i < j) closer than λ σ (1 − slack), and those closer than λ σ (1 + slack)."""
    distance = distances(engine) / (2 * RATIO * engine.radius[0])
    upper = np.triu(np.ones((engine.n, engine.n), bool), 1)
    surely = np.argwhere(upper & (distance < 1.0 - slack))
    maybe = np.argwhere(upper & (distance < 1.0 + slack))
    return set(map(tuple, surely.tolist())), set(map(tuple, maybe.tolist()))


def assert_states_hold(engine):
    """Every pair inside λ σ is listed with the state INSIDE, and none outside it."""
    by_state = inside_by_state(engine)
    surely, maybe = inside_by_distance(engine, 1e-9)
    assert surely <= by_state <= maybe


def test_every_pair_state_says_on_which_side_its_pair_is():
    engine = counting_gas()
    counts = engine.pair_interaction.counts
    start = len(inside_by_state(engine))
    energy = engine.kinetic_energy()
    for end in np.linspace(0.02, 0.4, 8):
        engine.run(time=end)
        assert_states_hold(engine)
        assert_no_overlap(engine)
    assert counts[INWARD] - counts[OUTWARD] == len(inside_by_state(engine)) - start
    assert counts[INWARD] > 10 * N and engine.collisions > 10 * N and counts[CORE] == 0
    # a crossing is an event, never a contact
    assert engine.events == engine.collisions + engine.counters[SHELL_EXITS] + counts[1:].sum()
    assert engine.contacts_by_disk().sum() == 2 * engine.collisions
    assert engine.kinetic_energy() == pytest.approx(energy, rel=1e-12)


def test_crossings_leave_the_disks_on_the_paths_of_hard_disks():
    counting, hard = counting_gas(), gas(N, 0.3, periodic=(True, True), seed=5)
    counting.run(time=0.05)
    hard.run(time=0.05)
    assert counting.collisions == hard.collisions > N
    assert np.abs(counting.positions(0.05) - hard.positions(0.05)).max() < 1e-9


def test_pair_states_survive_renumbering_grown_lists_and_a_checkpoint():
    engine = counting_gas()
    engine.run(time=0.1)
    before = inside_by_state(engine)
    engine.reorder()
    engine._grow_lists(0)
    assert inside_by_state(engine) == before
    state = {key: np.array(value) for key, value in engine.state_dict().items()}
    engine.run(time=0.2)
    assert_states_hold(engine)
    resumed = counting_gas()
    resumed.load_state_dict(state)
    resumed.run(time=0.2)
    assert resumed.positions().tobytes() == engine.positions().tobytes()
    assert inside_by_state(resumed) == inside_by_state(engine)
    assert resumed.disks.pair_state.tobytes() == engine.disks.pair_state.tobytes()


def test_a_reach_below_the_radius_is_refused():
    with pytest.raises(ValueError, match="reach"):
        counting_gas(ratio=0.5)
