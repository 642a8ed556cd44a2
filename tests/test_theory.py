"""The closed forms themselves: limits and identities they must satisfy."""

import numpy as np
import pytest
from scipy import integrate

from sim.analysis.theory import (
    garzo_dufty_cooling_rates,
    garzo_dufty_temperature_ratio,
    maxwell_speed_cdf,
    maxwell_speed_pdf,
)


def test_maxwell_speed_density_is_normalised_with_mean_energy_t():
    m, t = 4.0, 0.7
    total, _ = integrate.quad(maxwell_speed_pdf, 0, np.inf, args=(m, t))
    energy, _ = integrate.quad(lambda v: 0.5 * m * v**2 * maxwell_speed_pdf(v, m, t), 0, np.inf)
    assert total == pytest.approx(1.0, rel=1e-12)
    assert energy == pytest.approx(t, rel=1e-10)  # 2D: ⟨m v²/2⟩ = T
    assert maxwell_speed_cdf(1.3, m, t) == pytest.approx(
        integrate.quad(maxwell_speed_pdf, 0, 1.3, args=(m, t))[0], rel=1e-12)


def test_garzo_dufty_equipartition_when_elastic_and_for_equal_masses():
    assert garzo_dufty_temperature_ratio([1.0, 4.0], [0.5, 0.5], 1.0) == 1.0
    assert garzo_dufty_temperature_ratio([1.0, 1.0], [0.3, 0.7], 0.8) == pytest.approx(1.0)
    rates = garzo_dufty_cooling_rates([1.0, 1.0], [1.0, 4.0], [0.5, 0.5], 1.0)
    np.testing.assert_allclose(rates, 0.0, atol=1e-15)


def test_garzo_dufty_heavy_species_runs_hotter_as_restitution_falls():
    ratios = [garzo_dufty_temperature_ratio([1.0, 4.0], [0.5, 0.5], xi)
              for xi in (0.95, 0.9, 0.8, 0.6)]
    assert np.all(np.diff(ratios) > 0) and ratios[0] > 1.0
    gamma = ratios[2]
    z = garzo_dufty_cooling_rates([1.0, gamma], [1.0, 4.0], [0.5, 0.5], 0.8)
    assert z[0] == pytest.approx(z[1], rel=1e-10)
