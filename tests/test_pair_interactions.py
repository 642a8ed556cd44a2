"""Pair interactions (:mod:`sim.engine.pairs`): a kind written here, in the test file alone,
plugs into the loop's pair seam. Disks of two species whose unlike pairs have a softer core:
they touch at s σ_ij instead of σ_ij = R_i + R_j, like pairs at σ_ij. With s = 1 the rule is
the hard core, and the run gives the bits of hard disks.

One kind, so one compiled variant of the loop, outside the quick suite's canonical set: slow.
"""

from typing import NamedTuple

import numpy as np
import pytest
from numba import njit

from conftest import distances, gas
from sim.engine.kinematics import INF, may_touch_before, pair_contact_time
from sim.engine.pairs import rules
from sim.engine.parameters import per_disk

pytestmark = pytest.mark.slow


class SoftCore(NamedTuple):
    scale: float  # s: unlike disks touch at s σ_ij


@njit
def soft_core_event_time(value, i, j, rx, ry, vx, vy, sigma, tau, state, disks):
    if per_disk(disks.species, i) != per_disk(disks.species, j):
        sigma = value.scale * sigma
    if may_touch_before(rx, ry, vx, vy, sigma, tau):
        return pair_contact_time(rx, ry, vx, vy, sigma), 0
    return INF, 0


rules(SoftCore, soft_core_event_time)

N = 400


def mixture(pair_interaction):
    """N equal disks of two species, alternating, at φ = 0.4 in a periodic box of side 1."""
    return gas(N, 0.4, periodic=(True, True), seed=3, species=np.arange(N) % 2,
               pair_interaction=pair_interaction)


def closest(engine):
    """The smallest distance over σ_ij of like pairs and of unlike pairs (nearest images)."""
    distance = distances(engine) / (2 * engine.radius[0])
    np.fill_diagonal(distance, np.inf)
    unlike = (np.arange(N)[:, None] % 2) != (np.arange(N)[None, :] % 2)
    return distance[~unlike].min(), distance[unlike].min()


def test_unlike_disks_touch_at_their_softer_core_and_like_disks_never_overlap():
    engine = mixture(SoftCore(0.6))
    energy = engine.kinetic_energy()
    like, unlike = [], []
    for end in np.linspace(0.03, 0.6, 20):
        engine.run(time=end)
        closest_like, closest_unlike = closest(engine)
        like.append(closest_like)
        unlike.append(closest_unlike)
    assert min(like) > 1.0 - 1e-9
    assert 0.6 * (1.0 - 1e-9) < min(unlike) < 0.9  # unlike pairs came inside σ, not inside sσ
    assert engine.kinetic_energy() == pytest.approx(energy, rel=1e-12)
    assert engine.collisions > 10 * N


def test_a_soft_core_of_scale_one_is_the_hard_core_to_the_bit():
    soft, hard = mixture(SoftCore(1.0)), mixture(None)
    soft.run(collisions=20 * N, chunk_events=997)
    hard.run(collisions=20 * N)
    assert soft.positions().tobytes() == hard.positions().tobytes()
    assert soft.velocities().tobytes() == hard.velocities().tobytes()
    assert soft.time == hard.time
