"""Physics terms of the DST solver (2D and 3D): one small ``@njit`` function per equation
(SPEC §5.1, §1.3).

Pair terms take the pair geometry (x_ij = x_i − x_j, r² and F = −W'(r)/r of the quintic spline,
so ∇_iW_ij = −x_ij F) and return the contribution to particle i; pair loops live in
:mod:`~suspsim.dst.passes`. References: J. P. Morris, P. J. Fox, Y. Zhu, J. Comput. Phys. 136,
214 (1997) (viscous term, Laplacian, step criteria); J. J. Monaghan, Annu. Rev. Astron.
Astrophys. 30, 543 (1992) (continuity, pressure); Wyart & Cates, PRL 112, 098302 (2014), seed 002
(microstructure).

Symbols (SI units; any consistent set works):

========= ============================================================ ==========
symbol    meaning                                                      unit
========= ============================================================ ==========
m         particle mass ρ0 Δx^d (2D: ρ0 Δx² per unit depth)            kg (2D: kg/m)
ρ, ρ0     density, reference density                                   kg/m³
p, p_b    pressure, background pressure                                Pa
c         artificial sound speed                                       m/s
γ_t       Tait exponent (7)                                            1
x_ij, r   pair vector x_i − x_j, its length                            m
F         −W'(r)/r, so ∇_iW_ij = −x_ij F                               1/m^(d+2)
h_sl      quintic smoothing length (support 3 h_sl)                    m
v_ij      v_i − v_j                                                    m/s
η         viscosity                                                    Pa s
G         velocity gradient, G_ab ≈ ∂v_a/∂x_b                           1/s
γ̇         shear-rate magnitude sqrt(2 D:D), D = (G + Gᵀ)/2             1/s
f, f̂      frictional fraction, its steady value                        1
σ         local stress magnitude η γ̇                                   Pa
K_f, α    relaxation constant, diffusivity of f                        1, m²/s
========= ============================================================ ==========

(d the dimension; 2D masses and forces are per unit depth; any consistent units work the same
way.) No term carries a factor of d: Morris's viscous term and Laplacian are dimension-free
(the kernel's normalisation, :mod:`suspsim.sph.kernels`, holds the dimension), and
γ̇ = sqrt(2 D:D) sums over the d × d tensor (:func:`shear_rate_2d`, :func:`shear_rate_3d`).
"""
from __future__ import annotations

import math

from numba import njit

from suspsim.rheology.wyart_cates import wc_frictional_fraction
from suspsim.sph import JIT_OPTIONS

#: Tait exponent γ of the equation of state (SPEC §5.1).
TAIT_EXPONENT = 7.0
#: Morris's regulariser 0.01 h² in the viscous and Laplacian denominators (h = h_sl).
EPSILON = 0.01


@njit(**JIT_OPTIONS)
def tait_pressure(rho, rho0, c, p_b):
    """p = (ρ0 c²/γ_t)((ρ/ρ0)^γ_t − 1) + p_b, γ_t = 7 (Tait EOS with background pressure)."""
    return rho0 * c * c / TAIT_EXPONENT * ((rho / rho0) ** TAIT_EXPONENT - 1.0) + p_b


@njit(**JIT_OPTIONS)
def tait_density(p, rho0, c, p_b):
    """ρ = ρ0 (1 + γ_t (p − p_b)/(ρ0 c²))^(1/γ_t), the inverse Tait EOS (wall density, §5.3).

    Clamped at ρ = 0 for pressures below the EOS's floor −ρ0 c²/γ_t + p_b.
    """
    base = 1.0 + TAIT_EXPONENT * (p - p_b) / (rho0 * c * c)
    if base <= 0.0:
        return 0.0
    return rho0 * base ** (1.0 / TAIT_EXPONENT)


@njit(**JIT_OPTIONS)
def continuity_pair(m_j, vx, vy, x, y, F):
    """m_j v_ij·∇_iW_ij = −m_j F (v_ij·x_ij), one term of dρ_i/dt = Σ_j m_j v_ij·∇_iW_ij."""
    return -m_j * F * (vx * x + vy * y)


@njit(**JIT_OPTIONS)
def continuity_pair_3d(m_j, vx, vy, vz, x, y, z, F):
    """:func:`continuity_pair` in 3D: −m_j F (v_ij·x_ij)."""
    return -m_j * F * (vx * x + vy * y + vz * z)


@njit(**JIT_OPTIONS)
def pressure_pair(m_j, p_i, rho_i, p_j, rho_j, F):
    """Scalar s with −m_j (p_i/ρ_i² + p_j/ρ_j²) ∇_iW_ij = s x_ij, s = m_j (p_i/ρ_i² + p_j/ρ_j²) F.

    Monaghan 1992 symmetric pressure gradient; antisymmetric in i ↔ j (momentum conserved).
    """
    return m_j * (p_i / (rho_i * rho_i) + p_j / (rho_j * rho_j)) * F


@njit(**JIT_OPTIONS)
def morris_viscous_pair(m_j, eta_i, eta_j, rho_i, rho_j, r2, F, h_sl):
    """Scalar s with dv_i/dt|_visc += s v_ij, Morris et al. 1997 Eq. 6:

    m_j (η_i + η_j)(x_ij·∇_iW_ij)/(ρ_i ρ_j (r² + 0.01 h_sl²)) = −m_j (η_i + η_j) r² F/(ρ_i ρ_j
    (r² + 0.01 h_sl²)) ≤ 0 (a drag towards v_j; tends to ∇·(η∇v) for smooth η).
    """
    return -m_j * (eta_i + eta_j) * r2 * F / (rho_i * rho_j * (r2 + EPSILON * h_sl * h_sl))


@njit(**JIT_OPTIONS)
def laplacian_pair(v_j, f_i, f_j, r2, F, h_sl):
    """V_j 2 (f_i − f_j)(x_ij·∇_iW_ij)/(r² + 0.01 h_sl²), i.e. −2 V_j (f_i − f_j) r² F/(r² + ε h_sl²).

    One term of the Morris/Brookshaw Laplacian ∇²f_i (SPEC §5.1); antisymmetric in i ↔ j for
    equal volumes, so Σ_i V_i ∇²f_i = 0 (f is conserved, zero flux where the sum stops).
    """
    return -2.0 * v_j * (f_i - f_j) * r2 * F / (r2 + EPSILON * h_sl * h_sl)


@njit(**JIT_OPTIONS)
def shear_rate_2d(gxx, gxy, gyx, gyy):
    """γ̇ = sqrt(2 D:D), D = (G + Gᵀ)/2: sqrt(2 gxx² + 2 gyy² + (gxy + gyx)²) (SPEC §1.3).

    Exactly |du/dy| in simple shear u = γ̇ y (G_xy = γ̇) and 0 under rigid rotation.
    """
    s = gxy + gyx
    return math.sqrt(2.0 * gxx * gxx + 2.0 * gyy * gyy + s * s)


@njit(**JIT_OPTIONS)
def shear_rate_3d(g):
    """γ̇ = sqrt(2 D:D) of G (``g`` the 9 components G_ab at 3a + b, G_ab ≈ ∂v_a/∂x_b):
    sqrt(2 (G_xx² + G_yy² + G_zz²) + (G_xy + G_yx)² + (G_xz + G_zx)² + (G_yz + G_zy)²).

    |du/dy| in simple shear u = γ̇ y, 0 under rigid rotation (SPEC §1.3).
    """
    sxy = g[1] + g[3]
    sxz = g[2] + g[6]
    syz = g[5] + g[7]
    return math.sqrt(2.0 * (g[0] * g[0] + g[4] * g[4] + g[8] * g[8])
                     + sxy * sxy + sxz * sxz + syz * syz)


@njit(**JIT_OPTIONS)
def jamming_fraction(f, phi_m, phi_0):
    """φ_J(f) = f φ_m + (1 − f) φ_0 (Wyart & Cates 2014)."""
    return f * phi_m + (1.0 - f) * phi_0


@njit(**JIT_OPTIONS)
def suspension_viscosity(f, eta_s, phi, phi_m, phi_0):
    """η = η_s (1 − φ/φ_J(f))^−2 (Maron–Pierce, seed 002); −1.0 flags φ ≥ φ_J (jammed).

    The caller turns the flag into a NumericalError; no inf or NaN enters the pair sums.
    """
    phi_j = jamming_fraction(f, phi_m, phi_0)
    if phi >= phi_j:
        return -1.0
    r = 1.0 - phi / phi_j
    return eta_s / (r * r)


@njit(**JIT_OPTIONS)
def microstructure_rate(f, gdot, eta, K_f, sigma_star, beta, alpha, laplacian):
    """Df/Dt = K_f γ̇ (f̂(σ) − f) + α ∇²f with σ = η γ̇, f̂ = exp(−(σ*/σ)^β) (SPEC §1.3)."""
    sigma = eta * gdot
    return K_f * gdot * (wc_frictional_fraction(sigma, sigma_star, beta) - f) + alpha * laplacian
