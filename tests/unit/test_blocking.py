"""Standard errors of correlated series: AR(1) with a known variance of the mean."""
import math

import numpy as np
import pytest
from scipy.signal import lfilter

from suspsim.analysis.blocking import (MIN_BLOCKS, batch_means, blocking_mean,
                                       periodic_batch_means)


def ar1(phi, n, n_series, seed):
    """``n_series`` stationary AR(1) series x_t = φ x_{t−1} + ε_t with unit innovations."""
    rng = np.random.default_rng(seed)
    noise = rng.standard_normal((n_series, n))
    noise[:, 0] /= math.sqrt(1 - phi**2)  # start in the stationary distribution
    return lfilter([1.0], [1.0, -phi], noise, axis=1)


def variance_of_mean(phi, n):
    """Exact Var(x̄) of a stationary AR(1) of length n: (σ_x²/n)[1 + 2Σ_k (1 − k/n) φ^k]."""
    k = np.arange(1, n)
    return (1 / (1 - phi**2)) / n * (1 + 2 * np.sum((1 - k / n) * phi**k))


@pytest.mark.parametrize("phi", [0.0, 0.5, 0.9, 0.97])
def test_blocking_recovers_the_variance_of_the_mean(phi):
    n = 10_000  # not a power of two on purpose
    series = ar1(phi, n, 300, seed=int(phi * 100))
    estimates = [blocking_mean(x) for x in series]
    true = variance_of_mean(phi, n)
    mean_variance = np.mean([e.stderr**2 for e in estimates])
    assert mean_variance == pytest.approx(true, rel=0.08)
    assert np.mean([e.converged for e in estimates]) > 0.95
    # The errors are honest: about 68 % of the means fall within one standard error of 0.
    covered = np.mean([abs(e.mean) < e.stderr for e in estimates])
    assert 0.58 < covered < 0.78
    if phi == 0.0:
        assert np.median([e.block_size for e in estimates]) == 1


def test_blocking_flags_a_series_too_short_for_its_correlation():
    walks = np.cumsum(np.random.default_rng(5).standard_normal((50, 4096)), axis=1)
    assert not any(blocking_mean(x).converged for x in walks)


def test_blocking_tiny_inputs():
    assert math.isnan(blocking_mean([1.0]).stderr) and blocking_mean([1.0]).mean == 1.0
    estimate = blocking_mean([1.0, 3.0])
    assert estimate.mean == 2.0 and estimate.stderr == pytest.approx(1.0)
    assert not estimate.converged


@pytest.mark.parametrize("phi", [0.0, 0.8])
def test_batch_means_on_ar1(phi):
    n = 8192
    series = ar1(phi, n, 400, seed=7)
    estimates = [batch_means(x, 16) for x in series]
    assert np.mean([e.stderr**2 for e in estimates]) == pytest.approx(variance_of_mean(phi, n),
                                                                      rel=0.15)
    assert estimates[0].n_blocks == 16 and estimates[0].block_size == 512


def test_batch_means_drops_the_remainder_at_the_start():
    x = np.r_[100.0, np.arange(16.0)]
    estimate = batch_means(x, 8)
    assert estimate.mean == pytest.approx(7.5) and estimate.n_used == 16
    with pytest.raises(ValueError):
        batch_means([1.0, 2.0], 8)


def test_periodic_batch_means_uses_whole_periods():
    # 20 samples per strain unit from strain 4.05 to 20: a window of 16 strain units.
    strain = np.round(np.arange(81, 401) * 0.05, 12)
    oscillation = 0.05 * np.sin(2 * np.pi * strain)
    estimate = periodic_batch_means(strain, 1.0 + oscillation, period=1.0)
    assert estimate.n_blocks == 8 and estimate.block_size == 2.0 and estimate.n_used == 320
    # Whole periods cancel a pure oscillation exactly: the mean and its error see no bias.
    assert estimate.mean == pytest.approx(1.0, abs=1e-12) and estimate.stderr < 1e-12
    # 9.3 strain units: blocks of one unit, 9 of them; the first 0.3 units are left out.
    short = strain[strain > 20 - 9.3 + 1e-9]
    estimate = periodic_batch_means(short, 1.0 + 0.05 * np.sin(2 * np.pi * short), period=1.0)
    assert estimate.n_blocks == 9 and estimate.n_used == 180
    assert estimate.mean == pytest.approx(1.0, abs=1e-12)


def test_periodic_batch_means_on_ar1_with_uneven_sampling_per_block():
    # 7 samples per unit: blocks of whole units hold 7 samples; 24 units → 8 blocks of 3.
    n, phi = 7 * 24, 0.5
    coordinate = np.arange(1, n + 1) / 7
    series = ar1(phi, n, 2000, seed=3)
    estimates = [periodic_batch_means(coordinate, x, 1.0) for x in series]
    assert estimates[0].n_blocks == MIN_BLOCKS and estimates[0].block_size == 3.0
    assert np.mean([e.stderr**2 for e in estimates]) == pytest.approx(variance_of_mean(phi, n),
                                                                      rel=0.15)


def test_periodic_batch_means_needs_enough_periods():
    strain = np.arange(1, 101) * 0.05  # 5 strain units
    assert periodic_batch_means(strain, np.ones(100), period=1.0) is None
    with pytest.raises(ValueError):
        periodic_batch_means(strain[::-1], np.ones(100), period=1.0)
