"""The equation of state at the published sizes (sim.checks.melting): the reference data as
published, and a short run of the study's state point (its long run is the validation row
``melting_small_n``)."""

import numpy as np
import pytest

from sim.checks.melting import reference, state_point


def test_the_published_pressures_are_read_per_size_and_box():
    phi, pressure, error, aspect = reference(72, "1:1")
    assert aspect == 1.0 and phi[0] == 0.65 and pressure[0] == pytest.approx(6.901074)
    assert np.all(np.diff(pressure) > 0)  # N = 72 in its square box has no loop
    phi, pressure, error, aspect = reference(224, "1:1")
    assert np.any(np.diff(pressure) < 0)  # N = 224 in its square box has one
    assert reference(870, "29:30√3/2")[3] == pytest.approx(29 / (15 * np.sqrt(3)))
    with pytest.raises(ValueError, match="no published pressures"):
        reference(100, "1:1")


def test_a_short_run_of_a_state_point_is_near_the_published_pressure():
    """N = 72 in its square box at φ = 0.65, 4000 collisions per disk: within 1 % of
    Li et al.'s value (the validation row runs it to an error of 0.002)."""
    phi, pressure, _, aspect = reference(72, "1:1")
    mean, error, _, per_disk = state_point(72, aspect, 0.65, collisions=4000, blocks=64)
    assert per_disk == pytest.approx(4100, rel=0.01)
    assert abs(mean - pressure[0]) < 0.01 * pressure[0] and error < 0.05
