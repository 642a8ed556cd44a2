"""The pressure of a run with zero total momentum (N + (N − 1) X/K) against the two naive
forms on a synthetic collision log, and blocking errors against series of known
correlation (sim.analysis.equation_of_state)."""

import math

import numpy as np
import pytest

from sim.analysis.equation_of_state import blocking, pressure_area, reduced_pressure_d2


def test_the_pressure_of_a_synthetic_log_and_the_naive_forms():
    """N = 72 at kT = 1 (K = N − 1 with zero momentum) and βP/ρ = 9.6, near melting: the log's
    collisions sum to the virial the formula needs; kT = K/N is 1.26 % high and
    P A = K + X 0.14 % low, twenty and more times the published errors at this N."""
    n, kinetic, elapsed = 72, 71.0, 3.5
    target = 9.6 * n  # βPA
    x = (target - n) * kinetic / (n - 1)
    rng = np.random.default_rng(4)
    virials = rng.exponential(1.0, 10_000)
    virials *= 2.0 * elapsed * x / virials.sum()  # the log: one r·Δp per collision
    measured = pressure_area(n, kinetic, virials.sum(), elapsed)
    assert measured == pytest.approx(target, rel=1e-12)
    per_disk_temperature = n + n * x / kinetic  # kT = K/N
    kinetic_plus_virial = (kinetic + x) * (n - 1) / kinetic  # P A = K + X, kT = K/(N − 1)
    assert per_disk_temperature / measured - 1.0 == pytest.approx(0.0126, abs=5e-4)
    assert kinetic_plus_virial / measured - 1.0 == pytest.approx(-0.00145, abs=5e-5)
    area, diameter = 2.0, 0.1
    assert reduced_pressure_d2(n, kinetic, virials.sum(), elapsed, area, diameter) == \
        pytest.approx(target * diameter**2 / area, rel=1e-12)


def test_blocking_finds_the_error_of_white_noise_at_once():
    series = np.random.default_rng(5).normal(3.0, 2.0, 2**14)
    mean, error, converged, errors = blocking(series)
    assert converged and error == errors[0]
    assert error == pytest.approx(2.0 / math.sqrt(series.size), rel=0.05)


def test_blocking_finds_the_error_of_a_correlated_series():
    """An AR(1) series x_k = ρ x_{k−1} + ε_k: the variance of its mean is
    σ²/m (1 + ρ)/(1 − ρ), σ² = Var(ε)/(1 − ρ²); blocking finds it within its own error, where
    the naive error is three times too small."""
    rho, m = 0.8, 2**17
    rng = np.random.default_rng(6)
    noise = rng.normal(0.0, 1.0, m)
    series = np.empty(m)
    series[0] = noise[0] / math.sqrt(1.0 - rho**2)
    for k in range(1, m):
        series[k] = rho * series[k - 1] + noise[k]
    exact = math.sqrt(1.0 / (1.0 - rho**2) / m * (1.0 + rho) / (1.0 - rho))
    mean, error, converged, errors = blocking(series)
    assert converged
    assert error == pytest.approx(exact, rel=0.15)
    assert errors[0] < 0.4 * exact
