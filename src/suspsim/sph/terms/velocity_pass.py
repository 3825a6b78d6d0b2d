"""Velocity-gradient pass (γ̇, μ) and dissipation-normalisation pass over the pair table.

Both follow the pattern of ``density`` (read it first): half pair table, particles split into
T chunks of equal pair count, chunk 0 accumulating into the output, chunk c ≥ 1 into its row of
``scratch``, rows added by ``add_chunk_buffers``; no allocation, results independent of thread
scheduling. Velocities are the predicted ṽ of the integrator (the viscosity update uses ṽ,
SPEC §2.6); a pair across a sheared face has v_ij,x −= n γ̇ L_y (SPEC §2.7; the table's
pairs from ``pair_cross[i]`` on, with n in ``pair_image``).

Pass 1 (:func:`_gradient_sums`, then :func:`_gradient_finish`): per particle G (9) and M2 (6)
(``gradient``), then per particle g = M2⁻¹ G, γ̇ and, for a non-Newtonian law,
μ = viscosity_kernel(code, params, γ̇). Pass 2 (:func:`_dissipation_sums`, then
:func:`_normalisation_finish`): D_i = α Σ_j V_j F (r·S_i r)²/r² + β (L Lᵀ):M2
(``normalisation``; the β part is per particle, from pass 1), then s_i and μ̂_i = μ_i/s_i.
Without the normalisation μ̂ = μ and pass 2 is skipped; with α = 0 (2D with the bulk
correction) only its per-particle half runs. A Newtonian fluid needs both passes only for
s, and runs them only on the steps :func:`normalisation_due` picks
(``numerics.normalisation_interval``), holding μ̂ in between; a non-Newtonian fluid needs
pass 1 for μ anyway, and holding s would save only the dissipation sums (on the benchmark box
no faster: 1.78 M particle-steps/s at k = 2 against 1.86 M at k = 1, one thread), so it
updates s every step.

Symbols: V_j = m/ρ_j particle volume [h^d] (``volume``, computed once per step); ``shear_ly`` γ̇ L_y, the velocity jump across the
sheared faces [h τ^−1]; the other symbols as in ``gradient`` and ``normalisation``.
"""
from __future__ import annotations

from numba import njit, prange

from suspsim.rheology.laws import viscosity_kernel
from suspsim.sph import JIT_OPTIONS
from suspsim.sph.chunks import add_chunk_buffers
from suspsim.sph.terms.gradient import XX, YY, ZZ, corrected_gradient, invert_symmetric, shear_rate
from suspsim.sph.terms.normalisation import (continuum_dissipation, moment_dissipation,
                                             normalisation_factor, quadratic_form, strain_form)

#: Values per particle accumulated by the gradient pass: G (9) then M2 (xx, yy, zz, xy, xz, yz).
GRADIENT_WIDTH = 15


@njit(inline="always", **JIT_OPTIONS)
def _gradient_loop(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image, velocity,
                   volume, shear_ly, acc):
    """acc[15 i ...] += (G, M2) of particles lo..hi−1, both ends of each pair."""
    sums = acc.reshape((acc.shape[0] // GRADIENT_WIDTH, GRADIENT_WIDTH))
    for i in range(lo, hi):
        vol_i = volume[i]
        vxi, vyi, vzi = velocity[i, 0], velocity[i, 1], velocity[i, 2]
        g0 = g1 = g2 = g3 = g4 = g5 = g6 = g7 = g8 = 0.0
        mxx = myy = mzz = mxy = mxz = myz = 0.0
        first, last = start[i], pair_end[i]
        js, rows, images = pair_j[first:last], geometry[first:last], pair_image[first:last]
        n_plain = pair_cross[i] - first
        for k in range(js.shape[0]):
            j = js[k]
            row = rows[k]
            dx, dy, dz, f = row[0], row[1], row[2], row[3]
            vx = vxi - velocity[j, 0]
            # Only a pair across a face can have n ≠ 0 (n γ̇ L_y is exact: same v as one FMA).
            if k >= n_plain:
                vx -= images[k] * shear_ly
            vy = vyi - velocity[j, 1]
            vz = vzi - velocity[j, 2]
            fi = f * vol_i
            fj = f * volume[j]
            a0, a1, a2 = dx * vx, dx * vy, dx * vz
            a3, a4, a5 = dy * vx, dy * vy, dy * vz
            a6, a7, a8 = dz * vx, dz * vy, dz * vz
            bxx, byy, bzz = dx * dx, dy * dy, dz * dz
            bxy, bxz, byz = dx * dy, dx * dz, dy * dz
            g0 += fj * a0
            g1 += fj * a1
            g2 += fj * a2
            g3 += fj * a3
            g4 += fj * a4
            g5 += fj * a5
            g6 += fj * a6
            g7 += fj * a7
            g8 += fj * a8
            mxx += fj * bxx
            myy += fj * byy
            mzz += fj * bzz
            mxy += fj * bxy
            mxz += fj * bxz
            myz += fj * byz
            sj = sums[j]
            sj[0] += fi * a0
            sj[1] += fi * a1
            sj[2] += fi * a2
            sj[3] += fi * a3
            sj[4] += fi * a4
            sj[5] += fi * a5
            sj[6] += fi * a6
            sj[7] += fi * a7
            sj[8] += fi * a8
            sj[9] += fi * bxx
            sj[10] += fi * byy
            sj[11] += fi * bzz
            sj[12] += fi * bxy
            sj[13] += fi * bxz
            sj[14] += fi * byz
        si = sums[i]
        si[0] += g0
        si[1] += g1
        si[2] += g2
        si[3] += g3
        si[4] += g4
        si[5] += g5
        si[6] += g6
        si[7] += g7
        si[8] += g8
        si[9] += mxx
        si[10] += myy
        si[11] += mzz
        si[12] += mxy
        si[13] += mxz
        si[14] += myz


@njit(inline="always", **JIT_OPTIONS)
def _gradient_loop_2d(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image,
                      velocity, volume, shear_ly, acc):
    """:func:`_gradient_loop` for z ≡ 0: only G_xx, G_xy, G_yx, G_yy, M2_xx, M2_yy, M2_xy (the
    other 8 of the 15 entries stay 0)."""
    sums = acc.reshape((acc.shape[0] // GRADIENT_WIDTH, GRADIENT_WIDTH))
    for i in range(lo, hi):
        vol_i = volume[i]
        vxi, vyi = velocity[i, 0], velocity[i, 1]
        g0 = g1 = g3 = g4 = mxx = myy = mxy = 0.0
        first, last = start[i], pair_end[i]
        js, rows, images = pair_j[first:last], geometry[first:last], pair_image[first:last]
        n_plain = pair_cross[i] - first
        for k in range(js.shape[0]):
            j = js[k]
            row = rows[k]
            dx, dy, f = row[0], row[1], row[3]
            vx = vxi - velocity[j, 0]
            if k >= n_plain:
                vx -= images[k] * shear_ly
            vy = vyi - velocity[j, 1]
            fi = f * vol_i
            fj = f * volume[j]
            a0, a1, a3, a4 = dx * vx, dx * vy, dy * vx, dy * vy
            bxx, byy, bxy = dx * dx, dy * dy, dx * dy
            g0 += fj * a0
            g1 += fj * a1
            g3 += fj * a3
            g4 += fj * a4
            mxx += fj * bxx
            myy += fj * byy
            mxy += fj * bxy
            sj = sums[j]
            sj[0] += fi * a0
            sj[1] += fi * a1
            sj[3] += fi * a3
            sj[4] += fi * a4
            sj[9] += fi * bxx
            sj[10] += fi * byy
            sj[12] += fi * bxy
        si = sums[i]
        si[0] += g0
        si[1] += g1
        si[3] += g3
        si[4] += g4
        si[9] += mxx
        si[10] += myy
        si[12] += mxy


@njit(**JIT_OPTIONS)
def _gradient_chunk(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image, velocity,
                    volume, shear_ly, dimension, acc):
    """The 2D or 3D loop (each compiled with its dimension fixed)."""
    if dimension == 2:
        _gradient_loop_2d(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image,
                          velocity, volume, shear_ly, acc)
    else:
        _gradient_loop(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image,
                       velocity, volume, shear_ly, acc)


@njit(parallel=True, **JIT_OPTIONS)
def _gradient_sums(start, pair_end, pair_j, geometry, pair_cross, pair_image, velocity, volume,
                   shear_ly, dimension, acc, scratch, bounds):
    """acc (15 N,) = (G, M2) of every particle, T = scratch.shape[0] + 1 chunks."""
    n_chunks = scratch.shape[0] + 1
    for c in prange(n_chunks):
        lo, hi = bounds[c], bounds[c + 1]
        if c == 0:
            acc[:] = 0.0
            _gradient_chunk(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image,
                            velocity, volume, shear_ly, dimension, acc)
        else:
            buffer = scratch[c - 1]
            buffer[GRADIENT_WIDTH * lo:] = 0.0
            _gradient_chunk(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image,
                            velocity, volume, shear_ly, dimension, buffer)
    add_chunk_buffers(acc, scratch, bounds, n_chunks, GRADIENT_WIDTH)


@njit(inline="always", **JIT_OPTIONS)
def _gradient_row(i, acc, dimension, normalise, beta, symmetric, body_of, gradient,
                  inverse_moment, moment_trace, gdot, strain, dissipation):
    """Particle i of :func:`_gradient_finish` without μ."""
    sums = acc[GRADIENT_WIDTH * i:GRADIENT_WIDTH * (i + 1)]
    moment = sums[9:]
    moment_trace[i] = moment[XX] + moment[YY] + moment[ZZ]
    if body_of[i] >= 0:
        gradient[i, :] = 0.0
        inverse_moment[i, :] = 0.0
        gdot[i] = 0.0
        if normalise:
            strain[i, :] = 0.0
            dissipation[i] = 0.0
        return
    if dimension == 2:
        moment[ZZ] = 1.0
    minv = inverse_moment[i]
    invert_symmetric(moment, minv)
    g = gradient[i]
    corrected_gradient(minv, sums, g)
    gdot[i] = shear_rate(g)
    if normalise:
        strain_form(g, strain[i])
        if dimension == 2:
            moment[ZZ] = 0.0
        dissipation[i] = beta * moment_dissipation(g, moment, symmetric)


@njit(parallel=True, **JIT_OPTIONS)
def _gradient_finish(acc, dimension, law_code, law_params, newtonian, normalise, beta, symmetric,
                     body_of, gradient, inverse_moment, moment_trace, gdot, viscosity, strain,
                     dissipation):
    """Per particle: g = M2⁻¹ G, tr M2, γ̇ and (non-Newtonian) μ(γ̇) [SPEC §2.5, §1.1]; with
    ``normalise`` also the strain form of g and the β part β (L Lᵀ):M2 of D_i
    (``normalisation``; with ``symmetric``, ``numerics.spin_correction``, β (S Sᵀ):M2). A
    rigid-body particle (``body_of`` ≥ 0) gets g = 0, M2⁻¹ = 0, γ̇ = 0: it has no pairs
    inside its body, so its M2 is one-sided or zero (``integrator``).

    Measured on the 32,768-particle Papanastasiou bench box (one thread): 1.21 ms with μ in
    the particle loop, 0.93 ms with μ in a loop of its own (the law's call, expm1 here, 0.6 →
    0.3 ms), 0.87 ms with the particle's body in the inline :func:`_gradient_row` (written
    out in the prange body, its row views were reference-counted by atomic calls).
    """
    n = gradient.shape[0]
    for i in prange(n):
        _gradient_row(i, acc, dimension, normalise, beta, symmetric, body_of, gradient,
                      inverse_moment, moment_trace, gdot, strain, dissipation)
    if not newtonian:
        for i in prange(n):
            viscosity[i] = viscosity_kernel(law_code, law_params, gdot[i])


@njit(inline="always", **JIT_OPTIONS)
def _dissipation_loop(lo, hi, start, pair_end, pair_j, geometry, volume, strain, acc):
    """acc[i] += Σ_j V_j F (r·S_i r)²/r² for particles lo..hi−1, both ends of each pair."""
    for i in range(lo, hi):
        vol_i = volume[i]
        si = strain[i]
        own = 0.0
        js, rows = pair_j[start[i]:pair_end[i]], geometry[start[i]:pair_end[i]]
        for k in range(js.shape[0]):
            j = js[k]
            row = rows[k]
            dx, dy, dz, f = row[0], row[1], row[2], row[3]
            xx, yy, zz = dx * dx, dy * dy, dz * dz
            xy, xz, yz = dx * dy, dx * dz, dy * dz
            w = f / (xx + yy + zz)
            qi = quadratic_form(si, xx, yy, zz, xy, xz, yz)
            qj = quadratic_form(strain[j], xx, yy, zz, xy, xz, yz)
            own += w * volume[j] * qi * qi
            acc[j] += w * vol_i * qj * qj
        acc[i] += own


@njit(parallel=True, **JIT_OPTIONS)
def _dissipation_sums(start, pair_end, pair_j, geometry, volume, strain, acc, scratch, bounds):
    """acc (N,) = Σ_j V_j F (r·S_i r)²/r², the α part of D_i without α (``normalisation``)."""
    n_chunks = scratch.shape[0] + 1
    for c in prange(n_chunks):
        lo, hi = bounds[c], bounds[c + 1]
        if c == 0:
            acc[:] = 0.0
            _dissipation_loop(lo, hi, start, pair_end, pair_j, geometry, volume, strain, acc)
        else:
            buffer = scratch[c - 1]
            buffer[lo:] = 0.0
            _dissipation_loop(lo, hi, start, pair_end, pair_j, geometry, volume, strain, buffer)
    add_chunk_buffers(acc, scratch, bounds, n_chunks, 1)


@njit(parallel=True, **JIT_OPTIONS)
def _normalisation_finish(acc, dissipation, gradient, moment_trace, viscosity, alpha, beta,
                          symmetric, dimension, body_of, factor, viscosity_hat):
    """D_i = α acc_i + β (L Lᵀ):M2 (``dissipation``), s_i = D_i/D_c and μ̂_i = μ_i/s_i of the
    fluid particles; a rigid-body particle (``body_of`` ≥ 0) keeps its μ̂, the fluid's beside
    it (``density.body_particle_density``)."""
    for i in prange(viscosity.shape[0]):
        if body_of[i] >= 0:
            continue
        g = gradient[i]
        norm2 = 0.0
        for k in range(9):
            norm2 += g[k] * g[k]
        s = normalisation_factor(alpha * acc[i] + dissipation[i],
                                 continuum_dissipation(g, alpha, beta, dimension, symmetric),
                                 norm2,
                                 moment_trace[i], dimension)
        factor[i] = s
        viscosity_hat[i] = viscosity[i] / s


@njit(**JIT_OPTIONS)
def normalisation_due(age, interval):
    """True when this step recomputes s (``numerics.normalisation_interval`` = ``interval``,
    Newtonian fluids).

    ``age`` (1,) int64 counts the steps still to hold s: 0 means due now (a neighbour-list
    rebuild, which reorders the particles, sets it to 0), after which it restarts at
    ``interval`` − 1.
    """
    if age[0] <= 0:
        age[0] = interval - 1
        return True
    age[0] -= 1
    return False
