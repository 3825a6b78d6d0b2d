"""Implicit pairwise lubrication (and repulsion) impulses: stable at any time step (SPEC §3.3).

Lubrication is stiff: with the squeeze resistance μ M_n ≈ 6πμ R_eff²/s an explicit step must
resolve the velocity relaxation time m_eff s/(6πμ R_eff²) (R_eff = a1 a2/(a1 + a2),
1/m_eff = 1/m1 + 1/m2), which vanishes with the gap. Here each pair is advanced implicitly.

**Normal mode, exact impulse** [derived]. The normal lubrication force on 2 is −μ M_n(s) ds/dt
= −μ dΦ/dt (Φ = :func:`~suspsim.bodies.lubrication.normal_potential`), so over a step that takes
the gap from s to s' its impulse is exactly −μ (Φ(s') − Φ(s)), whatever the path. With
x = ds/dt the relative normal velocity (U2 − U1)·d, x* its value after the other forces'
increments, w = 1/m_eff, and the positions advanced with the new velocities, s' = s + δt x:

    x = x* + w [−μ (Φ(s') − Φ(s)) + δt F_rep(s')]            (backward Euler in F_rep)

i.e. H(s') = (s' − s)/(δt w) − x*/w + μ (Φ(s') − Φ(s)) − δt F_rep(s') = 0. H increases strictly
(H' = 1/(δt w) + μ M_n(s') − δt F_rep'(s') > 0), so the root is unique; it is bracketed by
[s + δt min(x*, 0), s + δt (max(x*, 0) + δt w F_rep(s_min))] and found by safeguarded Newton.
Consequences: for the 1/s squeeze Φ → −∞ as s' → 0, so the gap cannot close in a step however
large δt is; and at low inertia (w → ∞) the step reduces to μ(Φ(s') − Φ(s)) = δt F, the exact
solution of the overdamped squeeze ODE μ M_n(s) ds/dt = F (for M_n = c/s: s' = s e^(−F δt/(μc))).

**Tangential and twist modes** (linear backward Euler at the current geometry). With scalar
moments of inertia (spheres) the modes decouple: for the sliding/rolling pair y = (σ, ρ) (per
tangential component) the mobility is W = [[1/m1 + 1/m2 + κ²(a1²/I1 + a2²/I2), κ(a1/I1 − a2/I2)],
[κ(a1/I1 − a2/I2), 1/I1 + 1/I2]] and (I + δt W μM) y' = y*, solved as a 2 × 2 system (det ≥ 1
since W is positive definite and M semi-definite); the twist rate ω_n' = ω_n*/(1 + δt μ M_t
(1/I1 + 1/I2)). The generalized forces −μM y' give the impulses through the same Qᵀ as the
force (module :mod:`~suspsim.bodies.lubrication`), so momentum and angular momentum about any
point are conserved exactly, and the step is unconditionally stable (L-stable).

**Contact friction** [choice, not in SPEC; Coulomb friction at roughness contacts as in Mari,
Seto, Morris & Denn, J. Rheol. 58, 1693 (2014), taken here history-free and implicit as in
Moreau–Jean contact dynamics]. Seed 000's repulsion stands for the contact of surface asperities;
with a coefficient μ_c > 0 that contact also resists sliding. After the lubrication solve, the
sliding velocity left at the contact points, σ', is stopped by a tangential impulse J_f at the
contact (a generalized sliding force, so it changes σ by W_σσ J_f and the spins through the same
lever arms) if that needs no more than μ_c j_rep (stick, J_f = −σ'/W_σσ); otherwise J_f =
−μ_c j_rep σ'/|σ'| (slip). j_rep is the repulsion's impulse over the step, so pairs the
repulsion does not reach feel no friction. The split (lubrication, then friction on its result)
is first order in δt and stable at any step: the friction impulse only removes sliding.

**Rolling friction** [choice, not in SPEC; the rolling resistance by which DEM represents the
shape of grains, Wensrich & Katterfeld, Powder Technol. 217, 409 (2012); in suspensions, rolling
constraints lower the jamming fraction of rough or faceted particles, Sharma, Sharma & Singh,
arXiv:2505.22747 (2025)]. With a coefficient μ_r > 0 the relative rolling ρ = (Ω₁ − Ω₂) × d
left after lubrication and sliding friction is stopped the same way by an angular impulse pair
±d × J_r (a generalized rolling force, so ρ changes by W_ρρ J_r and σ by W_σρ J_r): stick
J_r = −ρ/W_ρρ if |J_r| ≤ μ_r R_eff j_rep (R_eff = a1 a2/(a1 + a2)), else slip at that limit, the
constant-torque rolling resistance of Ai, Chen, Rotter & Ooi, Powder Technol. 206, 269 (2011).
Each of the two impulses is a fraction α ≤ 1 of the one that stops its own mode, so each
changes the kinetic energy by (α²/2 − α) y²/W ≤ 0; neither has a net force or torque.

Assumptions: positions are frozen at the start of the step (d, κ, s for the tangential modes);
the viscosity ``mu`` is supplied by the caller (lagged, e.g. :func:`gap_viscosity` at the
predicted velocities); the integrator moves positions by δt × the corrected velocities; pairs are
treated one at a time (a body in several pairs sees their impulses in sequence or summed, as the
caller's pair loop decides). Infinite masses or inertias (walls, fixed bodies) are allowed.

Units as in :mod:`~suspsim.bodies.lubrication` ([h], [τ], [m]); impulses [m h τ⁻¹], angular
impulses [m h² τ⁻¹]; dividing by δt gives the step-mean force for the stress (SPEC §3.5).
"""
from __future__ import annotations

import math

from numba import njit

from suspsim.sph import JIT_OPTIONS

from .lubrication import (_cross, _pair_geometry, normal_potential, normal_resistance,
                          pair_mode_resistances, repulsion_force, repulsion_slope,
                          sphere_squeeze_law)

__all__ = ["implicit_normal_gap", "lubrication_pair_impulse", "lubrication_pair_impulse_law"]

#: Newton iterations allowed in the normal-mode solve (bisection fallback keeps the bracket).
MAX_ITERATIONS = 200


@njit(**JIT_OPTIONS)
def implicit_normal_gap(s, x_star, w, dt, mu, c1, c2, c3, ell, cutoff_gap, min_gap,
                        repulsion_strength):
    """End-of-step gap s' [h] and normal impulses (lubrication, repulsion) [m h τ⁻¹] on body 2
    along d (on body 1: minus these), from the normal law of
    :func:`~suspsim.bodies.lubrication.normal_resistance` (c1, c2, c3, ℓ, s_c, s_min).

    ``x_star`` = (U2* − U1*)·d [h τ⁻¹] after the other forces, ``w`` the inverse effective mass
    along d [m⁻¹] (1/m1 + 1/m2 for spheres; add (c×n)·I⁻¹(c×n) lever-arm terms for grains),
    ``dt`` [τ], ``mu`` the gap viscosity. Solves H(s') = 0 (module docstring).
    """
    if w <= 0.0:
        return s + dt * x_star, 0.0, 0.0
    inv_dtw = 1.0 / (dt * w)
    xs_w = x_star / w
    phi0 = normal_potential(c1, c2, c3, ell, s, cutoff_gap, min_gap)
    f_max = repulsion_force(min_gap, repulsion_strength, cutoff_gap, min_gap)
    lo = s + dt * min(x_star, 0.0)
    hi = s + dt * (max(x_star, 0.0) + dt * w * max(f_max, 0.0))
    sp = min(max(s + dt * x_star, lo), hi)
    scale = max(min_gap, 1e-300)
    for _ in range(MAX_ITERATIONS):
        h = ((sp - s) * inv_dtw - xs_w
             + mu * (normal_potential(c1, c2, c3, ell, sp, cutoff_gap, min_gap) - phi0)
             - dt * repulsion_force(sp, repulsion_strength, cutoff_gap, min_gap))
        if h > 0.0:
            hi = sp
        elif h < 0.0:
            lo = sp
        else:
            break
        slope = (inv_dtw + mu * normal_resistance(c1, c2, c3, ell, sp, cutoff_gap, min_gap)
                 - dt * repulsion_slope(sp, repulsion_strength, cutoff_gap, min_gap))
        nxt = sp - h / slope
        if not (lo < nxt < hi):
            nxt = 0.5 * (lo + hi)
        done = abs(nxt - sp) <= 1e-14 * max(abs(sp), scale)
        sp = nxt
        if done or hi - lo <= 1e-15 * max(abs(sp), scale):
            break
    j_lub = -mu * (normal_potential(c1, c2, c3, ell, sp, cutoff_gap, min_gap) - phi0)
    j_rep = dt * repulsion_force(sp, repulsion_strength, cutoff_gap, min_gap)
    return sp, j_lub, j_rep


@njit(**JIT_OPTIONS)
def lubrication_pair_impulse(a1, a2, r12, U1, U2, W1, W2, dU1, dU2, dW1, dW2, m1, m2, I1, I2,
                             dt, mu, cutoff_gap, min_gap, repulsion_strength, friction,
                             rolling_friction, out):
    """Implicit lubrication, repulsion, contact and rolling friction impulses of a sphere pair
    over one step.

    Inputs: radii a1, a2 [h]; ``r12`` = x1 − x2 [h] at the start of the step; velocities U1, U2
    [h τ⁻¹] and angular velocities W1, W2 [τ⁻¹] before the update; dU1, dU2, dW1, dW2 their
    increments over the step from every other force (fluid, external); masses m1, m2 [m] and
    scalar moments of inertia I1, I2 [m h²] (inf for a fixed body); ``dt`` [τ]; ``mu`` the gap
    viscosity; ``cutoff_gap``, ``min_gap``, ``repulsion_strength`` as in
    :func:`~suspsim.bodies.lubrication.lubrication_pair_force` and
    :func:`~suspsim.bodies.lubrication.repulsion_force`; ``friction`` the Coulomb coefficient
    μ_c [1] of the contact the repulsion stands for and ``rolling_friction`` its rolling
    resistance μ_r [1] (module docstring; 0: frictionless).

    Writes ``out`` (4, 3): rows J1, J2 (impulses on 1 and 2, J2 = −J1) and L1, L2 (angular
    impulses); the new velocities are U + dU + J/m, Ω + dΩ + L/I. Returns the predicted gap at
    the end of the step (s + δt x, normal mode, module docstring); ≤ 0 flags an overlap, which the
    scheme excludes unless the capped forces below ``min_gap`` are overpowered.
    """
    c1, c2, c3, ell = sphere_squeeze_law(a1, a2)
    return _pair_impulse(a1, a2, r12, U1, U2, W1, W2, dU1, dU2, dW1, dW2, m1, m2, I1, I2, dt,
                         mu, c1, c2, c3, ell, cutoff_gap, min_gap, repulsion_strength, friction,
                         rolling_friction, out)


@njit(**JIT_OPTIONS)
def lubrication_pair_impulse_law(a1, a2, r12, U1, U2, W1, W2, dU1, dU2, dW1, dW2, m1, m2, I1,
                                 I2, dt, mu, c1, c2, c3, ell, cutoff_gap, min_gap,
                                 repulsion_strength, friction, rolling_friction, out):
    """:func:`lubrication_pair_impulse` with the normal law (c1, c2, c3, ℓ) of
    :func:`~suspsim.bodies.lubrication.normal_resistance` given: e.g. c1 from the curvatures
    of two non-spherical surfaces (SPEC §3.4,
    :func:`~suspsim.bodies.lubrication.curved_squeeze_coefficient`) and c2, c3, ℓ of the
    spheres a1, a2 that osculate them (:mod:`~suspsim.bodies.grain_lubrication_pass`). The
    tangential and twist modes are those of the spheres a1, a2."""
    return _pair_impulse(a1, a2, r12, U1, U2, W1, W2, dU1, dU2, dW1, dW2, m1, m2, I1, I2, dt,
                         mu, c1, c2, c3, ell, cutoff_gap, min_gap, repulsion_strength, friction,
                         rolling_friction, out)


@njit(inline="always", **JIT_OPTIONS)
def _stop_within(yx, yy, yz, mobility, limit):
    """Impulse −y/W that stops a mode of velocity y and mobility W, scaled down to length
    ``limit`` if longer (Coulomb stick or slip; module docstring)."""
    jx, jy, jz = -yx / mobility, -yy / mobility, -yz / mobility
    stick = math.sqrt(jx * jx + jy * jy + jz * jz)
    if stick > limit:
        slip = limit / stick
        jx, jy, jz = jx * slip, jy * slip, jz * slip
    return jx, jy, jz


@njit(inline="always", **JIT_OPTIONS)
def _pair_impulse(a1, a2, r12, U1, U2, W1, W2, dU1, dU2, dW1, dW2, m1, m2, I1, I2, dt, mu, c1, c2,
                  c3, ell, cutoff_gap, min_gap, repulsion_strength, friction, rolling_friction,
                  out):
    dx, dy, dz, s, kap = _pair_geometry(a1, a2, r12)
    out[:, :] = 0.0
    v1x, v1y, v1z = U1[0] + dU1[0], U1[1] + dU1[1], U1[2] + dU1[2]
    v2x, v2y, v2z = U2[0] + dU2[0], U2[1] + dU2[1], U2[2] + dU2[2]
    o1x, o1y, o1z = W1[0] + dW1[0], W1[1] + dW1[1], W1[2] + dW1[2]
    o2x, o2y, o2z = W2[0] + dW2[0], W2[1] + dW2[1], W2[2] + dW2[2]
    ux, uy, uz = v1x - v2x, v1y - v2y, v1z - v2z
    un = ux * dx + uy * dy + uz * dz
    inv_m = 1.0 / m1 + 1.0 / m2
    # normal mode: exact impulse, implicit in the end-of-step gap
    s_new, j_lub, j_rep = implicit_normal_gap(s, -un, inv_m, dt, mu, c1, c2, c3, ell,
                                              cutoff_gap, min_gap, repulsion_strength)
    jn = j_lub + j_rep
    if s >= cutoff_gap:
        out[0, 0] = -jn * dx
        out[0, 1] = -jn * dy
        out[0, 2] = -jn * dz
        out[1, 0] = jn * dx
        out[1, 1] = jn * dy
        out[1, 2] = jn * dz
        return s_new
    # tangential (sliding σ, rolling ρ) and twist: linear backward Euler at the current gap
    _, m_ss, m_sr, m_rr, m_t = pair_mode_resistances(a1, a2, s, cutoff_gap, min_gap)
    cx, cy, cz = _cross(a1 * o1x + a2 * o2x, a1 * o1y + a2 * o2y, a1 * o1z + a2 * o2z,
                        dx, dy, dz)
    sx = ux - un * dx + kap * cx
    sy = uy - un * dy + kap * cy
    sz = uz - un * dz + kap * cz
    wx, wy, wz = o1x - o2x, o1y - o2y, o1z - o2z
    rx, ry, rz = _cross(wx, wy, wz, dx, dy, dz)
    wn = wx * dx + wy * dy + wz * dz
    inv_i1 = 1.0 / I1
    inv_i2 = 1.0 / I2
    w_ss = inv_m + kap * kap * (a1 * a1 * inv_i1 + a2 * a2 * inv_i2)
    w_sr = kap * (a1 * inv_i1 - a2 * inv_i2)
    w_rr = inv_i1 + inv_i2
    k_ss = mu * m_ss
    k_sr = mu * m_sr
    k_rr = mu * m_rr
    b11 = 1.0 + dt * (w_ss * k_ss + w_sr * k_sr)
    b12 = dt * (w_ss * k_sr + w_sr * k_rr)
    b21 = dt * (w_sr * k_ss + w_rr * k_sr)
    b22 = 1.0 + dt * (w_sr * k_sr + w_rr * k_rr)
    inv_det = 1.0 / (b11 * b22 - b12 * b21)
    nsx = (b22 * sx - b12 * rx) * inv_det
    nsy = (b22 * sy - b12 * ry) * inv_det
    nsz = (b22 * sz - b12 * rz) * inv_det
    nrx = (b11 * rx - b21 * sx) * inv_det
    nry = (b11 * ry - b21 * sy) * inv_det
    nrz = (b11 * rz - b21 * sz) * inv_det
    # impulses of the generalized forces −μ M y' over dt
    fsx = -dt * (k_ss * nsx + k_sr * nrx)
    fsy = -dt * (k_ss * nsy + k_sr * nry)
    fsz = -dt * (k_ss * nsz + k_sr * nrz)
    frx = -dt * (k_sr * nsx + k_rr * nrx)
    fry = -dt * (k_sr * nsy + k_rr * nry)
    frz = -dt * (k_sr * nsz + k_rr * nrz)
    if friction > 0.0 and j_rep > 0.0:
        # Coulomb contact: stop the sliding left after lubrication, within μ_c j_rep
        jfx, jfy, jfz = _stop_within(nsx, nsy, nsz, w_ss, friction * j_rep)
        fsx += jfx
        fsy += jfy
        fsz += jfz
        nrx += w_sr * jfx
        nry += w_sr * jfy
        nrz += w_sr * jfz
    if rolling_friction > 0.0 and j_rep > 0.0:
        # rolling resistance: stop the rolling left, within μ_r R_eff j_rep
        jrx, jry, jrz = _stop_within(nrx, nry, nrz, w_rr,
                                     rolling_friction * a1 * a2 / (a1 + a2) * j_rep)
        frx += jrx
        fry += jry
        frz += jrz
    k_t = mu * m_t
    jt = -dt * k_t * wn / (1.0 + dt * k_t * w_rr)
    out[0, 0] = fsx - jn * dx
    out[0, 1] = fsy - jn * dy
    out[0, 2] = fsz - jn * dz
    out[1, 0] = -out[0, 0]
    out[1, 1] = -out[0, 1]
    out[1, 2] = -out[0, 2]
    ax, ay, az = _cross(dx, dy, dz, fsx, fsy, fsz)
    bx, by, bz = _cross(dx, dy, dz, frx, fry, frz)
    out[2, 0] = kap * a1 * ax + bx + jt * dx
    out[2, 1] = kap * a1 * ay + by + jt * dy
    out[2, 2] = kap * a1 * az + bz + jt * dz
    out[3, 0] = kap * a2 * ax - bx - jt * dx
    out[3, 1] = kap * a2 * ay - by - jt * dy
    out[3, 2] = kap * a2 * az - bz - jt * dz
    return s_new
