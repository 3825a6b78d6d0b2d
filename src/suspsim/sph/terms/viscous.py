"""Viscous pair force (A and the symmetrised bulk correction B^c) and the explicit ∇a term.

SPEC §2.3 (seed 000 Eqs. 9–12, sign derived) gives the pair form of A,
    f^A_ij = −(d + 2) m² F/(ρ_i ρ_j) (μ_i + μ_j) (r·v) r / r²,
and SPEC §2.4 with the probe's symmetrisation (a_i + a_j)/2 gives the pair form of B^c,
    f^B_ij = m² F/(ρ_i ρ_j) ā [v − (d + 2)(r·v) r / r²],   ā = (a_i + a_j)/2,
with a = ζ − (1 + 2/d) μ and ζ = 0 (seed 000), r = r_ij, v = v_ij. Both are antisymmetric, so
momentum is conserved to round-off. Together (ā = −(1 + 2/d)(μ_i + μ_j)/2):
    f_ij = −(μ_i + μ_j) m² F/(ρ_i ρ_j) [α (r·v) r / r² + β v]
with (α, β) = (d + 2, 0) without B and ((d + 2)(d − 2)/(2d), (d + 2)/(2d)) with B — in 3D
(5/6, 5/6), the Español–Revenga form; in 2D (0, 1). Continuum limit of the sum with the B
correction: ∇·[μ(∇v + ∇vᵀ)] + ∇(a ∇·v) except for ½ ∂_i a ∇·v − ½ ∂_k a ∂_i v_k, which the
symmetrisation removes and :func:`explicit_bulk_term` adds back per particle [SPEC §2.3,
derived; zero in simple shear and plane Poiseuille]. With ``numerics.spin_correction``
(:func:`local_spin`) the pair sum is itself the divergence of a symmetric stress with variable
μ, and no explicit term is added; its bulk viscosity goes through the pressure
(:func:`spin_bulk_pressure`).

Symbols:

====== ====================================================== ==================
symbol meaning                                                unit
====== ====================================================== ==================
μ      (normalised) viscosity of a particle                   [m h^(2−d) τ^−1]
a      bulk parameter ζ − (1 + 2/d) μ, ζ = 0                   [m h^(2−d) τ^−1]
α, β   weights of (r·v) r / r² and v in the pair force        1
F      kernel factor −W'/r                                     [h^−(d+2)]
d      dimension                                               1
====== ====================================================== ==================
"""
from __future__ import annotations

from numba import njit

from suspsim.sph import JIT_OPTIONS


def viscous_weights(dimension: int, bulk_correction: bool,
                    spin_correction: bool = False) -> tuple[float, float]:
    """(α, β) of the combined pair force for ``dimension`` with or without B (module
    docstring); with ``spin_correction`` β is doubled (:func:`local_spin`)."""
    d = float(dimension)
    if not bulk_correction:
        return d + 2.0, 0.0
    beta = (d + 2.0) / (2.0 * d)
    return (d + 2.0) * (d - 2.0) / (2.0 * d), 2.0 * beta if spin_correction else beta


def bulk_factor(dimension: int) -> float:
    """a/μ = −(1 + 2/d) for ζ = 0 [SPEC §2.4; seed 000 takes ζ = 0]."""
    return -(1.0 + 2.0 / dimension)


@njit(inline="always", **JIT_OPTIONS)
def pair_viscosity(mu_i, mu_j):
    """μ_i + μ_j of seed 000 Eq. 12, taken as twice the harmonic mean 4 μ_i μ_j/(μ_i + μ_j).

    [choice] Equal to μ_i + μ_j to first order in μ_i − μ_j, so the continuum limit (and the
    explicit ∇a term) is unchanged; across a steep viscosity rise (a yield-stress plug edge)
    it is the viscosity of two layers sheared in series, where the arithmetic sum lets the
    stiff particle dominate. Not yet compared with the arithmetic sum at Re ≤ 0.1.
    """
    return 4.0 * mu_i * mu_j / (mu_i + mu_j)


@njit(inline="always", **JIT_OPTIONS)
def viscous_pair(mu_sum, scale, dx, dy, dz, r2, vx, vy, vz, alpha, beta):
    """Force on i from j (module docstring): −(μ_i + μ_j) s [α (r·v) r/r² + β v].

    ``scale`` s = m² F/(ρ_i ρ_j); (dx, dy, dz) = r_ij, r2 = |r_ij|² > 0, (vx, vy, vz) = v_ij
    (with the Lees–Edwards image correction). SPEC §2.3–2.4, seed 000 Eqs. 9–16.
    """
    rv = (dx * vx + dy * vy + dz * vz) / r2
    k = -mu_sum * scale
    return (k * (alpha * rv * dx + beta * vx), k * (alpha * rv * dy + beta * vy),
            k * (alpha * rv * dz + beta * vz))


@njit(inline="always", **JIT_OPTIONS)
def spin_free_velocity(body_spin, body_i, body_j, dx, dy, dz, vx, vy, vz):
    """v_ij − w × r_ij for a pair with a rigid-body particle [h τ⁻¹]: w = Ω_B, the angular
    velocity [τ⁻¹] of the one body of a fluid–body pair (``body_spin[B]``), or the mean of the
    two bodies' for a pair of particles of two bodies; ``body_i``, ``body_j`` the pair's body
    indices (−1 for fluid), r_ij = (dx, dy, dz), v_ij = (vx, vy, vz).

    Why [derived; a correction to seed 000's pair form for rigid inclusions]: the β v term of
    :func:`viscous_pair` is not invariant under rigid rotation (r·(Ω × r) = 0 but Ω × r ≠ 0),
    so its continuum stress is μ[(1 − β′)(∇v + ∇vᵀ) + β′ ∇v]-like rather than 2μE: the two
    differ by μ ∇vᵀ, which is divergence-free in an incompressible fluid of uniform μ (the
    bulk forces are right) but whose moment over a body's surface, ∫ x ⊗ (∇vᵀ · n) dS =
    V_B ∇v_B, is the body's own rotation. A fluid co-rotating with the body would then exert a
    torque on it, and a torque-free sphere in simple shear spun at 1.36 × γ̇/2 instead of γ̇/2
    (one sphere, a = 2.4 h, φ = 0.03, README). Taking v relative to the body's rigid rotation
    removes that moment from the fluid–body pairs: a fluid particle moving rigidly with the body
    feels no viscous force from it (the sphere then turned at 1.26 × γ̇/2; the rest is the same
    term in the fluid–fluid pairs, which :func:`local_spin` removes, and with it a fluid–body
    pair takes the mean spin of :func:`particle_spin` instead: 1.001 × γ̇/2). The α term
    is unchanged (r·(w × r) = 0); the pair force stays antisymmetric, so momentum is conserved.
    """
    if body_i >= 0 and body_j >= 0:
        wx = 0.5 * (body_spin[body_i, 0] + body_spin[body_j, 0])
        wy = 0.5 * (body_spin[body_i, 1] + body_spin[body_j, 1])
        wz = 0.5 * (body_spin[body_i, 2] + body_spin[body_j, 2])
    else:
        b = body_i if body_i >= 0 else body_j
        wx, wy, wz = body_spin[b, 0], body_spin[b, 1], body_spin[b, 2]
    return without_rotation(wx, wy, wz, dx, dy, dz, vx, vy, vz)


@njit(inline="always", **JIT_OPTIONS)
def without_rotation(wx, wy, wz, dx, dy, dz, vx, vy, vz):
    """v_ij − w × r_ij [h τ⁻¹]: the pair's velocity relative to a rigid rotation at angular
    velocity w [τ⁻¹] (:func:`spin_free_velocity`, :func:`local_spin`)."""
    return (vx - (wy * dz - wz * dy), vy - (wz * dx - wx * dz), vz - (wx * dy - wy * dx))


@njit(inline="always", **JIT_OPTIONS)
def local_spin(g):
    """Angular velocity ½ ∇×v [τ⁻¹] of a particle from its corrected gradient g[3k + l] =
    ∂_k v_l (``velocity_pass``).

    Why [derived; ``numerics.spin_correction``, a [choice] beyond SPEC §2.3–2.4]: the β v term
    of :func:`viscous_pair` makes the continuum stress of the pair sum non-symmetric. For a
    linear field v_ij = L r_ij, the sums over a neighbourhood (Σ F r r = K I/d, the fourth
    moment K (δδ + δδ + δδ)/(d(d + 2))) give the stress μK [β/d L + α/(d(d + 2)) (L + Lᵀ +
    tr L I)]: its antisymmetric part β/(2d) μK (L − Lᵀ) follows the vorticity, as in the
    Español–Revenga form, which does not conserve angular momentum (Müller, Fedosov &
    Karniadakis, J. Comput. Phys. 281, 301 (2015)). In a suspension the fluid then carries
    less shear stress wherever it turns with the bodies, and torque-free bodies spin too fast.
    Taking the β term of v_ij − w̄ × r_ij, w̄ the mean of the two particles' ½ ∇×v, leaves
    (L − W) r = E r: the stress μK [(β/d + 2α/(d(d + 2))) E + α/(d(d + 2)) tr E I] is
    symmetric. Its divergence keeps μ ∇²v when β is doubled (α unchanged), so the shear
    viscosity is the same, and the bulk viscosity becomes ζ = 5μ/6 in 3D (μ in 2D) instead of
    seed 000's 0; :func:`spin_bulk_pressure` takes it out again through the pressure. Unlike
    the particle spins of Müller et al. this adds no variable: w is slaved to the local
    vorticity, so angular momentum is conserved to first order (exactly for a linear field).
    Rigid rotation then has no viscous force at all.

    Variable viscosity [derived]: expanding the pair sum to second order in r with μ_i + μ_j
    = 2μ − r·∇μ and w̄ = w − ½ (r·∇) w gives, besides the terms above, (α/(d(d + 2)))K
    (∂_l μ ∇·v + ∂_k μ ∂_l v_k + ∂_k μ ∂_k v_l) from the α term and (β′/(2d))K ∂_k μ
    (∂_k v_l + ∂_l v_k) from the corrected β′ = 2β term (w × ∇μ = ½ ∂_k μ (∂_k v_l − ∂_l
    v_k)). With the weights of B these are exactly the ∇μ terms of ∇·σ for σ = μ(∇v + ∇vᵀ)
    + (d − 2)/(2d) μ (∇·v) I, the same σ as the uniform-μ terms: the corrected form needs no
    :func:`explicit_bulk_term`, and adding it would be an error (measured on a lattice with
    27 particles per h³, linear v and μ: 1.3 % without it, 35 % with it;
    ``test_spin_correction``).
    """
    return 0.5 * (g[5] - g[7]), 0.5 * (g[6] - g[2]), 0.5 * (g[1] - g[3])


@njit(inline="always", **JIT_OPTIONS)
def spin_bulk_ratio(dimension):
    """ζ/μ = (d + 2)/(2d) of the spin-corrected pair form (5/6 in 3D, 1 in 2D), which
    :func:`spin_bulk_pressure` removes.

    Why [derived]: :func:`local_spin`'s stress σ = μ(∇v + ∇vᵀ) + (d − 2)/(2d) μ (∇·v) I is
    2μ(E − (∇·v)/d I) + ζ (∇·v) I with ζ = 2μ/d + (d − 2)/(2d) μ = (d + 2)/(2d) μ, where seed
    000's form has ζ = 0. A weakly compressible fluid squeezed out of a closing gap is not
    divergence-free, and there ζ adds a resistance the incompressible fluid does not have.
    """
    return (dimension + 2.0) / (2.0 * dimension)


@njit(inline="always", **JIT_OPTIONS)
def spin_bulk_coefficient(spin_correction, dimension):
    """The ζ/μ a step removes (``force_pass.force_sums``' ``spin_bulk``): :func:`spin_bulk_ratio`
    with the spin correction, 0 without."""
    return spin_bulk_ratio(dimension) if spin_correction else 0.0


@njit(inline="always", **JIT_OPTIONS)
def spin_bulk_pressure(mu, g, ratio):
    """ζ ∇·v = ``ratio`` μ (g[0] + g[4] + g[8]) [m h^(2−d) τ^−2], added to a fluid particle's
    pressure so that the spin-corrected form's bulk stress ζ (∇·v) I cancels (the pressure
    enters the stress as −P I; :func:`spin_bulk_ratio`). ``g`` the corrected gradient g[3k + l]
    = ∂_k v_l, μ the particle's (normalised) viscosity."""
    return ratio * mu * (g[0] + g[4] + g[8])


@njit(inline="always", **JIT_OPTIONS)
def particle_spin(body_spin, body, g):
    """Spin [τ⁻¹] a particle brings to the spin-corrected pair form: its local ½ ∇×v
    (:func:`local_spin` of its corrected gradient ``g``) for fluid (``body`` −1), its body's
    angular velocity ``body_spin[body]`` for a body particle (whose gradient is not formed).

    Why a fluid–body pair takes the mean of the two [derived]: the corrected form doubles β
    for every pair, so a fluid–body pair taking v − Ω_B × r alone (:func:`spin_free_velocity`,
    right for the uncorrected β) counts the fluid's rotation at the surface twice. The drag of
    a sphere translating through a periodic array (``validation.squeeze``) then read a
    hydrodynamic radius a_h/a = 1.084 (A = 30), against 1.027 uncorrected. A fluid particle
    turning rigidly with the body (½ ∇×v = Ω_B) still feels no force from it.
    """
    if body >= 0:
        return body_spin[body, 0], body_spin[body, 1], body_spin[body, 2]
    return local_spin(g)


@njit(inline="always", **JIT_OPTIONS)
def explicit_bulk_term(gax, gay, gaz, g, rho):
    """Acceleration ½ ∂_i a ∇·v − ½ ∂_k a ∂_i v_k, divided by ρ [SPEC §2.3, derived], of the
    uncorrected pair form (not with :func:`local_spin`).

    (gax, gay, gaz) = ∇a; ``g`` the 9 entries g[3k + j] = ∂_k v_j of the corrected gradient.
    """
    div = g[0] + g[4] + g[8]
    ax = 0.5 * (gax * div - (gax * g[0] + gay * g[1] + gaz * g[2])) / rho
    ay = 0.5 * (gay * div - (gax * g[3] + gay * g[4] + gaz * g[5])) / rho
    az = 0.5 * (gaz * div - (gax * g[6] + gay * g[7] + gaz * g[8])) / rho
    return ax, ay, az
