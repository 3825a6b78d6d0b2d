"""Lubrication between rigid bodies: the near-contact flow SPH cannot resolve (SPEC §3.3–3.4).

**Spheres** (Jeffrey & Onishi 1984; Kim & Karrila 1991, ch. 11). Radii a1, a2, λ = a2/a1, centre
separation r, gap s = r − a1 − a2, ξ = 2s/(a1 + a2), L = ln(1/ξ), d the unit vector from 1 to 2.
The resistance form (SPEC §3.3), F_α = −μ Σ_β (A_αβ·U_β + B̃_αβ·Ω_β), T_α = −μ Σ_β (B_αβ·U_β +
C_αβ·Ω_β), with A11 = 6πa1[X11A dd + Y11A (I − dd)], A12 = 3π(a1+a2)[X12A dd + Y12A (I − dd)],
B11 = 4πa1² Y11B ε·d, B12 = π(a1+a2)² Y12B ε·d, C11 = 8πa1³[X11C dd + Y11C (I − dd)],
C12 = π(a1+a2)³[X12C dd + Y12C (I − dd)], B̃_αβ = B_βαᵀ. Blocks 2· follow from 1· by relabelling
(λ → 1/λ, d → −d). The functions ``*_singular`` give the singular parts g1/ξ + g2 L + g3 ξL:

- X11A (squeeze): g1 = 2λ²/(1+λ)³, g2 = λ(1+7λ+λ²)/(5(1+λ)³),
  g3 = (1+18λ−29λ²+18λ³+λ⁴)/(42(1+λ)³); λ = 1: 1/4, 9/40, 3/112;
- Y11A (shear): g2 = 4λ(2+λ+2λ²)/(15(1+λ)³), g3 = 2(16−45λ+58λ²−45λ³+16λ⁴)/(375(1+λ)³);
  λ = 1: 1/6, 0;
- Y11B (pump): g2 = −λ(4+λ)/(5(1+λ)²), g3 = −(32−33λ+83λ²+43λ³)/(250(1+λ)²); λ = 1: −1/4, −1/8;
- Y11C (roll): g2 = 2λ/(5(1+λ)), g3 = (8+6λ+33λ²)/(125(1+λ)); λ = 1: 1/5, 47/250;
- Y12C (roll, normalised by 8πa1³ as in SPEC's table): g2 = λ²/(10(1+λ)),
  g3 = λ(43−24λ+43λ²)/(500(1+λ)); λ = 1: 1/20, 31/500;
- X11C (twist, not singular, normalised by 8πa1³): only g3 = −λ²/(4(1+λ)); λ = 1: −1/8.

The 12 functions share the 11 coefficients (Jeffrey & Onishi 1984; corrected forms in Townsend
2018, arXiv:1802.08226): X12A = −2/(1+λ)·X11A, Y12A = −2/(1+λ)·Y11A, Y12B = −4/(1+λ)²·Y11B
(singular parts), which is exactly the statement that co-translation U1 = U2 carries no
singular force or torque (A11 + A12 = 0, B11 + B12 = 0). In the π(a1+a2)³ normalisation of C12
the Y12C row above is multiplied by 8/(1+λ)³ (it must be: only then is C12 = C21ᵀ), and
likewise X12C = −8/(1+λ)³·X11C (no singular twist torque under co-rotation about d). The twist
has no singular term; its ξL term (a finite torque that falls as the gap opens) is kept because
it costs one multiply.

**Mode form (the hot path)** [derived]. Rigid motion of the pair (co-translation, and rotation
U_α = Ω × x_α, Ω1 = Ω2 = Ω) must give no singular force. Write the motion in the modes (six
components) that vanish on rigid motion: normal approach u_n = (U1 − U2)·d, sliding
σ = (I − dd)(U1 − U2) + κ (a1 Ω1 + a2 Ω2) × d with κ = r/(a1 + a2) = 1 + ξ/2 (the relative
velocity of the two contact points), rolling ρ = (Ω1 − Ω2) × d, and twist ω_n = (Ω1 − Ω2)·d.
Then, per unit viscosity,

    F1 = −μ [M_n u_n d + M_σσ σ + M_σρ ρ] = −F2
    T1 = −μ [κ a1 d × f_σ + d × f_ρ + M_t ω_n d],   T2 = −μ [κ a2 d × f_σ − d × f_ρ − M_t ω_n d]
    f_σ = M_σσ σ + M_σρ ρ,   f_ρ = M_σρ σ + M_ρρ ρ

so R = Qᵀ M Q is symmetric, annihilates every rigid motion *exactly*, conserves linear and
angular momentum (T1 + T2 + (x1 − x2) × F1 = 0), and is positive semi-definite whenever the
mode matrix is. Matching the entries of Qᵀ M Q to the functions above (and expanding κ, κ²):

    M_n  = 6πa1 X11A
    M_σσ = 6πa1 Y11A                               log coefficient 8πλ(2+λ+2λ²)/(5(1+λ)³) a1
    M_σρ = −4πa1² Y11B − κ a1 M_σσ                 log coefficient 12πλ²(1−λ)/(5(1+λ)³) a1²
    M_ρρ = 8πa1³ (Y11C + κ Y11B + ¾ κ² Y11A)       log coefficient 24πλ³/(5(1+λ)³) a1³
    M_t  = 8πa1³ X11C

each truncated at order ξL. With the table's coefficients, the same M follows from sphere 2's
functions (λ → 1/λ) and reproduces Y12C, Y12B(1/λ), Y11B(1/λ), Y11C(1/λ) to the same order —
checked in exact rational arithmetic for several λ, and numerically in the tests: the mode form
and the SPEC block form (:func:`jeffrey_onishi_matrix`) differ by O(ξ² ln(1/ξ)) only. This is
also how Y12C's normalisation and its 1/500 (not 1/250) were confirmed.

**Correction form** [Nguyen & Ladd 2002, Phys. Rev. E 66, 046708; Martys 2005]: the SPH fluid
resolves the flow down to a gap of order the particle spacing, so every function f above is
replaced by f(max(s, s_min)) − f(s_c) for s < s_c and 0 for s ≥ s_c (``cutoff_gap`` s_c, to be
calibrated against the resolved squeeze force; ``min_gap`` s_min, below which the resistances
are held). ``cutoff_gap = inf`` gives the bare singular parts (reference and tests only: the
bare twist term is negative). With s_c finite the mode matrix is positive semi-definite for
every s < s_c when ξ_c = 2s_c/(a1+a2) ≤ 1 and 0.1 ≤ λ ≤ 10 (checked in the tests on a grid);
the twist correction is clamped at ≥ 0, which only bites for ξ_c > 1/e.

**Repulsion** (seed 000: "F_AB ∼ C/s^8, directed radially"): F = C (1/max(s, s_min)⁸ − 1/s_c⁸)
for s < s_c, 0 beyond, pushing the bodies apart along d [choice: the shift makes it continuous at
the cutoff, the inner cap makes it finite]; C is ``repulsion_strength``, the exponent
:data:`REPULSION_EXPONENT`.

**Shear-thinning matrix** [seed 000, heuristic]: the lubrication viscosity is the matrix law at
the gap shear rate γ̇_gap = |v_c1 − v_c2| / max(s, s_min), v_cα the velocities of the two closest
surface points (:func:`gap_viscosity`). It is a first approximation; the true gap flow is not a
simple shear.

**Curved non-spherical surfaces** (SPEC §3.4) [derived]: with the gap h = s + xᵀKx/2 near the
closest points, K = K_A + K_B, the Reynolds equation ∇·(h³∇p) = 12μ ∂h/∂t = −12μU is solved
exactly by p = 3μU/(α + β)/h² (α, β = eigenvalues of K/2), whose integral gives
F = 12πμU/(s tr K √det K) (:func:`curved_squeeze_coefficient`). K is positive semi-definite at a
true closest point.

Units: simulation units throughout — lengths [h] (the SPH support radius), velocities [h τ⁻¹],
angular velocities [τ⁻¹], viscosity [m h⁻¹ τ⁻¹], forces [m h τ⁻²], torques [m h² τ⁻²].

Symbols:

========= ================================================== ==============
symbol    meaning                                            unit
========= ================================================== ==============
a1, a2    sphere radii (hydrodynamic, calibrated: SPEC §3.1) [h]
λ (lam)   size ratio a2/a1                                   1
r12       centre difference x1 − x2 (SPEC: r_pq = r_p − r_q) [h]
d         unit vector from 1 to 2, d = −r12/|r12|            1
s         surface gap |r12| − a1 − a2                        [h]
ξ (xi)    scaled gap 2s/(a1 + a2) = s/ℓ, ℓ = (a1 + a2)/2     1
κ         r/(a1 + a2) = 1 + ξ/2                              1
s_c       cutoff_gap: the correction vanishes for s ≥ s_c    [h]
s_min     min_gap: resistances and repulsion held below it   [h]
C         repulsion_strength, F = C/s⁸                       [m h⁹ τ⁻²]
U, Ω (W)  body velocity, angular velocity                    [h τ⁻¹], [τ⁻¹]
μ (mu)    matrix viscosity at the gap                        [m h⁻¹ τ⁻¹]
M_n, M_σσ normal, sliding resistance per unit viscosity      [h]
M_σρ      sliding–rolling coupling per unit viscosity        [h²]
M_ρρ, M_t rolling, twist resistance per unit viscosity       [h³]
k1, k2    principal curvatures (positive when convex)        [h⁻¹]
ω         angle between the two surfaces' principal frames   rad
========= ================================================== ==============

References: D. J. Jeffrey, Y. Onishi (1984), J. Fluid Mech. 139, 261; S. Kim, S. J. Karrila
(1991), Microhydrodynamics, ch. 11; A. K. Townsend (2018), arXiv:1802.08226 (corrected
coefficients); N.-Q. Nguyen, A. J. C. Ladd (2002), Phys. Rev. E 66, 046708; N. S. Martys (2005),
J. Rheol. 49, 401; Martys et al. (2010), Rheol. Acta 49, 1059 (seed 000).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from suspsim.rheology.laws import viscosity_kernel
from suspsim.sph import JIT_OPTIONS

__all__ = [
    "REPULSION_EXPONENT", "check_gap_parameters", "curvature_determinant",
    "curved_squeeze_coefficient", "curved_squeeze_coefficient_frames", "gap_shear_rate",
    "gap_viscosity", "jeffrey_onishi_matrix", "lubrication_pair_force", "normal_potential",
    "normal_resistance", "pair_mode_resistances", "pump_coefficients", "repulsion_force",
    "repulsion_slope",
    "resistance_matrix", "roll_coefficients", "roll_cross_coefficients", "shear_coefficients",
    "sphere_squeeze_law", "squeeze_coefficients", "twist_coefficient", "x11a_singular",
    "x11c_singular", "x12a_singular", "x12c_singular", "y11a_singular", "y11b_singular",
    "y11c_singular", "y12a_singular", "y12b_singular", "y12c_singular",
]

#: Exponent of the short-range repulsion F = C/s^8 (seed 000, read from garbled text: SPEC §3.3).
REPULSION_EXPONENT = 8


# ---------------------------------------------------------------------------------------------
# Coefficients of the singular parts, sphere 1's functions, λ = a2/a1 (module docstring table)

@njit(**JIT_OPTIONS)
def squeeze_coefficients(lam):
    """(g1, g2, g3) of X11A: 2λ²/(1+λ)³, λ(1+7λ+λ²)/(5(1+λ)³), (1+18λ−29λ²+18λ³+λ⁴)/(42(1+λ)³)."""
    q3 = (1.0 + lam) ** 3
    l2 = lam * lam
    return (2.0 * l2 / q3, lam * (1.0 + 7.0 * lam + l2) / (5.0 * q3),
            (1.0 + 18.0 * lam - 29.0 * l2 + 18.0 * l2 * lam + l2 * l2) / (42.0 * q3))


@njit(**JIT_OPTIONS)
def shear_coefficients(lam):
    """(g2, g3) of Y11A: 4λ(2+λ+2λ²)/(15(1+λ)³), 2(16−45λ+58λ²−45λ³+16λ⁴)/(375(1+λ)³)."""
    q3 = (1.0 + lam) ** 3
    l2 = lam * lam
    return (4.0 * lam * (2.0 + lam + 2.0 * l2) / (15.0 * q3),
            2.0 * (16.0 - 45.0 * lam + 58.0 * l2 - 45.0 * l2 * lam + 16.0 * l2 * l2) / (375.0 * q3))


@njit(**JIT_OPTIONS)
def pump_coefficients(lam):
    """(g2, g3) of Y11B: −λ(4+λ)/(5(1+λ)²), −(32−33λ+83λ²+43λ³)/(250(1+λ)²)."""
    q2 = (1.0 + lam) ** 2
    l2 = lam * lam
    return (-lam * (4.0 + lam) / (5.0 * q2),
            -(32.0 - 33.0 * lam + 83.0 * l2 + 43.0 * l2 * lam) / (250.0 * q2))


@njit(**JIT_OPTIONS)
def roll_coefficients(lam):
    """(g2, g3) of Y11C: 2λ/(5(1+λ)), (8+6λ+33λ²)/(125(1+λ))."""
    q = 1.0 + lam
    return 2.0 * lam / (5.0 * q), (8.0 + 6.0 * lam + 33.0 * lam * lam) / (125.0 * q)


@njit(**JIT_OPTIONS)
def roll_cross_coefficients(lam):
    """(g2, g3) of Y12C normalised by 8πa1³: λ²/(10(1+λ)), λ(43−24λ+43λ²)/(500(1+λ))."""
    q = 1.0 + lam
    return lam * lam / (10.0 * q), lam * (43.0 - 24.0 * lam + 43.0 * lam * lam) / (500.0 * q)


@njit(**JIT_OPTIONS)
def twist_coefficient(lam):
    """g3 of X11C (ξ ln(1/ξ) term, normalised by 8πa1³): −λ²/(4(1+λ)) [Townsend 2018 Eq. 26]."""
    return -lam * lam / (4.0 * (1.0 + lam))


# ---------------------------------------------------------------------------------------------
# Singular parts of the scalar resistance functions (SPEC §3.3 normalisation)

@njit(**JIT_OPTIONS)
def x11a_singular(xi, lam):
    """X11A ≈ g1/ξ + g2 ln(1/ξ) + g3 ξ ln(1/ξ), squeeze, A11 = 6πa1 X11A dd + … [J&O 3.17]."""
    g1, g2, g3 = squeeze_coefficients(lam)
    el = -math.log(xi)
    return g1 / xi + g2 * el + g3 * xi * el


@njit(**JIT_OPTIONS)
def x12a_singular(xi, lam):
    """X12A = −2/(1+λ) × singular X11A, with A12 = 3π(a1+a2) X12A dd + …."""
    return -2.0 / (1.0 + lam) * x11a_singular(xi, lam)


@njit(**JIT_OPTIONS)
def y11a_singular(xi, lam):
    """Y11A ≈ g2 ln(1/ξ) + g3 ξ ln(1/ξ), shear, A11 = … + 6πa1 Y11A (I − dd) [J&O 4.15]."""
    g2, g3 = shear_coefficients(lam)
    el = -math.log(xi)
    return g2 * el + g3 * xi * el


@njit(**JIT_OPTIONS)
def y12a_singular(xi, lam):
    """Y12A = −2/(1+λ) × singular Y11A, with A12 = … + 3π(a1+a2) Y12A (I − dd)."""
    return -2.0 / (1.0 + lam) * y11a_singular(xi, lam)


@njit(**JIT_OPTIONS)
def y11b_singular(xi, lam):
    """Y11B ≈ g2 ln(1/ξ) + g3 ξ ln(1/ξ), pump, B11_ij = 4πa1² Y11B ε_ijk d_k [J&O 5.6]."""
    g2, g3 = pump_coefficients(lam)
    el = -math.log(xi)
    return g2 * el + g3 * xi * el


@njit(**JIT_OPTIONS)
def y12b_singular(xi, lam):
    """Y12B = −4/(1+λ)² × singular Y11B, with B12_ij = π(a1+a2)² Y12B ε_ijk d_k (torque on 1
    from U2)."""
    return -4.0 / (1.0 + lam) ** 2 * y11b_singular(xi, lam)


@njit(**JIT_OPTIONS)
def y11c_singular(xi, lam):
    """Y11C ≈ g2 ln(1/ξ) + g3 ξ ln(1/ξ), roll, C11 = … + 8πa1³ Y11C (I − dd) [J&O 7.10]."""
    g2, g3 = roll_coefficients(lam)
    el = -math.log(xi)
    return g2 * el + g3 * xi * el


@njit(**JIT_OPTIONS)
def y12c_singular(xi, lam):
    """Y12C in the C12 = π(a1+a2)³ Y12C (I − dd) normalisation: 8/(1+λ)³ (g2 L + g3 ξL) with the
    8πa1³-normalised g's of :func:`roll_cross_coefficients` [J&O 7.10; Townsend 2018 Eq. 30]."""
    g2, g3 = roll_cross_coefficients(lam)
    el = -math.log(xi)
    return 8.0 / (1.0 + lam) ** 3 * (g2 * el + g3 * xi * el)


@njit(**JIT_OPTIONS)
def x11c_singular(xi, lam):
    """ξ ln(1/ξ) part of X11C (twist, not singular), C11 = 8πa1³ X11C dd + … [Townsend Eq. 26]."""
    return twist_coefficient(lam) * xi * -math.log(xi)


@njit(**JIT_OPTIONS)
def x12c_singular(xi, lam):
    """ξ ln(1/ξ) part of X12C = −8/(1+λ)³ X11C in the C12 = π(a1+a2)³ X12C dd normalisation."""
    return -8.0 / (1.0 + lam) ** 3 * x11c_singular(xi, lam)


# ---------------------------------------------------------------------------------------------
# Correction form: f(max(s, s_min)) − f(s_c) for s < s_c, 0 beyond

@njit(inline="always", **JIT_OPTIONS)
def _gap_terms(s, ell, cutoff_gap, min_gap):
    """(Δ(1/ξ), Δ ln(1/ξ), Δ ξ ln(1/ξ)) of the correction form, ξ = max(s, s_min)/ℓ."""
    if s >= cutoff_gap:
        return 0.0, 0.0, 0.0
    xi = max(s, min_gap) / ell
    el = -math.log(xi)
    f1 = 1.0 / xi
    f2 = el
    f3 = xi * el
    if cutoff_gap < math.inf:
        xc = cutoff_gap / ell
        elc = -math.log(xc)
        f1 -= 1.0 / xc
        f2 -= elc
        f3 -= xc * elc
    return f1, f2, f3


@njit(**JIT_OPTIONS)
def pair_mode_resistances(a1, a2, s, cutoff_gap, min_gap):
    """Mode resistances per unit viscosity (M_n, M_σσ, M_σρ, M_ρρ, M_t) at gap ``s`` [h].

    Correction form (module docstring): every function f → f(max(s, s_min)) − f(s_c) for
    s < s_c, all zero for s ≥ s_c; ``cutoff_gap = inf`` gives the bare singular parts. Units
    [h], [h], [h²], [h³], [h³]. The twist M_t is clamped at ≥ 0 when s_c is finite.
    """
    lam = a2 / a1
    ell = 0.5 * (a1 + a2)
    f1, f2, f3 = _gap_terms(s, ell, cutoff_gap, min_gap)
    x1, x2, x3 = squeeze_coefficients(lam)
    ya2, ya3 = shear_coefficients(lam)
    yb2, yb3 = pump_coefficients(lam)
    yc2, yc3 = roll_coefficients(lam)
    pi = math.pi
    m_n = 6.0 * pi * a1 * (x1 * f1 + x2 * f2 + x3 * f3)
    m_ss = 6.0 * pi * a1 * (ya2 * f2 + ya3 * f3)
    # −4πa1² Y11B − κ a1 6πa1 Y11A, κ = 1 + ξ/2, truncated at ξL
    m_sr = -pi * a1 * a1 * ((4.0 * yb2 + 6.0 * ya2) * f2
                            + (4.0 * yb3 + 6.0 * ya3 + 3.0 * ya2) * f3)
    # 8πa1³ (Y11C + κ Y11B + ¾ κ² Y11A), κ² = 1 + ξ, truncated at ξL
    m_rr = 8.0 * pi * a1 * a1 * a1 * ((yc2 + yb2 + 0.75 * ya2) * f2
                                      + (yc3 + yb3 + 0.5 * yb2 + 0.75 * (ya3 + ya2)) * f3)
    m_t = 8.0 * pi * a1 * a1 * a1 * twist_coefficient(lam) * f3
    if cutoff_gap < math.inf:
        m_t = max(m_t, 0.0)
    return m_n, m_ss, m_sr, m_rr, m_t


@njit(**JIT_OPTIONS)
def sphere_squeeze_law(a1, a2):
    """(c1, c2, c3, ℓ) of the sphere squeeze M_n = 6πa1 X11A in the form of
    :func:`normal_resistance`: c1 = 6πa1 g1 ℓ [h²], c2 = 6πa1 g2, c3 = 6πa1 g3 [h],
    ℓ = (a1 + a2)/2."""
    g1, g2, g3 = squeeze_coefficients(a2 / a1)
    ell = 0.5 * (a1 + a2)
    c = 6.0 * math.pi * a1
    return c * g1 * ell, c * g2, c * g3, ell


@njit(inline="always", **JIT_OPTIONS)
def _raw_normal(c1, c2, c3, ell, s):
    """c1/s + c2 ln(ℓ/s) + c3 (s/ℓ) ln(ℓ/s) (uncorrected)."""
    el = math.log(ell / s)
    return c1 / s + c2 * el + c3 * (s / ell) * el


@njit(inline="always", **JIT_OPTIONS)
def _raw_normal_antiderivative(c1, c2, c3, ell, s):
    """∫ of :func:`_raw_normal` ds: c1 ln s + c2 s (ln(ℓ/s) + 1) + c3 s² (2 ln(ℓ/s) + 1)/(4ℓ)."""
    el = math.log(ell / s)
    return c1 * math.log(s) + c2 * s * (el + 1.0) + c3 * s * s * (2.0 * el + 1.0) / (4.0 * ell)


@njit(**JIT_OPTIONS)
def normal_resistance(c1, c2, c3, ell, s, cutoff_gap, min_gap):
    """Normal (squeeze) resistance per unit viscosity, correction form, at gap ``s`` [h]:

        M(s) = m(max(s, s_min)) − m(s_c) for s < s_c, 0 beyond,
        m(s) = c1/s + c2 ln(ℓ/s) + c3 (s/ℓ) ln(ℓ/s)

    (``cutoff_gap = inf``: m itself). Spheres: :func:`sphere_squeeze_law`; a curved squeeze
    (SPEC §3.4): c1 = :func:`curved_squeeze_coefficient`, c2 = c3 = 0, any ℓ.
    """
    if s >= cutoff_gap:
        return 0.0
    m = _raw_normal(c1, c2, c3, ell, max(s, min_gap))
    if cutoff_gap < math.inf:
        m -= _raw_normal(c1, c2, c3, ell, cutoff_gap)
    return m


@njit(**JIT_OPTIONS)
def normal_potential(c1, c2, c3, ell, s, cutoff_gap, min_gap):
    """Φ(s) = ∫ M ds of :func:`normal_resistance`, with Φ = 0 for s ≥ s_c (finite s_c).

    The normal lubrication force is −μ M(s) ds/dt = −μ dΦ/dt, so its impulse over any motion
    from s to s' is exactly −μ (Φ(s') − Φ(s)) (used by the implicit step). Below s_min M is
    constant, so Φ continues linearly. Unit [h²] × (unit of M / [h]).
    """
    finite = cutoff_gap < math.inf
    if finite and s >= cutoff_gap:
        return 0.0
    se = max(s, min_gap)
    phi = _raw_normal_antiderivative(c1, c2, c3, ell, se)
    m_min = _raw_normal(c1, c2, c3, ell, min_gap) if s < min_gap else 0.0
    if finite:
        mc = _raw_normal(c1, c2, c3, ell, cutoff_gap)
        phi -= _raw_normal_antiderivative(c1, c2, c3, ell, cutoff_gap) + mc * (se - cutoff_gap)
        m_min -= mc if s < min_gap else 0.0
    return phi + m_min * (s - se)


@njit(**JIT_OPTIONS)
def repulsion_force(s, repulsion_strength, cutoff_gap, min_gap):
    """Short-range repulsion magnitude C (1/max(s, s_min)⁸ − 1/s_c⁸) for s < s_c, else 0.

    Positive: pushes the bodies apart along d (force +F d on 2, −F d on 1). Seed 000 (SPEC §3.3),
    exponent :data:`REPULSION_EXPONENT`; shift and inner cap [choice].
    """
    if s >= cutoff_gap:
        return 0.0
    se = max(s, min_gap)
    f = repulsion_strength / se ** REPULSION_EXPONENT
    if cutoff_gap < math.inf:
        f -= repulsion_strength / cutoff_gap ** REPULSION_EXPONENT
    return f


@njit(**JIT_OPTIONS)
def repulsion_slope(s, repulsion_strength, cutoff_gap, min_gap):
    """d/ds of :func:`repulsion_force`: −8C/s⁹ for s_min < s < s_c, else 0."""
    if s >= cutoff_gap or s <= min_gap:
        return 0.0
    return -REPULSION_EXPONENT * repulsion_strength / s ** (REPULSION_EXPONENT + 1)


# ---------------------------------------------------------------------------------------------
# Pair force (hot path)

@njit(inline="always", **JIT_OPTIONS)
def _pair_geometry(a1, a2, r12):
    """(d_x, d_y, d_z, s, κ) from the centre difference r12 = x1 − x2."""
    r = math.sqrt(r12[0] * r12[0] + r12[1] * r12[1] + r12[2] * r12[2])
    inv = -1.0 / r
    return r12[0] * inv, r12[1] * inv, r12[2] * inv, r - a1 - a2, r / (a1 + a2)


@njit(inline="always", **JIT_OPTIONS)
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(**JIT_OPTIONS)
def lubrication_pair_force(a1, a2, r12, U1, U2, W1, W2, mu, cutoff_gap, min_gap, out):
    """Lubrication forces and torques of a sphere pair (mode form, correction form).

    Writes ``out`` (4, 3): rows F1, F2, T1, T2 (forces [m h τ⁻²] and torques [m h² τ⁻²] on
    spheres 1 and 2) and returns the gap s [h]. ``r12`` = x1 − x2 (minimum image), U/W the
    velocities and angular velocities (3,), ``mu`` the gap viscosity (:func:`gap_viscosity`).
    All zero for s ≥ ``cutoff_gap``. Equations: module docstring; no allocation.
    """
    dx, dy, dz, s, kap = _pair_geometry(a1, a2, r12)
    out[:, :] = 0.0
    if s >= cutoff_gap:
        return s
    m_n, m_ss, m_sr, m_rr, m_t = pair_mode_resistances(a1, a2, s, cutoff_gap, min_gap)
    ux = U1[0] - U2[0]
    uy = U1[1] - U2[1]
    uz = U1[2] - U2[2]
    un = ux * dx + uy * dy + uz * dz
    cx, cy, cz = _cross(a1 * W1[0] + a2 * W2[0], a1 * W1[1] + a2 * W2[1],
                        a1 * W1[2] + a2 * W2[2], dx, dy, dz)
    sx = ux - un * dx + kap * cx
    sy = uy - un * dy + kap * cy
    sz = uz - un * dz + kap * cz
    wx = W1[0] - W2[0]
    wy = W1[1] - W2[1]
    wz = W1[2] - W2[2]
    rx, ry, rz = _cross(wx, wy, wz, dx, dy, dz)
    wn = wx * dx + wy * dy + wz * dz
    fsx = m_ss * sx + m_sr * rx
    fsy = m_ss * sy + m_sr * ry
    fsz = m_ss * sz + m_sr * rz
    frx = m_sr * sx + m_rr * rx
    fry = m_sr * sy + m_rr * ry
    frz = m_sr * sz + m_rr * rz
    out[0, 0] = -mu * (m_n * un * dx + fsx)
    out[0, 1] = -mu * (m_n * un * dy + fsy)
    out[0, 2] = -mu * (m_n * un * dz + fsz)
    out[1, 0] = -out[0, 0]
    out[1, 1] = -out[0, 1]
    out[1, 2] = -out[0, 2]
    ax, ay, az = _cross(dx, dy, dz, fsx, fsy, fsz)
    bx, by, bz = _cross(dx, dy, dz, frx, fry, frz)
    t = m_t * wn
    out[2, 0] = -mu * (kap * a1 * ax + bx + t * dx)
    out[2, 1] = -mu * (kap * a1 * ay + by + t * dy)
    out[2, 2] = -mu * (kap * a1 * az + bz + t * dz)
    out[3, 0] = -mu * (kap * a2 * ax - bx - t * dx)
    out[3, 1] = -mu * (kap * a2 * ay - by - t * dy)
    out[3, 2] = -mu * (kap * a2 * az - bz - t * dz)
    return s


# ---------------------------------------------------------------------------------------------
# Gap viscosity for a generalized Newtonian matrix (heuristic, seed 000)

@njit(**JIT_OPTIONS)
def gap_shear_rate(a1, a2, r12, U1, U2, W1, W2, min_gap):
    """γ̇_gap = |v_c1 − v_c2| / max(s, s_min) [τ⁻¹], v_c1 = U1 + Ω1 × a1 d, v_c2 = U2 − Ω2 × a2 d
    the velocities of the closest surface points (normal and tangential parts)."""
    dx, dy, dz, s, _ = _pair_geometry(a1, a2, r12)
    c1x, c1y, c1z = _cross(W1[0], W1[1], W1[2], dx, dy, dz)
    c2x, c2y, c2z = _cross(W2[0], W2[1], W2[2], dx, dy, dz)
    vx = U1[0] - U2[0] + a1 * c1x + a2 * c2x
    vy = U1[1] - U2[1] + a1 * c1y + a2 * c2y
    vz = U1[2] - U2[2] + a1 * c1z + a2 * c2z
    return math.sqrt(vx * vx + vy * vy + vz * vz) / max(s, min_gap)


@njit(**JIT_OPTIONS)
def gap_viscosity(code, p, a1, a2, r12, U1, U2, W1, W2, min_gap):
    """μ(γ̇_gap) of law ``code`` with packed parameters ``p`` (:mod:`suspsim.rheology.laws`) at
    the gap shear rate of :func:`gap_shear_rate` [seed 000, heuristic; SPEC §3.3]."""
    return viscosity_kernel(code, p, gap_shear_rate(a1, a2, r12, U1, U2, W1, W2, min_gap))


# ---------------------------------------------------------------------------------------------
# Squeeze between curved non-spherical surfaces (SPEC §3.4)

@njit(**JIT_OPTIONS)
def curvature_determinant(k1a, k2a, k1b, k2b, omega):
    """det(K_A + K_B) = k1A k2A + k1B k2B + (k1A k2B + k2A k1B) cos²ω + (k1A k1B + k2A k2B) sin²ω
    (SPEC §3.4), ω the angle between the first principal directions of A and B."""
    c2 = math.cos(omega) ** 2
    s2 = 1.0 - c2
    return k1a * k2a + k1b * k2b + (k1a * k2b + k2a * k1b) * c2 + (k1a * k1b + k2a * k2b) * s2


@njit(**JIT_OPTIONS)
def curved_squeeze_coefficient(k1a, k2a, k1b, k2b, omega):
    """c = 12π/(tr K √det K) [h²], so the squeeze force is F = μ c U/s (SPEC §3.4).

    k1a, k2a and k1b, k2b [h⁻¹] are the principal curvatures of surfaces A and B at their closest
    points (positive when convex), ω the angle between their first principal directions in the
    common tangent plane. Spheres: c = 6π (a1 a2/(a1 + a2))². NaN unless K is positive definite
    (at a true closest point it is at least semi-definite; det K = 0 gives inf).
    """
    tr = k1a + k2a + k1b + k2b
    det = curvature_determinant(k1a, k2a, k1b, k2b, omega)
    if tr <= 0.0 or det < 0.0:
        return math.nan
    return 12.0 * math.pi / (tr * math.sqrt(det))


@njit(**JIT_OPTIONS)
def curved_squeeze_coefficient_frames(k1a, k2a, e1a, k1b, k2b, e1b, normal):
    """:func:`curved_squeeze_coefficient` with ω from the first principal directions e1a, e1b (3,)
    projected on the plane normal to ``normal`` (3,); only cos²ω matters, so signs are free."""
    nn = normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]
    pa = (e1a[0] * normal[0] + e1a[1] * normal[1] + e1a[2] * normal[2]) / nn
    pb = (e1b[0] * normal[0] + e1b[1] * normal[1] + e1b[2] * normal[2]) / nn
    ax, ay, az = e1a[0] - pa * normal[0], e1a[1] - pa * normal[1], e1a[2] - pa * normal[2]
    bx, by, bz = e1b[0] - pb * normal[0], e1b[1] - pb * normal[1], e1b[2] - pb * normal[2]
    cosw = (ax * bx + ay * by + az * bz) / math.sqrt((ax * ax + ay * ay + az * az)
                                                      * (bx * bx + by * by + bz * bz))
    return curved_squeeze_coefficient(k1a, k2a, k1b, k2b, math.acos(min(1.0, max(-1.0, cosw))))


# ---------------------------------------------------------------------------------------------
# Python references (tests, diagnostics): full 12 × 12 matrices, order (U1, U2, Ω1, Ω2)

def _unit_d(r12):
    r12 = np.asarray(r12, dtype=float)
    r = float(np.linalg.norm(r12))
    return -r12 / r, r


def jeffrey_onishi_matrix(a1: float, a2: float, r12) -> np.ndarray:
    """R (12, 12) of SPEC §3.3 assembled block by block from the bare singular functions.

    (F1, F2, T1, T2) = −μ R (U1, U2, Ω1, Ω2); blocks of sphere 2 from sphere 1's functions with
    λ → 1/λ and d → −d; B̃_αβ = B_βαᵀ. Reference for the mode form of
    :func:`lubrication_pair_force` (they agree to O(ξ² ln(1/ξ))).
    """
    d, r = _unit_d(r12)
    s = r - a1 - a2
    xi = 2.0 * s / (a1 + a2)
    dd = np.outer(d, d)
    p = np.eye(3) - dd

    def eps(v):  # (ε·v)_ij = ε_ijk v_k
        return np.array([[0.0, v[2], -v[1]], [-v[2], 0.0, v[0]], [v[1], -v[0], 0.0]])

    pi = math.pi
    a12 = a1 + a2
    blocks = {}
    for (al, be), (aa, lam, dv) in {(0, 1): (a1, a2 / a1, d), (1, 0): (a2, a1 / a2, -d)}.items():
        x, y = x11a_singular(xi, lam), y11a_singular(xi, lam)
        blocks["A", al, al] = 6 * pi * aa * (x * dd + y * p)
        x, y = x12a_singular(xi, lam), y12a_singular(xi, lam)
        blocks["A", al, be] = 3 * pi * a12 * (x * dd + y * p)
        blocks["B", al, al] = 4 * pi * aa ** 2 * y11b_singular(xi, lam) * eps(dv)
        blocks["B", al, be] = pi * a12 ** 2 * y12b_singular(xi, lam) * eps(dv)
        x, y = x11c_singular(xi, lam), y11c_singular(xi, lam)
        blocks["C", al, al] = 8 * pi * aa ** 3 * (x * dd + y * p)
        x, y = x12c_singular(xi, lam), y12c_singular(xi, lam)
        blocks["C", al, be] = pi * a12 ** 3 * (x * dd + y * p)
    big = np.zeros((12, 12))
    for al in range(2):
        for be in range(2):
            big[3 * al:3 * al + 3, 3 * be:3 * be + 3] = blocks["A", al, be]
            big[6 + 3 * al:9 + 3 * al, 3 * be:3 * be + 3] = blocks["B", al, be]
            big[3 * al:3 * al + 3, 6 + 3 * be:9 + 3 * be] = blocks["B", be, al].T
            big[6 + 3 * al:9 + 3 * al, 6 + 3 * be:9 + 3 * be] = blocks["C", al, be]
    return big


def resistance_matrix(a1: float, a2: float, r12, cutoff_gap: float = math.inf,
                      min_gap: float = 0.0) -> np.ndarray:
    """R (12, 12) of the hot path, (F1, F2, T1, T2) = −μ R (U1, U2, Ω1, Ω2), column by column
    from :func:`lubrication_pair_force` with μ = 1 (so it is exactly the model the solver uses)."""
    r12 = np.ascontiguousarray(r12, dtype=float)
    out = np.zeros((4, 3))
    big = np.zeros((12, 12))
    for k in range(12):
        v = np.zeros(12)
        v[k] = 1.0
        lubrication_pair_force(a1, a2, r12, v[0:3], v[3:6], v[6:9], v[9:12], 1.0,
                               cutoff_gap, min_gap, out)
        big[:, k] = -out.ravel()
    return big


def check_gap_parameters(radius: float, cutoff_gap: float, min_gap: float,
                         repulsion_strength: float = 0.0) -> None:
    """Raise ``ValueError`` unless 0 < min_gap < cutoff_gap, C ≥ 0 and ξ_c = cutoff_gap/radius ≤ 1
    (``radius`` the smallest sphere radius [h]: the range where the correction form was checked
    to be positive semi-definite)."""
    if not (min_gap > 0.0):
        raise ValueError(f"lubrication min_gap = {min_gap:g} h must be > 0 (it caps 1/s)")
    if not (cutoff_gap > min_gap):
        raise ValueError(f"lubrication cutoff_gap = {cutoff_gap:g} h must exceed min_gap = "
                         f"{min_gap:g} h")
    if repulsion_strength < 0.0:
        raise ValueError(f"repulsion_strength = {repulsion_strength:g} must be ≥ 0")
    if math.isfinite(cutoff_gap) and cutoff_gap > radius:
        raise ValueError(f"lubrication cutoff_gap = {cutoff_gap:g} h exceeds the sphere radius "
                         f"{radius:g} h; the near-field expansion (ξ_c ≤ 1) no longer holds")
