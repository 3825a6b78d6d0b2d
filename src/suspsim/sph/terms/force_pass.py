"""Force pass: pressure + viscous (A + B^c) pair forces, ∇a sums and the stress virial.

One pass over the step's pair table (pattern of ``density``: half table, T chunks, chunk 0 into
the output, chunk c ≥ 1 into ``scratch[c − 1]``). Per pair (i, j), r = r_ij, v = ṽ_ij (with the
Lees–Edwards correction v_x −= n γ̇ L_y):

    f_ij = m² (P_i/ρ_i² + P_j/ρ_j²) F r                         (``pressure``, SPEC §2.2)
         − (μ̂_i + μ̂_j) m² F/(ρ_i ρ_j) [α (r·v) r/r² + β v]      (``viscous``, SPEC §2.3–2.4)

with m² F/(ρ_i ρ_j) = F V_i V_j from the step's volumes V = m/ρ, added to i and subtracted from j (antisymmetric: momentum conserved to round-off).
A fluid–body pair takes the fluid particle's μ̂ at both ends: a body particle has no viscosity
of its own, and the rate of its one-sided neighbourhood is meaningless (in a power-law matrix,
n = 0.5, its μ̂ read 2 × the fluid's, which stiffened every fluid–body pair by a third). A pair
of particles of two bodies takes at each end the μ̂ of the fluid beside that particle
(``density.body_particle_density``). Pairs of two particles of one rigid body
(``body_of[i] == body_of[j] ≥ 0``) have no force: they are internal to the body, and the β
term of a rotating body would give a spurious torque. The simulation's list does not hold
them (``group`` of ``neighbours.build_neighbour_list``); the loop also skips them, for tables
built without groups. For the same reason a pair with a body particle takes v relative to the
body's rigid rotation, v − Ω_B × r (``viscous.spin_free_velocity``; Ω_B from ``body_spin``),
and with ``numerics.spin_correction`` every pair takes v relative to the mean of its two
particles' spins (``viscous.particle_spin``: ½ ∇×v of a fluid particle, Ω_B of a body's), which
makes the stress symmetric. With the bulk correction and a varying viscosity (and no spin
correction, whose pair sum needs no explicit term) the pass also sums Σ_j V_j F (a_i − a_j) r_ij
for ∇a = M2⁻¹ Σ_j V_j F (a_i − a_j) r_ij (moment-corrected, as the velocity gradient), whose
explicit term ½ ∂_i a ∇·v − ½ ∂_k a ∂_i v_k is added per particle afterwards; it has no pair
form and is left out of the virial (it vanishes in simple shear and plane Poiseuille).

With particle shifting (``terms.shifting``) the pass also sums the particle concentration
gradient ∇C_i = −Σ_j V_j F r_ij over the same pairs, so shifting needs no pass of its own (its
positions and volumes are the force pass's: shifting acts after the kick, before the next
drift). A pass of its own cost 0.55 ms per step; these sums add 0.15 ms in a Newtonian matrix
and 0.35 ms beside the bulk gradient's sums (φ = 0.4 benchmark suspensions, two threads). Pairs
inside one body are skipped here, which changes ∇C only on body particles, which do not shift.

The accumulator holds per particle the force (3), then the ∇a sums (3) with the bulk
gradient, then ∇C (3) with shifting, then ∇C_b = −Σ_{j ∈ bodies} V_j F r_ij (3), the bodies'
part of ∇C, where shifting is tangential at bodies (:func:`force_width`): the plain fluid
scatters 3 values per pair end, not 12.

The virial Σ_pairs f_ij,a r_ij,b (½ Σ_i Σ_j of SPEC §2.8 over the half table) is summed per
chunk into ``virial[c]`` = (xx, yy, zz, xy, yx); ``stress`` turns it into Π and σ = −Π.
Accelerations: a_i = (Σ_j f_ij)/m + body force + explicit ∇a term.

Symbols: P pressure, ρ density, ρ_eq N m/V, c² squared sound speed, μ̂ normalised viscosity,
a = −(1 + 2/d) μ̂ bulk parameter, (α, β) weights (``viscous``), g body acceleration
(Poiseuille: +g for y mod L_y < L_y/2, −g above; SPEC §2.7), m particle mass.
"""
from __future__ import annotations

import math

from numba import njit, prange

from suspsim.sph import JIT_OPTIONS
from suspsim.sph.chunks import add_chunk_buffers
from suspsim.sph.terms.pressure import pressure_pair, pressure_term
from suspsim.sph.terms.viscous import (explicit_bulk_term, pair_viscosity, particle_spin,
                                      spin_bulk_pressure, spin_free_velocity, viscous_pair,
                                      without_rotation)


@njit(inline="always", **JIT_OPTIONS)
def concentration_column(bulk_gradient):
    """The accumulator's first ∇C column (:func:`force_width`); ∇C_b follows it."""
    return 6 if bulk_gradient else 3


def force_width(bulk_gradient: bool, shifting: bool, body_normal: bool = False) -> int:
    """Values per particle in the force accumulator: force (3), Σ V_j F (a_i − a_j) r (3) with
    the bulk gradient, ∇C (3) with shifting, then ∇C_b (3), the bodies' part of ∇C, with
    ``body_normal`` (shifting tangential at bodies, ``terms.shifting``)."""
    return (concentration_column(bool(bulk_gradient)) + 3 * bool(shifting)
            + 3 * bool(shifting and body_normal))


#: Columns of a chunk's virial row.
VXX, VYY, VZZ, VXY, VYX = range(5)


@njit(inline="always", **JIT_OPTIONS)
def _force_loop(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image, velocity,
                volume, pressure, viscosity, alpha, beta, bulk_factor, bulk_gradient, shear_ly,
                body_of, body_spin, spin_correction, spin, acc, virial_row):
    """acc[w i ...] += forces, ∇a sums and ∇C (layout of :func:`force_width`) of particles
    lo..hi−1, both ends; virial_row +=. ``spin`` (N, 3): each particle's
    ``viscous.particle_spin``, read with ``spin_correction``."""
    n = volume.shape[0]
    width = acc.shape[0] // n
    # The start's relaxation turns the bulk gradient off in the run's wider accumulator; it does
    # not shift, so wherever ∇C lands then is scratch.
    c0 = concentration_column(bulk_gradient)
    concentration = width > c0
    body_normal = width > c0 + 3
    sums = acc.reshape((n, width))
    sxx = syy = szz = sxy = syx = 0.0
    for i in range(lo, hi):
        p_i = pressure[i]
        mu_i = viscosity[i]
        a_i = bulk_factor * mu_i
        vol_i = volume[i]
        body_i = body_of[i]
        vxi, vyi, vzi = velocity[i, 0], velocity[i, 1], velocity[i, 2]
        oxi = oyi = ozi = 0.0
        if spin_correction:
            oxi, oyi, ozi = spin[i, 0], spin[i, 1], spin[i, 2]
        fxi = fyi = fzi = 0.0
        gxi = gyi = gzi = 0.0
        cxi = cyi = czi = 0.0
        first, last = start[i], pair_end[i]
        js, rows, images = pair_j[first:last], geometry[first:last], pair_image[first:last]
        n_plain = pair_cross[i] - first
        for k in range(js.shape[0]):
            j = js[k]
            body_j = body_of[j]
            if body_i >= 0 and body_j == body_i:
                continue
            dx, dy, dz, f = rows[k, 0], rows[k, 1], rows[k, 2], rows[k, 3]
            r2 = dx * dx + dy * dy + dz * dz
            vx = vxi - velocity[j, 0]
            if k >= n_plain:
                vx -= images[k] * shear_ly
            vy = vyi - velocity[j, 1]
            vz = vzi - velocity[j, 2]
            vol_j = volume[j]
            kp = pressure_pair(p_i, pressure[j], f)
            mu_a, mu_b = mu_i, viscosity[j]
            if spin_correction:
                vx, vy, vz = without_rotation(0.5 * (oxi + spin[j, 0]), 0.5 * (oyi + spin[j, 1]),
                                              0.5 * (ozi + spin[j, 2]), dx, dy, dz, vx, vy, vz)
            elif body_i >= 0 or body_j >= 0:
                vx, vy, vz = spin_free_velocity(body_spin, body_i, body_j, dx, dy, dz,
                                                vx, vy, vz)
            if body_i < 0 <= body_j:
                mu_b = mu_a
            elif body_j < 0 <= body_i:
                mu_a = mu_b
            wx, wy, wz = viscous_pair(pair_viscosity(mu_a, mu_b), f * vol_i * vol_j,
                                      dx, dy, dz, r2, vx, vy, vz, alpha, beta)
            fx = kp * dx + wx
            fy = kp * dy + wy
            fz = kp * dz + wz
            fxi += fx
            fyi += fy
            fzi += fz
            sums[j, 0] -= fx
            sums[j, 1] -= fy
            sums[j, 2] -= fz
            sxx += fx * dx
            syy += fy * dy
            szz += fz * dz
            sxy += fx * dy
            syx += fy * dx
            if bulk_gradient:
                t = f * (a_i - bulk_factor * viscosity[j])
                tj = t * vol_j
                gxi += tj * dx
                gyi += tj * dy
                gzi += tj * dz
                ti = t * vol_i
                sums[j, 3] += ti * dx
                sums[j, 4] += ti * dy
                sums[j, 5] += ti * dz
            if concentration:
                cj = vol_j * f
                cxi -= cj * dx
                cyi -= cj * dy
                czi -= cj * dz
                ci = vol_i * f
                sums[j, c0] += ci * dx
                sums[j, c0 + 1] += ci * dy
                sums[j, c0 + 2] += ci * dz
                if body_normal and body_i < 0 <= body_j:
                    sums[i, c0 + 3] -= cj * dx
                    sums[i, c0 + 4] -= cj * dy
                    sums[i, c0 + 5] -= cj * dz
                elif body_normal and body_j < 0 <= body_i:
                    sums[j, c0 + 3] += ci * dx
                    sums[j, c0 + 4] += ci * dy
                    sums[j, c0 + 5] += ci * dz
        sums[i, 0] += fxi
        sums[i, 1] += fyi
        sums[i, 2] += fzi
        if bulk_gradient:
            sums[i, 3] += gxi
            sums[i, 4] += gyi
            sums[i, 5] += gzi
        if concentration:
            sums[i, c0] += cxi
            sums[i, c0 + 1] += cyi
            sums[i, c0 + 2] += czi
    virial_row[VXX] = sxx
    virial_row[VYY] = syy
    virial_row[VZZ] = szz
    virial_row[VXY] = sxy
    virial_row[VYX] = syx


@njit(parallel=True, **JIT_OPTIONS)
def force_sums(start, pair_end, pair_j, geometry, pair_cross, pair_image, velocity, rho, volume,
               viscosity, mass, rho_eq, c2, alpha, beta, bulk_factor, bulk_gradient, shear_ly,
               body_of, body_spin, spin_correction, spin_bulk, gradient, pressure, spin, acc,
               scratch, bounds, virial):
    """acc (w N,) = pair forces, ∇a sums and ∇C of every particle, w = :func:`force_width`
    (columns beyond the force and, with ``bulk_gradient``, the ∇a sums take ∇C); ``scratch``
    rows of w N; virial (T, 5) per chunk; ``pressure`` (N,) scratch for the particles'
    m² P/ρ²; ``spin`` (N, 3) scratch for their spins (``spin_correction``); ``body_of`` (N,)
    the rigid body of each particle, −1 for fluid; ``body_spin`` (B, 3) the bodies' angular
    velocities [τ⁻¹] (:func:`spin_free_velocity`; any (≥ 1, 3) array without bodies);
    ``spin_correction`` takes fluid–fluid pairs' v relative to the mean local spin of the two
    particles (``viscous.local_spin``) from ``gradient`` (N, 9);
    ``spin_bulk`` ζ/μ of that form, removed through the fluid particles' pressure
    (``viscous.spin_bulk_pressure``; 0 leaves the pressure alone)."""
    for i in prange(rho.shape[0]):
        pressure[i] = pressure_term(rho[i], rho_eq, c2, mass)
        if spin_bulk != 0.0 and body_of[i] < 0:
            pressure[i] += (mass * mass / (rho[i] * rho[i])
                            * spin_bulk_pressure(viscosity[i], gradient[i], spin_bulk))
        # Once per particle, not at both ends of every pair from a 9-wide gradient row: the
        # benchmark suspension's pass went from 3.3 to 3.0–3.2 ms (one thread).
        if spin_correction:
            spin[i, 0], spin[i, 1], spin[i, 2] = particle_spin(body_spin, body_of[i], gradient[i])
    n_chunks = scratch.shape[0] + 1
    width = acc.shape[0] // rho.shape[0]
    if bulk_gradient and width < 6:
        raise ValueError("the force accumulator has no columns for the bulk gradient's sums "
                         "(force_pass.force_width)")
    for c in prange(n_chunks):
        lo, hi = bounds[c], bounds[c + 1]
        if c == 0:
            acc[:] = 0.0
            _force_loop(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image,
                        velocity, volume, pressure, viscosity, alpha, beta, bulk_factor,
                        bulk_gradient, shear_ly, body_of, body_spin, spin_correction, spin,
                        acc, virial[0])
        else:
            buffer = scratch[c - 1]
            buffer[width * lo:] = 0.0
            _force_loop(lo, hi, start, pair_end, pair_j, geometry, pair_cross, pair_image,
                        velocity, volume, pressure, viscosity, alpha, beta, bulk_factor,
                        bulk_gradient, shear_ly, body_of, body_spin, spin_correction, spin,
                        buffer, virial[c])
    add_chunk_buffers(acc, scratch, bounds, n_chunks, width)


@njit(parallel=True, **JIT_OPTIONS)
def force_finish(acc, positions, rho, inverse_moment, gradient, mass, bulk_gradient, body_force,
                 ly, accel):
    """a_i = F_i/m + body force + explicit ∇a term (module docstring)."""
    half = 0.5 * ly
    width = acc.shape[0] // accel.shape[0]
    for i in prange(accel.shape[0]):
        b = width * i
        ax = acc[b] / mass
        ay = acc[b + 1] / mass
        az = acc[b + 2] / mass
        if body_force != 0.0:
            y = positions[i, 1] - ly * math.floor(positions[i, 1] / ly)
            ax += body_force if y < half else -body_force
        if bulk_gradient:
            m = inverse_moment[i]
            sx, sy, sz = acc[b + 3], acc[b + 4], acc[b + 5]
            gax = m[0] * sx + m[3] * sy + m[4] * sz
            gay = m[3] * sx + m[1] * sy + m[5] * sz
            gaz = m[4] * sx + m[5] * sy + m[2] * sz
            ex, ey, ez = explicit_bulk_term(gax, gay, gaz, gradient[i], rho[i])
            ax += ex
            ay += ey
            az += ez
        accel[i, 0] = ax
        accel[i, 1] = ay
        accel[i, 2] = az
