"""The cache hints of the event loop compile for every array they are given and change
nothing, whether they reach one or several events ahead."""

import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

from sim.engine import Boundary, Engine
from sim.engine.prefetch import prefetch
from sim.pipeline.initial import fixed_speed, random_sequential


@njit
def gather_with_hints(values, order):
    """Σ values[order[k]] (rows summed for 2-d arrays), hinting each element a few ahead."""
    total = 0.0
    for k in range(order.shape[0]):
        if k + 4 < order.shape[0]:
            prefetch(values, order[k + 4])
            prefetch(order, k + 4)
        total += np.sum(values[order[k]])
    return total


@pytest.mark.parametrize("values", [
    np.arange(1000, dtype=np.int32),
    np.arange(8000, dtype=np.float64).reshape(1000, 8),
    np.arange(16000, dtype=np.float64).reshape(1000, 16)[:, ::2],  # strided rows
    np.arange(3000, dtype=np.int32).reshape(1000, 3),
])
def test_hints_change_no_result(values):
    order = np.random.default_rng(0).permutation(1000).astype(np.int32)
    assert gather_with_hints(values, order) == float(values[order].sum())


def test_only_arrays_take_hints():
    @njit
    def hint_a_number(x):
        prefetch(x, 0)

    with pytest.raises(TypingError):
        hint_a_number(1.0)


def mixed_disks(periodic, seed):
    """600 small disks and one 8 times larger (a "big" disk, outside the cells), the big one
    as heavy as its area, inelastic contacts under the TC model: the crater scene's compiled
    variant (variants.py)."""
    radius = np.full(601, 0.008)
    radius[0] = 0.064
    position = random_sequential(radius, periodic=periodic, seed=seed)
    species = (radius > radius.min()).astype(int)
    return (position, fixed_speed(601, 1.0, seed=seed + 1), radius,
            {"mass": (radius / radius.min())**2, "species": species, "restitution": 0.9,
             "wall_restitution": 0.9, "tc": 1e-6})


def equal_disks(periodic, seed):
    """600 equal elastic disks: the gas scene's compiled variant."""
    radius = np.full(600, 0.01)
    position = random_sequential(radius, periodic=periodic, seed=seed)
    return position, fixed_speed(600, 1.0, seed=seed + 1), radius, {}


@pytest.mark.parametrize("disks", [
    equal_disks,
    # per-disk masses and list capacities, a big disk: a variant of its own, looking ahead
    pytest.param(mixed_disks, marks=pytest.mark.slow)])
@pytest.mark.parametrize("periodic", [(False, False), (True, True), (True, False)])
def test_look_ahead_changes_no_trajectory(disks, periodic):
    """The hints for states larger than the caches (``lookahead``: the rows of the next
    disks' neighbours, their partners, the cells a shell exit scans and the lists it edits,
    the next bucket) leave every bit of the run as it is without them."""
    position, velocity, radius, keywords = disks(periodic, seed=4)
    engines = [Engine(position, velocity, radius, boundary=Boundary(periodic=periodic),
                      **keywords) for _ in range(2)]
    assert not engines[0].lookahead
    engines[1].lookahead = True
    n = radius.size
    for engine in engines:
        engine.run(collisions=20 * n)
    assert engines[0].counters.tolist() == engines[1].counters.tolist()
    assert engines[0].collisions == 20 * n
    assert engines[0].disks.big.size == (1 if disks is mixed_disks else 0)
    np.testing.assert_array_equal(engines[0].positions(), engines[1].positions())
    np.testing.assert_array_equal(engines[0].velocities(), engines[1].velocities())
