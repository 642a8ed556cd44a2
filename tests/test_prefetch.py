"""The cache hint of the event loop compiles for every array it is given and changes nothing."""

import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

from sim.prefetch import prefetch


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
