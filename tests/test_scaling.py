"""sim.analysis.scaling: local exponents and the χ² test of a single power law."""

import numpy as np
import pytest

from sim.analysis.scaling import local_exponents, single_power_law


def test_a_power_law_has_one_exponent_everywhere_and_no_chi_square():
    x = np.geomspace(0.01, 0.1, 6)
    y = 3.0 * x**1.7
    middle, local, error = local_exponents(x, y, 0.02 * y)
    np.testing.assert_allclose(local, 1.7, rtol=1e-12)
    np.testing.assert_allclose(middle, np.sqrt(x[1:] * x[:-1]))
    np.testing.assert_allclose(error, np.hypot(0.02, 0.02) / np.log(x[1:] / x[:-1]))
    slope, slope_error, chi_square, freedom, p_value = single_power_law(x, y, 0.02 * y)
    assert slope == pytest.approx(1.7, rel=1e-12) and slope_error > 0.0
    assert chi_square < 1e-20 and freedom == 4 and p_value == pytest.approx(1.0)


def test_points_that_curve_fail_the_single_power_law():
    x = np.geomspace(1.0, 100.0, 7)
    y = x**2 / (1.0 + x)  # exponent 2 → 1
    _, local, _ = local_exponents(x, y, 0.01 * y)
    assert np.all(np.diff(local) < 0)
    _, _, chi_square, freedom, p_value = single_power_law(x, y, 0.01 * y)
    assert chi_square > 100 * freedom and p_value < 1e-10
