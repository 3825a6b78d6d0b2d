"""Suspension reference laws against REFERENCE_NUMBERS.md §1, §2a, §4a and SPEC §1.2."""
import math

import numpy as np
import pytest

from suspsim.rheology.suspension import (
    BATCHELOR_BROWNIAN, BATCHELOR_GREEN_STRAINING, batchelor, boyer_friction_coefficient,
    boyer_normal_viscosity, boyer_shear_viscosity, chateau_ovarlez_trung_viscosity,
    cot_herschel_bulkley, einstein, krieger_dougherty, local_shear_rate_factor, maron_pierce,
    published_envelope, zarraga)


def assert_printed(value, printed):
    """``value`` rounds to ``printed``: within half a unit of its last digit, at >= 3 s.f.

    A table printing 2.90 as "2.9" still means three significant digits.
    """
    p = float(printed)
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    decimals = max(decimals, 2 - math.floor(math.log10(abs(p))))
    assert abs(value - p) <= 0.5 * 10.0 ** (-decimals) * (1 + 1e-9), (value, printed)


# REFERENCE_NUMBERS.md §2a: φ, Einstein, Batchelor 6.2, B&G 7.6, Zarraga, Boyer η_s, η_n, μ,
# MP φm=0.605, KD φm=0.57, MP φm=0.656.
TABLE_2A = """
0.05 1.125 1.141 1.144 1.14 1.14 0.00873 130.839 1.19 1.14 1.17
0.10 1.250 1.312 1.326 1.34 1.33 0.0425 31.316 1.44 1.32 1.39
0.15 1.375 1.514 1.546 1.62 1.59 0.119 13.351 1.77 1.55 1.68
0.20 1.500 1.748 1.804 2.01 1.95 0.27 7.220 2.23 1.85 2.07
0.25 1.625 2.013 2.100 2.62 2.48 0.557 4.454 2.9 2.28 2.61
0.30 1.750 2.308 2.434 3.6 3.31 1.11 2.990 3.93 2.9 3.4
0.35 1.875 2.635 2.806 5.34 4.72 2.22 2.129 5.63 3.88 4.6
0.40 2.000 2.992 3.216 8.78 7.39 4.67 1.582 8.71 5.61 6.57
0.45 2.125 3.381 3.664 16.9 13.4 11.1 1.209 15.2 9.21 10.1
0.50 2.250 3.800 4.150 42.8 31.9 34.6 0.921 33.2 19.9 17.7
0.52 2.300 3.976 4.355 70.6 51.6 64 0.806 50.7 32.1 23.3
0.54 2.350 4.158 4.566 132 96.4 144 0.670 86.6 66.4 32
0.55 2.375 4.251 4.674 192 145 247 0.587 121 118 38.3
0.56 2.400 4.344 4.783 298 249 502 0.496 181 318 46.7
"""
LAWS_2A = [
    einstein,
    lambda p: batchelor(p, BATCHELOR_BROWNIAN),
    lambda p: batchelor(p, BATCHELOR_GREEN_STRAINING),
    zarraga,
    boyer_shear_viscosity,
    boyer_normal_viscosity,
    boyer_friction_coefficient,
    lambda p: maron_pierce(p, 0.605),
    lambda p: krieger_dougherty(p, 0.57),
    lambda p: maron_pierce(p, 0.656),
]
ROWS_2A = [line.split() for line in TABLE_2A.strip().splitlines()]


@pytest.mark.parametrize("row", ROWS_2A, ids=[r[0] for r in ROWS_2A])
def test_table_2a(row):
    phi = float(row[0])
    for law, printed in zip(LAWS_2A, row[1:], strict=True):
        assert_printed(float(law(phi)), printed)


# REFERENCE_NUMBERS.md §4a: φ, g, τ_y/τ_y0, K/K0 for n = 0.3, 0.4, 0.5, 0.6, 1, γ̇_local/γ̇.
TABLE_4A = """
0.05 1.140 1.041 1.069 1.079 1.089 1.099 1.140 1.095
0.10 1.316 1.088 1.152 1.174 1.197 1.220 1.316 1.209
0.15 1.545 1.146 1.254 1.292 1.331 1.371 1.545 1.348
0.20 1.851 1.217 1.380 1.439 1.501 1.565 1.851 1.521
0.25 2.277 1.307 1.543 1.632 1.725 1.823 2.277 1.742
0.30 2.900 1.425 1.763 1.893 2.033 2.183 2.900 2.035
0.35 3.883 1.589 2.077 2.271 2.484 2.716 3.883 2.444
0.40 5.607 1.834 2.565 2.868 3.207 3.586 5.607 3.057
0.45 9.211 2.251 3.435 3.955 4.553 5.242 9.211 4.092
0.50 19.854 3.151 5.473 6.579 7.909 9.508 19.854 6.301
"""
ROWS_4A = [line.split() for line in TABLE_4A.strip().splitlines()]


@pytest.mark.parametrize("row", ROWS_4A, ids=[r[0] for r in ROWS_4A])
def test_table_4a_chateau_ovarlez_trung(row):
    phi = float(row[0])
    g = krieger_dougherty(phi, 0.57)
    assert_printed(g, row[1])
    for n, printed_k in zip((0.3, 0.4, 0.5, 0.6, 1.0), row[3:8], strict=True):
        tau_ratio, k_ratio, n_phi = cot_herschel_bulkley(1.0, 1.0, n, phi, g)
        assert_printed(tau_ratio, row[2])
        assert_printed(k_ratio, printed_k)
        assert n_phi == n
    assert_printed(local_shear_rate_factor(phi, g), row[8])


@pytest.mark.parametrize("phi_max", [0.55, 0.605, 0.64, 0.74, 1.0])
def test_dilute_slopes(phi_max):
    """KD has slope [η] for any φ_m; MP has 2/φ_m (second-order one-sided difference at 0)."""
    h = 1e-5

    def slope(law):
        return (-3 * law(0.0) + 4 * law(h) - law(2 * h)) / (2 * h)

    assert krieger_dougherty(0.0, phi_max) == 1.0
    assert slope(lambda p: krieger_dougherty(p, phi_max)) == pytest.approx(2.5, abs=1e-8)
    assert slope(lambda p: krieger_dougherty(p, phi_max, 3.1)) == pytest.approx(3.1, abs=1e-8)
    assert slope(lambda p: maron_pierce(p, phi_max)) == pytest.approx(2 / phi_max, abs=1e-8)


def test_dilute_laws_agree_with_einstein():
    """REFERENCE_NUMBERS §1: only the 2.5φ term is a hard check, |η_r − 1 − 2.5φ| < 0.1 at 0.02."""
    phi = 0.02
    assert einstein(phi) == pytest.approx(1.05, rel=1e-15)
    assert batchelor(phi) == pytest.approx(1.05 + 5.2 * phi**2, rel=1e-15)
    for law in (zarraga, boyer_shear_viscosity, lambda p: maron_pierce(p, 0.605),
                lambda p: krieger_dougherty(p, 0.57)):
        assert abs(law(phi) - 1 - 2.5 * phi) < 0.1


def test_divergence_and_validation():
    phi = np.array([0.3, 0.57, 0.6])
    np.testing.assert_array_equal(np.isinf(krieger_dougherty(phi, 0.57)), [False, True, True])
    np.testing.assert_array_equal(np.isinf(maron_pierce(phi, 0.57)), [False, True, True])
    assert np.isinf(zarraga(0.62)) and np.isinf(boyer_shear_viscosity(0.585))
    assert boyer_friction_coefficient(0.585) == pytest.approx(0.32, rel=1e-15)
    for bad in (-0.01, 1.0, np.nan):
        for law in (einstein, batchelor, zarraga, boyer_shear_viscosity,
                    lambda p: krieger_dougherty(p, 0.6), lambda p: maron_pierce(p, 0.6)):
            with pytest.raises(ValueError, match="volume fraction"):
                law(bad)
    with pytest.raises(ValueError, match="packing fraction"):
        maron_pierce(0.3, 0.0)
    with pytest.raises(ValueError, match="relative viscosity"):
        local_shear_rate_factor(0.3, 0.9)


def test_vectorised_shapes():
    phi = np.linspace(0.0, 0.5, 12).reshape(3, 4)
    for law in (einstein, batchelor, zarraga, boyer_shear_viscosity,
                lambda p: krieger_dougherty(p, 0.57), lambda p: maron_pierce(p, 0.605)):
        out = law(phi)
        assert out.shape == (3, 4)
        np.testing.assert_allclose(out[1], [law(p) for p in phi[1]], rtol=1e-14)  # SIMD pow: 1 ulp
    assert np.ndim(einstein(0.1)) == 0


def hb_matrix(tau_y, K, n):
    """Unregularised Herschel–Bulkley secant viscosity τ_y/γ̇ + K γ̇^(n−1) [Pa s]."""
    return lambda rate: tau_y / rate + K * rate ** (n - 1.0)


@pytest.mark.parametrize("phi", [0.1, 0.3, 0.45])
def test_cot_numerical_matrix_equals_closed_form(phi):
    """g μ_HB(γ̇ sqrt(g/(1−φ))) is HB with τ_y(φ), K(φ), same n, in both regimes."""
    tau_y, K, n = 2.0, 0.5, 0.4  # plastic below ≈ (τ_y/K)^(1/n) = 32 1/s
    g = krieger_dougherty(phi, 0.57)
    tau_phi, k_phi, _ = cot_herschel_bulkley(tau_y, K, n, phi, g)
    rates = np.array([1e-12, 1e-10, 1e10, 1e12])
    eta = chateau_ovarlez_trung_viscosity(hb_matrix(tau_y, K, n), rates, phi, g)
    np.testing.assert_allclose(eta, tau_phi / rates + k_phi * rates ** (n - 1.0), rtol=1e-13)
    # The rates are deep in each regime: τ ≈ τ_y(φ) (plastic), then τ ≈ K(φ) γ̇ⁿ (power law).
    np.testing.assert_allclose(eta[:2] * rates[:2], tau_phi, rtol=1e-3)
    np.testing.assert_allclose(eta[2:] * rates[2:] ** (1 - n), k_phi, rtol=1e-3)


@pytest.mark.parametrize("phi", [0.05, 0.3, 0.5])
def test_cot_newtonian_matrix_gives_g(phi):
    g = krieger_dougherty(phi, 0.57)
    rates = np.array([0.0, 1e-3, 1.0, 1e3])
    eta = chateau_ovarlez_trung_viscosity(lambda r: np.full_like(r, 0.7), rates, phi, g)
    np.testing.assert_allclose(eta, 0.7 * g, rtol=1e-15)
    tau_phi, k_phi, _ = cot_herschel_bulkley(0.0, 0.7, 1.0, phi, g)
    assert tau_phi == 0.0 and k_phi == pytest.approx(0.7 * g, rel=1e-15)


def test_spec_plastic_regime_claim():
    """SPEC §1.2: φ = 0.4, g = 10, plastic regime: η_susp/η_matrix = sqrt((1 − φ) g) ≈ 2.45."""
    phi, g, rate = 0.4, 10.0, 1e-10
    matrix = hb_matrix(1.0, 1.0, 0.5)
    ratio = chateau_ovarlez_trung_viscosity(matrix, rate, phi, g) / matrix(rate)
    assert ratio == pytest.approx(math.sqrt(6.0), rel=1e-4)
    assert_printed(ratio, "2.45")


def test_cot_jammed_and_broadcast():
    g = krieger_dougherty(np.array([0.3, 0.6]), 0.57)
    eta = chateau_ovarlez_trung_viscosity(hb_matrix(1.0, 1.0, 0.5), 1.0, [0.3, 0.6], g)
    assert np.isfinite(eta[0]) and np.isinf(eta[1])
    with pytest.raises(ValueError, match="shear rate"):
        chateau_ovarlez_trung_viscosity(hb_matrix(1.0, 1.0, 0.5), -1.0, 0.3, 2.0)


@pytest.mark.parametrize("row", [r for r in ROWS_2A if float(r[0]) <= 0.5],
                         ids=[r[0] for r in ROWS_2A if float(r[0]) <= 0.5])
def test_published_envelope_is_the_min_max_of_the_experimental_fits(row):
    """§2a's read-across: the band of the Zarraga, Boyer η_s, MP 0.605, KD 0.57, MP 0.656 columns
    (5.61–8.78 at φ = 0.4, 17.7–42.8 at 0.5)."""
    printed = [row[i] for i in (4, 5, 8, 9, 10)]
    low, high = published_envelope(float(row[0]))
    assert_printed(float(low), min(printed, key=float))
    assert_printed(float(high), max(printed, key=float))
