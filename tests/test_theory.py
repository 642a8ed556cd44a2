"""The closed forms themselves: limits and identities they must satisfy."""

import numpy as np
import pytest
from scipy import integrate

from sim.analysis.theory import (
    enskog_collision_frequency,
    garzo_dufty_cooling_rates,
    garzo_dufty_haff_temperature,
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


def test_mixture_haff_law_of_equal_masses_is_the_one_species_law():
    # equal masses: Haff's T₀/(1 + t/t₀)², t₀ = 4/((1 − ξ²) ω₀), ω₀ Enskog's at T₀
    n, sigma, chi, xi, t0_temperature = 120.0, 0.01, 1.03, 0.8, 2.0
    t = np.array([0.0, 0.3, 2.0, 9.0])
    omega = enskog_collision_frequency(n, sigma, chi, t0_temperature, 3.0)
    expected = t0_temperature / (1.0 + t * (1.0 - xi**2) * omega / 4.0) ** 2
    np.testing.assert_allclose(garzo_dufty_haff_temperature(
        t, t0_temperature, [3.0, 3.0], [0.4, 0.6], xi, n, sigma, chi), expected, rtol=1e-12)
    # elastic: no cooling
    np.testing.assert_allclose(garzo_dufty_haff_temperature(
        t, 1.0, [1.0, 4.0], [0.5, 0.5], 1.0, n, sigma, chi), 1.0)
