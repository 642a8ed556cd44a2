"""The pressure of a run with zero total momentum (N + (N − 1) X/K) against the two naive
forms on a synthetic collision log, and blocking errors against series of known
correlation (sim.analysis.equation_of_state)."""

import math

import numpy as np
import pytest

from sim.analysis.equation_of_state import (
    block_pressures,
    blocking,
    equilibration_cut,
    pressure_area,
    reduced_pressure_d2,
    run_pressure,
    time_weighted,
)


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


def test_the_equilibration_cut_drops_a_drift_and_keeps_a_stationary_series():
    """MSER: a relaxation over the first 50 of 1000 entries is cut within a few entries of
    its end; white noise loses at most a few per cent of its entries."""
    rng = np.random.default_rng(7)
    noise = rng.normal(0.0, 0.1, 1000)
    relaxing = noise + np.where(np.arange(1000) < 50, 2.0 * (1.0 - np.arange(1000) / 50), 0.0)
    assert 40 <= equilibration_cut(relaxing) <= 60
    assert equilibration_cut(noise) <= 30
    ramp = np.linspace(1.0, 0.0, 64)  # a drift all through: at most half is dropped
    assert equilibration_cut(ramp) == 32


def test_block_pressures_and_run_pressure_of_a_run(tmp_path):
    """A short melting run: one block per snapshot interval, the formula's value from the
    run file's virial and time; a run whose kinetic energy changes beyond round-off and one
    that does not start at zero momentum refused."""
    from sim.analysis.datasets import open_run
    from sim.analysis.theory import kolafa_rottner_z
    from sim.pipeline.run_cache import compose_config
    from sim.pipeline.runner import run

    overrides = ["scenario=melting", "disks.n=72", "disks.packing_fraction=0.6",
                 "stop.collisions=144000", "output.every_collisions=3600",
                 "output.progress=false"]
    with open_run(run(compose_config(overrides), tmp_path / "a")) as data:
        pressure, collisions, elapsed = block_pressures(data)
        assert pressure.size == 40 and np.all(np.diff(collisions) == 3600)
        k = 5
        expected = reduced_pressure_d2(
            72, float(data["kinetic_energy"][0]),
            float(data["collision_virial"][k + 1] - data["collision_virial"][k]),
            float(data["time"][k + 1] - data["time"][k]), 1.0, 2.0 * float(data["radius"][0]))
        assert pressure[k] == pytest.approx(expected, rel=1e-13)
        point = run_pressure(data)
        assert point.cut + point.blocks == 40
        kept = slice(point.cut, None)  # the production's pressure over its time
        assert point.mean == pytest.approx(
            np.sum(pressure[kept] * elapsed[kept]) / np.sum(elapsed[kept]), rel=1e-12)
        z = kolafa_rottner_z(0.6)  # βP/ρ, and ρ d² = 4φ/π
        assert point.mean == pytest.approx(z * 4.0 * 0.6 / math.pi, rel=0.02)
        # round-off's drift of K over a long run is passed; a dissipative run's is not
        ramp = np.linspace(0.0, 1.0, data.sizes["time"])
        for change, refused in ((1e-8, False), (1e-5, True)):
            changed = data.assign(kinetic_energy=data["kinetic_energy"] * (1.0 + change * ramp))
            if refused:
                with pytest.raises(ValueError, match="an elastic run.*changes by 1.0e-05"):
                    block_pressures(changed)
            else:
                assert np.allclose(block_pressures(changed)[0], pressure, rtol=1e-7)
    drifting = run(compose_config([*overrides, "disks.zero_momentum=false"]), tmp_path / "b")
    with open_run(drifting) as data, pytest.raises(ValueError, match="total momentum"):
        block_pressures(data)


def test_blocks_of_equal_collisions_are_weighted_by_their_time():
    """A gas of constant pressure as a Poisson process of collisions, blocks of m = 20 of
    them: a block lasts t_b ~ Gamma(m) and its pressure X_b/t_b averages m/(m − 1) of the
    true one, block by block. Over the time of all blocks (:func:`time_weighted`) the mean is
    the ratio of sums and the true pressure within its blocking error."""
    rng = np.random.default_rng(5)
    m, blocks, rate, true = 20, 40_000, 3.0, 7.0
    elapsed = rng.gamma(m, 1.0 / rate, blocks)
    virial = true / rate * rng.exponential(1.0, (blocks, m)).sum(axis=1)  # E = true · t
    pressure = virial / elapsed
    z = time_weighted(pressure, elapsed)
    assert z.mean() == pytest.approx(virial.sum() / elapsed.sum(), rel=1e-12)
    mean, error, converged, _ = blocking(z)
    assert converged and abs(mean - true) < 4.0 * error
    plain, plain_error, _, _ = blocking(pressure)
    assert plain == pytest.approx(true * m / (m - 1), rel=4.0 * plain_error / plain)
    assert plain - true > 20.0 * plain_error


def test_blocking_of_a_series_too_short_to_converge_gives_its_largest_error():
    """A random walk of 64 steps has no plateau: not converged, and the error is the
    largest level's (finite); fewer than MIN_BLOCKS entries give the naive error."""
    walk = np.cumsum(np.random.default_rng(8).normal(size=64))
    mean, error, converged, errors = blocking(walk)
    assert not converged and np.isfinite(error) and error == errors.max()
    short = walk[:5]
    assert blocking(short)[1] == pytest.approx(short.std(ddof=1) / math.sqrt(5))
