"""Velocity-gradient pass (γ̇, μ) and dissipation-normalisation pass over the pair table.

Both follow the pattern of ``density`` (read it first): half pair table, particles split into
T chunks of equal pair count, chunk 0 accumulating into the output, chunk c ≥ 1 into its row of
``scratch``, rows added by ``add_chunk_buffers``; no allocation, results independent of thread
scheduling. Velocities are the predicted ṽ of the integrator (the viscosity update uses ṽ,
SPEC §2.6); a pair across a sheared face has v_ij,x −= n γ̇ L_y (SPEC §2.7).

Pass 1 (:func:`gradient_pass`): per particle G (9) and M2 (6) (``gradient``), then per particle
g = M2⁻¹ G, γ̇ and, for a non-Newtonian law, μ = viscosity_kernel(code, params, γ̇).
Pass 2 (:func:`normalisation_pass`): D_i = α Σ_j V_j F (r·S_i r)²/r² + β (L Lᵀ):M2
(``normalisation``; the β part is per particle, from pass 1), then s_i and μ̂_i = μ_i/s_i.
Without the normalisation μ̂ = μ and pass 2 is skipped; with α = 0 (2D with the bulk
correction) only its per-particle half runs.

Symbols: V_j = m/ρ_j particle volume [h^d] (``volume``, computed once per step); ``shear_ly`` γ̇ L_y, the velocity jump across the
sheared faces [h τ^−1]; the other symbols as in ``gradient`` and ``normalisation``.
"""
from __future__ import annotations

from numba import njit, prange

from suspsim.rheology.laws import viscosity_kernel
from suspsim.sph import JIT_OPTIONS
from suspsim.sph.chunks import add_chunk_buffers, chunk_bounds
from suspsim.sph.terms.gradient import XX, YY, ZZ, corrected_gradient, invert_symmetric, shear_rate
from suspsim.sph.terms.normalisation import (continuum_dissipation, moment_dissipation,
                                             normalisation_factor, quadratic_form, strain_form)

#: Values per particle accumulated by the gradient pass: G (9) then M2 (xx, yy, zz, xy, xz, yz).
GRADIENT_WIDTH = 15


@njit(inline="always", **JIT_OPTIONS)
def _gradient_loop(lo, hi, start, pair_end, pair_j, geometry, velocity, volume, shear_ly, acc):
    """acc[15 i ...] += (G, M2) of particles lo..hi−1, both ends of each pair."""
    for i in range(lo, hi):
        vol_i = volume[i]
        vxi, vyi, vzi = velocity[i, 0], velocity[i, 1], velocity[i, 2]
        g0 = g1 = g2 = g3 = g4 = g5 = g6 = g7 = g8 = 0.0
        mxx = myy = mzz = mxy = mxz = myz = 0.0
        for k in range(start[i], pair_end[i]):
            j = pair_j[k]
            row = geometry[k]
            dx, dy, dz, f = row[0], row[1], row[2], row[3]
            vx = vxi - velocity[j, 0] - row[4] * shear_ly
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
            b = 15 * j
            acc[b] += fi * a0
            acc[b + 1] += fi * a1
            acc[b + 2] += fi * a2
            acc[b + 3] += fi * a3
            acc[b + 4] += fi * a4
            acc[b + 5] += fi * a5
            acc[b + 6] += fi * a6
            acc[b + 7] += fi * a7
            acc[b + 8] += fi * a8
            acc[b + 9] += fi * bxx
            acc[b + 10] += fi * byy
            acc[b + 11] += fi * bzz
            acc[b + 12] += fi * bxy
            acc[b + 13] += fi * bxz
            acc[b + 14] += fi * byz
        b = 15 * i
        acc[b] += g0
        acc[b + 1] += g1
        acc[b + 2] += g2
        acc[b + 3] += g3
        acc[b + 4] += g4
        acc[b + 5] += g5
        acc[b + 6] += g6
        acc[b + 7] += g7
        acc[b + 8] += g8
        acc[b + 9] += mxx
        acc[b + 10] += myy
        acc[b + 11] += mzz
        acc[b + 12] += mxy
        acc[b + 13] += mxz
        acc[b + 14] += myz


@njit(inline="always", **JIT_OPTIONS)
def _gradient_loop_2d(lo, hi, start, pair_end, pair_j, geometry, velocity, volume, shear_ly,
                      acc):
    """:func:`_gradient_loop` for z ≡ 0: only G_xx, G_xy, G_yx, G_yy, M2_xx, M2_yy, M2_xy (the
    other 8 of the 15 entries stay 0)."""
    for i in range(lo, hi):
        vol_i = volume[i]
        vxi, vyi = velocity[i, 0], velocity[i, 1]
        g0 = g1 = g3 = g4 = mxx = myy = mxy = 0.0
        for k in range(start[i], pair_end[i]):
            j = pair_j[k]
            row = geometry[k]
            dx, dy, f = row[0], row[1], row[3]
            vx = vxi - velocity[j, 0] - row[4] * shear_ly
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
            b = 15 * j
            acc[b] += fi * a0
            acc[b + 1] += fi * a1
            acc[b + 3] += fi * a3
            acc[b + 4] += fi * a4
            acc[b + 9] += fi * bxx
            acc[b + 10] += fi * byy
            acc[b + 12] += fi * bxy
        b = 15 * i
        acc[b] += g0
        acc[b + 1] += g1
        acc[b + 3] += g3
        acc[b + 4] += g4
        acc[b + 9] += mxx
        acc[b + 10] += myy
        acc[b + 12] += mxy


@njit(**JIT_OPTIONS)
def _gradient_chunk(lo, hi, start, pair_end, pair_j, geometry, velocity, volume, shear_ly,
                    dimension, acc):
    """The 2D or 3D loop (each compiled with its dimension fixed)."""
    if dimension == 2:
        _gradient_loop_2d(lo, hi, start, pair_end, pair_j, geometry, velocity, volume, shear_ly,
                          acc)
    else:
        _gradient_loop(lo, hi, start, pair_end, pair_j, geometry, velocity, volume, shear_ly,
                       acc)


@njit(parallel=True, **JIT_OPTIONS)
def _gradient_sums(start, pair_end, pair_j, geometry, velocity, volume, shear_ly, dimension, acc,
                   scratch, bounds):
    """acc (15 N,) = (G, M2) of every particle, T = scratch.shape[0] + 1 chunks."""
    n_chunks = scratch.shape[0] + 1
    chunk_bounds(start, n_chunks, bounds)
    for c in prange(n_chunks):
        lo, hi = bounds[c], bounds[c + 1]
        if c == 0:
            acc[:] = 0.0
            _gradient_chunk(lo, hi, start, pair_end, pair_j, geometry, velocity, volume,
                            shear_ly, dimension, acc)
        else:
            buffer = scratch[c - 1]
            buffer[GRADIENT_WIDTH * lo:] = 0.0
            _gradient_chunk(lo, hi, start, pair_end, pair_j, geometry, velocity, volume,
                            shear_ly, dimension, buffer)
    add_chunk_buffers(acc, scratch, bounds, n_chunks, GRADIENT_WIDTH)


@njit(parallel=True, **JIT_OPTIONS)
def _gradient_finish(acc, dimension, law_code, law_params, newtonian, normalise, beta, gradient,
                     inverse_moment, moment_trace, gdot, viscosity, strain, dissipation):
    """Per particle: g = M2⁻¹ G, tr M2, γ̇ and (non-Newtonian) μ(γ̇) [SPEC §2.5, §1.1]; with
    ``normalise`` also the strain form of g and the β part β (L Lᵀ):M2 of D_i
    (``normalisation``)."""
    for i in prange(gradient.shape[0]):
        sums = acc[GRADIENT_WIDTH * i:GRADIENT_WIDTH * (i + 1)]
        moment = sums[9:]
        moment_trace[i] = moment[XX] + moment[YY] + moment[ZZ]
        if dimension == 2:
            moment[ZZ] = 1.0
        minv = inverse_moment[i]
        invert_symmetric(moment, minv)
        g = gradient[i]
        corrected_gradient(minv, sums, g)
        rate = shear_rate(g)
        gdot[i] = rate
        if not newtonian:
            viscosity[i] = viscosity_kernel(law_code, law_params, rate)
        if normalise:
            strain_form(g, strain[i])
            if dimension == 2:
                moment[ZZ] = 0.0
            dissipation[i] = beta * moment_dissipation(g, moment)


def gradient_pass(start, pair_end, pair_j, geometry, velocity, volume, shear_ly, dimension,
                  law_code, law_params, newtonian, normalise, beta, acc, scratch, bounds,
                  gradient, inverse_moment, moment_trace, gdot, viscosity, strain, dissipation):
    """Python entry of pass 1 (the integrator calls the two compiled halves directly)."""
    _gradient_sums(start, pair_end, pair_j, geometry, velocity, volume, shear_ly, dimension, acc,
                   scratch, bounds)
    _gradient_finish(acc, dimension, law_code, law_params, newtonian, normalise, beta, gradient,
                     inverse_moment, moment_trace, gdot, viscosity, strain, dissipation)


@njit(inline="always", **JIT_OPTIONS)
def _dissipation_loop(lo, hi, start, pair_end, pair_j, geometry, volume, strain, acc):
    """acc[i] += Σ_j V_j F (r·S_i r)²/r² for particles lo..hi−1, both ends of each pair."""
    for i in range(lo, hi):
        vol_i = volume[i]
        si = strain[i]
        own = 0.0
        for k in range(start[i], pair_end[i]):
            j = pair_j[k]
            row = geometry[k]
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
    chunk_bounds(start, n_chunks, bounds)
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
                          dimension, factor, viscosity_hat):
    """D_i = α acc_i + β (L Lᵀ):M2 (``dissipation``), s_i = D_i/D_c and μ̂_i = μ_i/s_i."""
    for i in prange(viscosity.shape[0]):
        g = gradient[i]
        norm2 = 0.0
        for k in range(9):
            norm2 += g[k] * g[k]
        s = normalisation_factor(alpha * acc[i] + dissipation[i],
                                 continuum_dissipation(g, alpha, beta, dimension), norm2,
                                 moment_trace[i], dimension)
        factor[i] = s
        viscosity_hat[i] = viscosity[i] / s


def normalisation_pass(start, pair_end, pair_j, geometry, volume, strain, gradient, moment_trace,
                       viscosity, alpha, beta, dimension, acc, scratch, bounds, dissipation,
                       factor, viscosity_hat):
    """Python entry of pass 2 (the integrator calls the compiled halves directly); the pair
    sums run only when α ≠ 0."""
    if alpha != 0.0:
        _dissipation_sums(start, pair_end, pair_j, geometry, volume, strain, acc, scratch,
                          bounds)
    else:
        acc[:] = 0.0
    _normalisation_finish(acc, dissipation, gradient, moment_trace, viscosity, alpha, beta,
                          dimension, factor, viscosity_hat)
