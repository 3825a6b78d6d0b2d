"""Dissipation normalisation of the viscous sums (SPEC §2.3, "What the probe found works").

The discrete viscous sum under-represents the continuum operator because the discrete fourth
(and second) moments of a real particle arrangement fall short of their continuum values. For
a linear velocity field v_ij = L r_ij (L_lk = ∂_k v_l, the local corrected gradient) the
dissipation of particle i's viscous pair forces, per unit viscosity, is

    D_i = Σ_j V_j F [α (r·L r)²/r² + β |L r|²] = α Σ_j V_j F (r·S r)²/r² + β (L Lᵀ) : M2,

(the β part needs no pair loop: M2 = Σ_j V_j F r r is known from the gradient pass, and in 2D
with the bulk correction α = 0, so the pass is skipped), whose continuum value (∫F r_k r_l r_m r_n / r² = (δδ + δδ + δδ)/(d + 2), ∫F r r = I) is

    D_c = α ((tr L)² + 2 S:S)/(d + 2) + β L:L,    S = (L + Lᵀ)/2.

The factor s_i = D_i/D_c makes them equal; the pair force then uses μ̂_i = μ_i/s_i. Dividing the
viscosity (not particle i's sum) keeps every pair force antisymmetric — momentum is conserved
and force balance in inhomogeneous flows is not broken (the probe's per-particle division of
the sums spoiled split-force Poiseuille). In a homogeneous flow the measured virial stress then
equals μ D_c exactly for the affine part of the motion. Where D_c vanishes (rest, rigid
rotation without B) the direction of L is undefined and s falls back to the scalar second
moment tr(M2)/d [choice]; s is clipped to [S_MIN, S_MAX] [choice] against isolated particles.

Symbols: L, S velocity gradient and strain rate [τ^−1]; α, β weights of the pair force
(``viscous``); V_j = m/ρ_j [h^d]; F kernel factor [h^−(d+2)]; s factor [1]; d dimension.
"""
from __future__ import annotations

from numba import njit

from suspsim.sph import JIT_OPTIONS

#: Bounds of the factor [choice]: a lattice gives 0.8–1.1; beyond these bounds a particle has
#: lost most of its neighbours and the factor would only amplify the defect.
S_MIN, S_MAX = 0.25, 4.0
#: D_c below this fraction of |L|² counts as "no deformation" (fallback) [choice].
DEGENERATE = 1e-12


@njit(inline="always", **JIT_OPTIONS)
def pair_dissipation(g, dx, dy, dz, r2, alpha, beta):
    """α (r·L r)²/r² + β |L r|² with (L r)_l = Σ_k r_k g[3k + l] (module docstring).

    The reference form of one pair's term; the pass uses the split below, which is the same
    sum in another order.
    """
    ux = dx * g[0] + dy * g[3] + dz * g[6]
    uy = dx * g[1] + dy * g[4] + dz * g[7]
    uz = dx * g[2] + dy * g[5] + dz * g[8]
    ru = dx * ux + dy * uy + dz * uz
    return alpha * ru * ru / r2 + beta * (ux * ux + uy * uy + uz * uz)


@njit(inline="always", **JIT_OPTIONS)
def strain_form(g, out):
    """out = (S_xx, S_yy, S_zz, 2 S_xy, 2 S_xz, 2 S_yz), S = (L + Lᵀ)/2, so that
    r·L r = r·S r = Σ out · (x², y², z², xy, xz, yz)."""
    out[0] = g[0]
    out[1] = g[4]
    out[2] = g[8]
    out[3] = g[1] + g[3]
    out[4] = g[2] + g[6]
    out[5] = g[5] + g[7]


@njit(inline="always", **JIT_OPTIONS)
def quadratic_form(s, xx, yy, zz, xy, xz, yz):
    """r·S r from :func:`strain_form`'s ``s`` and the monomials of r."""
    return s[0] * xx + s[1] * yy + s[2] * zz + s[3] * xy + s[4] * xz + s[5] * yz


@njit(inline="always", **JIT_OPTIONS)
def _entry(g, k, m, symmetric):
    """g[3k + m], or its symmetric part ½ (g[3k + m] + g[3m + k]) (the strain rate)."""
    if symmetric:
        return 0.5 * (g[3 * k + m] + g[3 * m + k])
    return g[3 * k + m]


@njit(inline="always", **JIT_OPTIONS)
def moment_dissipation(g, moment, symmetric=False):
    """Σ_j V_j F |L r_ij|² = (L Lᵀ) : M2, the β part of D_i without a pair loop; with
    ``symmetric`` (``numerics.spin_correction``, whose β term sees (L − W) r = S r) the same
    with S for L.

    |L r|² = Σ_km r_k r_m C_km with C_km = Σ_l g[3k + l] g[3m + l]; ``moment`` is M2 =
    Σ_j V_j F r r stored as (xx, yy, zz, xy, xz, yz).
    """
    c = 0.0
    for k in range(3):
        for m in range(3):
            ckm = 0.0
            for n in range(3):
                ckm += _entry(g, k, n, symmetric) * _entry(g, m, n, symmetric)
            if k == m:
                c += ckm * moment[k]
            else:
                c += ckm * moment[2 + k + m]
    return c


@njit(inline="always", **JIT_OPTIONS)
def continuum_dissipation(g, alpha, beta, dimension, symmetric=False):
    """D_c = α ((tr L)² + 2 S:S)/(d + 2) + β L:L (module docstring); β S:S with
    ``symmetric`` (:func:`moment_dissipation`)."""
    tr = g[0] + g[4] + g[8]
    sxy = 0.5 * (g[1] + g[3])
    sxz = 0.5 * (g[2] + g[6])
    syz = 0.5 * (g[5] + g[7])
    ss = g[0] * g[0] + g[4] * g[4] + g[8] * g[8] + 2.0 * (sxy * sxy + sxz * sxz + syz * syz)
    if symmetric:
        return alpha * (tr * tr + 2.0 * ss) / (dimension + 2.0) + beta * ss
    ll = 0.0
    for k in range(9):
        ll += g[k] * g[k]
    return alpha * (tr * tr + 2.0 * ss) / (dimension + 2.0) + beta * ll


@njit(inline="always", **JIT_OPTIONS)
def normalisation_factor(discrete, continuum, gradient_norm2, second_moment_trace, dimension):
    """s = D_i/D_c, or tr(M2)/d where D_c ≤ DEGENERATE |L|²; clipped to [S_MIN, S_MAX]."""
    if continuum > DEGENERATE * gradient_norm2 and continuum > 0.0:
        s = discrete / continuum
    else:
        s = second_moment_trace / dimension
    return min(max(s, S_MIN), S_MAX)
