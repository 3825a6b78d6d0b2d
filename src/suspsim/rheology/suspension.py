"""Reference laws for the viscosity of suspensions of rigid spheres (SPEC §1.2).

Used for plots and validation, never by the solver. Every function takes NumPy arrays
(broadcasting its array arguments) and returns an array, or a NumPy scalar for scalar input.
Volume fractions must satisfy 0 ≤ φ < 1 (``ValueError`` otherwise); the divergent laws return
``inf`` at and above their maximum packing fraction, where the suspension no longer flows.

Symbols:

=========== ================================================================ =========
symbol      meaning                                                          unit
=========== ================================================================ =========
φ           (volume_fraction) solid volume fraction                          1
φ_m         (phi_max) maximum (jamming) packing fraction                     1
η_r, g(φ)   (relative_viscosity) η_suspension/η_fluid, Newtonian matrix      1
[η]         (intrinsic_viscosity) dη_r/dφ at φ → 0; 2.5 for rigid spheres     1
c           (coefficient) O(φ²) coefficient of the dilute expansion          1
J           viscous number η_f γ̇/P (Boyer et al.)                            1
μ(J)        macroscopic friction coefficient τ/P                             1
η_n         normal viscosity P/(η_f γ̇) = 1/J                                 1
γ̇           macroscopic shear rate                                           1/s
μ_m(γ̇)      (matrix_viscosity) viscosity law of the matrix fluid             Pa s
τ_y, K, n   Herschel–Bulkley yield stress, consistency, flow index           Pa, Pa sⁿ, 1
=========== ================================================================ =========
"""
from __future__ import annotations

from typing import Callable

import numpy as np

#: O(φ²) coefficients of η_r = 1 + 2.5φ + cφ²: hydrodynamic pairs in shear (Batchelor & Green,
#: JFM 56, 401 (1972)), Brownian low-shear (Batchelor, JFM 83, 97 (1977)) and pure straining
#: flow (Batchelor & Green 1972).
BATCHELOR_HYDRODYNAMIC = 5.2
BATCHELOR_BROWNIAN = 6.2
BATCHELOR_GREEN_STRAINING = 7.6

#: Einstein's intrinsic viscosity of rigid spheres.
INTRINSIC_VISCOSITY_SPHERES = 2.5


def _as_result(x: np.ndarray) -> np.ndarray:
    """Return a NumPy scalar for 0-d arrays so scalar input gives scalar output."""
    return x[()]


def _volume_fraction(volume_fraction) -> np.ndarray:
    phi = np.asarray(volume_fraction, dtype=float)
    bad = ~((phi >= 0.0) & (phi < 1.0))
    if np.any(bad):
        raise ValueError(f"volume fraction must satisfy 0 <= phi < 1; got {phi[bad].flat[0]!r}")
    return phi


def _packing_fraction(phi_max) -> np.ndarray:
    phi_m = np.asarray(phi_max, dtype=float)
    bad = ~((phi_m > 0.0) & (phi_m <= 1.0))
    if np.any(bad):
        raise ValueError(f"maximum packing fraction must satisfy 0 < phi_max <= 1; "
                         f"got {phi_m[bad].flat[0]!r}")
    return phi_m


def _divergent_power(phi: np.ndarray, phi_max: np.ndarray, exponent) -> np.ndarray:
    """(1 − φ/φ_m)^(−exponent), and inf where φ ≥ φ_m (jammed: no flow)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        base = 1.0 - phi / phi_max
        return np.where(base > 0.0, np.abs(base) ** (-np.asarray(exponent, dtype=float)), np.inf)


def einstein(volume_fraction):
    """η_r = 1 + 2.5 φ [1], dilute rigid spheres in a Newtonian fluid.

    Einstein, Ann. Phys. 19, 289 (1906); correction Ann. Phys. 34, 591 (1911).
    """
    phi = _volume_fraction(volume_fraction)
    return _as_result(1.0 + INTRINSIC_VISCOSITY_SPHERES * phi)


def batchelor(volume_fraction, coefficient=BATCHELOR_HYDRODYNAMIC):
    """η_r = 1 + 2.5 φ + c φ² [1], the O(φ²) dilute expansion.

    c = 5.2: hydrodynamic pair interactions, non-Brownian (Batchelor & Green, JFM 56, 401 (1972));
    c = 6.2: Brownian spheres at low shear, 5.2 + ≈1.0 Brownian (Batchelor, JFM 83, 97 (1977));
    c = 7.6: pure straining flow (Batchelor & Green 1972). In simple shear of non-Brownian spheres
    the O(φ²) term is not uniquely defined (closed pair orbits), so only 2.5 φ is a hard check.
    """
    phi = _volume_fraction(volume_fraction)
    return _as_result(1.0 + INTRINSIC_VISCOSITY_SPHERES * phi + np.asarray(coefficient) * phi**2)


def krieger_dougherty(volume_fraction, phi_max, intrinsic_viscosity=INTRINSIC_VISCOSITY_SPHERES):
    """η_r = (1 − φ/φ_m)^(−[η] φ_m) [1]; inf for φ ≥ φ_m.

    Krieger & Dougherty, Trans. Soc. Rheol. 3, 137 (1959). Dilute slope dη_r/dφ = [η] for any
    φ_m. With φ_m = 0.57 it is the g(φ) Mahaut et al. (J. Rheol. 52, 287 (2008)) measured for
    beads in yield-stress fluids.
    """
    phi, phi_m = _volume_fraction(volume_fraction), _packing_fraction(phi_max)
    return _as_result(_divergent_power(phi, phi_m, np.asarray(intrinsic_viscosity) * phi_m))


def maron_pierce(volume_fraction, phi_max):
    """η_r = (1 − φ/φ_m)^(−2) [1]; inf for φ ≥ φ_m.

    Maron & Pierce, J. Colloid Sci. 11, 80 (1956). Dilute slope 2/φ_m. Fits: φ_m = 0.605, PMMA
    beads in oil by MRI (Ovarlez, Bertrand & Rodts, J. Rheol. 50, 259 (2006)); φ_m ≈ 0.656,
    smooth monodisperse spheres (Mueller, Llewellin & Mader, Proc. R. Soc. A 466, 1201 (2010)).
    """
    phi, phi_m = _volume_fraction(volume_fraction), _packing_fraction(phi_max)
    return _as_result(_divergent_power(phi, phi_m, 2.0))


def zarraga(volume_fraction):
    """η_r = exp(−2.34 φ) (1 − φ/0.62)^(−3) [1]; inf for φ ≥ 0.62.

    Zarraga, Hill & Leighton, J. Rheol. 44, 185 (2000): glass spheres, cone-plate, φ ≈ 0.30–0.55.
    """
    phi = _volume_fraction(volume_fraction)
    return _as_result(np.exp(-2.34 * phi) * _divergent_power(phi, 0.62, 3.0))


def _boyer_inverse_viscous_number(phi: np.ndarray, phi_max) -> np.ndarray:
    """1/J = (φ/(φ_m − φ))², from φ(J) = φ_m/(1 + J^½); inf for φ ≥ φ_m."""
    return phi**2 * _divergent_power(phi, phi_max, 2.0) / np.asarray(phi_max) ** 2


def boyer_shear_viscosity(volume_fraction, mu1=0.32, mu2=0.7, I0=0.005, phi_max=0.585):
    """Volume-imposed shear viscosity η_s = μ(J)/J [1] of Boyer, Guazzelli & Pouliquen.

    From μ(J) = μ1 + (μ2 − μ1)/(1 + I0/J) + J + (5/2) φ_m J^½ and φ(J) = φ_m/(1 + J^½)
    (PRL 107, 188301 (2011); PS/PMMA beads, 0.4 ≲ φ < 0.585), eliminating J = ((φ_m − φ)/φ)²:
    η_s = 1 + (5/2) φ/(1 − φ/φ_m) + μ1 (φ/(φ_m − φ))² + (μ2 − μ1)/(J + I0); inf for φ ≥ φ_m.
    The last term is written with 1/J so that φ = 0 gives exactly 1.
    """
    phi, phi_m = _volume_fraction(volume_fraction), _packing_fraction(phi_max)
    inv_j = _boyer_inverse_viscous_number(phi, phi_m)
    with np.errstate(invalid="ignore"):
        eta = (1.0 + 2.5 * phi * _divergent_power(phi, phi_m, 1.0) + mu1 * inv_j
               + (mu2 - mu1) * inv_j / (1.0 + I0 * inv_j))
    return _as_result(np.where(np.isfinite(inv_j), eta, np.inf))


def boyer_normal_viscosity(volume_fraction, phi_max=0.585):
    """Normal (particle-pressure) viscosity η_n = P/(η_f γ̇) = 1/J = (φ/(φ_m − φ))² [1].

    Boyer, Guazzelli & Pouliquen, PRL 107, 188301 (2011); inf for φ ≥ φ_m.
    """
    phi, phi_m = _volume_fraction(volume_fraction), _packing_fraction(phi_max)
    return _as_result(_boyer_inverse_viscous_number(phi, phi_m))


def boyer_friction_coefficient(volume_fraction, mu1=0.32, mu2=0.7, I0=0.005, phi_max=0.585):
    """Friction coefficient μ(J(φ)) = η_s/η_n [1] of Boyer, Guazzelli & Pouliquen (2011).

    J = ((φ_m − φ)/φ)²; μ → μ1 (quasi-static friction) for φ ≥ φ_m, inf at φ = 0. A dense-regime
    fit: meaningless below φ ≈ 0.3.
    """
    phi, phi_m = _volume_fraction(volume_fraction), _packing_fraction(phi_max)
    with np.errstate(divide="ignore", invalid="ignore"):
        root_j = np.maximum(phi_m - phi, 0.0) / phi
        mu = mu1 + (mu2 - mu1) / (1.0 + I0 / root_j**2) + root_j**2 + 2.5 * phi_m * root_j
    return _as_result(np.where(phi > 0.0, mu, np.inf))


def published_envelope(volume_fraction) -> tuple[np.ndarray, np.ndarray]:
    """(lowest, highest) η_r [1] of the published experimental fits at φ: Zarraga et al. (2000),
    Boyer et al. (2011) η_s, Maron–Pierce with φ_m = 0.605 (Ovarlez et al. 2006) and 0.656
    (Mueller et al. 2010), Krieger–Dougherty with φ_m = 0.57 (Mahaut et al. 2008).

    The spread is the experimental uncertainty of non-Brownian spheres in a Newtonian fluid
    (REFERENCE_NUMBERS §2a: 5.61–8.78 at φ = 0.4, 17.7–42.8 at φ = 0.5); meant for φ ≤ 0.5.
    """
    fits = np.stack(np.broadcast_arrays(
        zarraga(volume_fraction), boyer_shear_viscosity(volume_fraction),
        maron_pierce(volume_fraction, 0.605), maron_pierce(volume_fraction, 0.656),
        krieger_dougherty(volume_fraction, 0.57)))
    return _as_result(fits.min(axis=0)), _as_result(fits.max(axis=0))


def _cot_inputs(volume_fraction, relative_viscosity) -> tuple[np.ndarray, np.ndarray]:
    phi = _volume_fraction(volume_fraction)
    g = np.asarray(relative_viscosity, dtype=float)
    # Rigid inclusions can only add dissipation, so g ≥ 1; inf (jammed) is allowed.
    if np.any(~(g >= 1.0)):
        raise ValueError(f"relative viscosity g(phi) must be >= 1; got {g[~(g >= 1.0)].flat[0]!r}")
    return np.broadcast_arrays(phi, g)


def local_shear_rate_factor(volume_fraction, relative_viscosity):
    """γ̇_local/γ̇ = sqrt(g(φ)/(1 − φ)) [1], the mean shear-rate amplification in the matrix.

    Chateau, Ovarlez & Trung, J. Rheol. 52, 489 (2008): the dissipation of the suspension,
    g η_f γ̇², equals that of the fluid, (1 − φ) η_f γ̇_local², when the matrix is Newtonian.
    """
    phi, g = _cot_inputs(volume_fraction, relative_viscosity)
    return _as_result(np.sqrt(g / (1.0 - phi)))


def chateau_ovarlez_trung_viscosity(matrix_viscosity: Callable[[np.ndarray], np.ndarray],
                                    shear_rate, volume_fraction, relative_viscosity):
    """Suspension viscosity η(γ̇) = g(φ) μ_m(γ̇ sqrt(g(φ)/(1 − φ))) [Pa s].

    Homogenisation of Chateau, Ovarlez & Trung, J. Rheol. 52, 489 (2008) (SPEC §1.2): the matrix
    is sheared at the mean local rate of :func:`local_shear_rate_factor` and its secant viscosity
    is amplified by the Newtonian relative viscosity g(φ), e.g. ``krieger_dougherty(φ, 0.57)``.

    Parameters
    ----------
    matrix_viscosity : callable
        μ_m(γ̇) [Pa s]; takes and returns an ndarray of shear rates [1/s] of the same shape.
    shear_rate : array_like
        Macroscopic shear rate γ̇ ≥ 0 [1/s].
    volume_fraction, relative_viscosity : array_like
        φ [1] and g(φ) ≥ 1 [1]; g = inf (jammed) gives inf.
    """
    phi, g = _cot_inputs(volume_fraction, relative_viscosity)
    rate = np.asarray(shear_rate, dtype=float)
    if np.any(~(rate >= 0.0)):
        raise ValueError("shear rate must be >= 0")
    rate, phi, g = np.broadcast_arrays(rate, phi, g)
    jammed = np.isinf(g)
    factor = np.sqrt(np.where(jammed, 1.0, g) / (1.0 - phi))
    eta = np.where(jammed, 1.0, g) * np.asarray(matrix_viscosity(rate * factor), dtype=float)
    return _as_result(np.where(jammed, np.inf, eta))


def cot_herschel_bulkley(tau_y, K, n, volume_fraction, relative_viscosity):
    """Herschel–Bulkley parameters (τ_y(φ) [Pa], K(φ) [Pa sⁿ], n [1]) of the suspension.

    Chateau, Ovarlez & Trung, J. Rheol. 52, 489 (2008), for τ = τ_y + K γ̇ⁿ in the matrix:
    τ_y(φ) = τ_y sqrt((1 − φ) g), K(φ) = K (1 − φ)^((1−n)/2) g^((1+n)/2), n unchanged. In the
    plastic regime η_susp/η_matrix = sqrt((1 − φ) g); n = 1 gives K(φ)/K = g.
    """
    phi, g = _cot_inputs(volume_fraction, relative_viscosity)
    tau_y, K, n = (np.asarray(v, dtype=float) for v in (tau_y, K, n))
    if np.any(~(tau_y >= 0.0)) or np.any(~(K > 0.0)) or np.any(~(n > 0.0)):
        raise ValueError("Herschel-Bulkley parameters need tau_y >= 0, K > 0 and n > 0")
    tau_phi = tau_y * np.sqrt((1.0 - phi) * g)
    k_phi = K * (1.0 - phi) ** ((1.0 - n) / 2.0) * g ** ((1.0 + n) / 2.0)
    return _as_result(tau_phi), _as_result(k_phi), _as_result(n)
