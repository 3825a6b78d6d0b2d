"""Groot–Warren modified velocity Verlet and the compiled step loop (SPEC §2.6; seed 000 Eqs. 21–23).

One step of size δt:

    x(t + δt) = x + v δt + ½ δt² a(t)
    ṽ         = v + λ δt a(t),  λ = ½
    a(t + δt) = f(x(t + δt), ṽ)/m          (density → gradient → normalisation → force passes)
    v(t + δt) = v + ½ δt (a(t) + a(t + δt))

The viscosity update uses ṽ (the gradient pass reads ṽ). The imposed Couette flow is
γ̇ (y − L_y/2) (``lattice``), at rest at y_0 = L_y/2, the origin of the rebuild criterion. :func:`advance_steps` runs whole steps
in compiled code and returns early, after the drift of a step, when the neighbour list must be
rebuilt (``list_validity.list_outdated``) or, after a density pass that found the pair table too
small, the table grown; the caller rebuilds (wrap, sort, list) or grows the table and calls
again with ``resume=True``, which finishes that step. Time is step_count · δt (no drift of
round-off).

Symbols: x, v, a positions, velocities, accelerations (N, 3); ṽ predicted velocity; λ the
Groot–Warren factor; δt time step [τ]; γ̇ imposed shear rate; Δ Lees–Edwards offset.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from suspsim.sph import JIT_OPTIONS
from suspsim.sph.boundaries import lees_edwards_offset
from suspsim.sph.density import (TABLE_OK, body_particle_density, mass_density,
                                 summation_density)
from suspsim.sph.list_validity import MAX_CHECKED_OUTLIERS, list_outdated
from suspsim.sph.terms.force_pass import force_finish, force_sums
from suspsim.sph.terms.rate_smoothing import RATE_WIDTH, smoothed_rate_viscosity
from suspsim.sph.terms.viscous import spin_bulk_coefficient
from suspsim.sph.terms.velocity_pass import (_dissipation_sums, _gradient_finish, _gradient_sums,
                                             _normalisation_finish, normalisation_due)

#: Groot–Warren λ [seed 000 Eq. 23].
LAMBDA = 0.5
#: Why :func:`advance_steps` returned.
DONE, REBUILD, GROW_TABLE = 0, 1, 2


@njit(parallel=True, **JIT_OPTIONS)
def drift(positions, velocities, accel, dt):
    """x += v δt + ½ δt² a."""
    half = 0.5 * dt * dt
    for i in prange(positions.shape[0]):
        for a in range(3):
            positions[i, a] += velocities[i, a] * dt + half * accel[i, a]


@njit(parallel=True, **JIT_OPTIONS)
def predict(velocities, accel, dt, predicted):
    """ṽ = v + λ δt a."""
    k = LAMBDA * dt
    for i in prange(velocities.shape[0]):
        for a in range(3):
            predicted[i, a] = velocities[i, a] + k * accel[i, a]


@njit(parallel=True, **JIT_OPTIONS)
def kick(velocities, accel, accel_new, dt):
    """v += ½ δt (a(t) + a(t + δt)); then a(t) ← a(t + δt)."""
    half = 0.5 * dt
    for i in prange(velocities.shape[0]):
        for a in range(3):
            velocities[i, a] += half * (accel[i, a] + accel_new[i, a])
            accel[i, a] = accel_new[i, a]


@njit(**JIT_OPTIONS)
def accelerations(positions, predicted, box, offset, nl_start, nl_image_start, nl_neighbours,
                  kernel, h, mass, rho_eq, c2, shear_rate, body_force, dimension, law_code,
                  law_params, newtonian, velocity_gradient, smooth_rate, normalise,
                  normalisation_interval, normalisation_age, alpha, beta,
                  bulk_factor, bulk_gradient, has_bodies, body_of, body_spin, spin_correction,
                  rho, volume, pressure, spin, pair_start, pair_end, pair_j, geometry, pair_cross,
                  pair_image, gradient, inverse_moment, moment_trace, strain, dissipation, gdot,
                  viscosity, factor, viscosity_hat, grad_acc, diss_acc, force_acc, scratch_1,
                  scratch_15, force_scratch, bounds, virial, accel_out):
    """a = f(x, ṽ)/m through the four passes; fills ρ, γ̇, μ, s, μ̂, the virial and ``accel_out``.

    Returns ``density.TABLE_OK``, or ``density.TABLE_OVERFLOW`` straight after the density pass
    when the pair table is too small: grow it and call again (nothing else was changed).

    ``velocity_gradient`` runs the gradient pass (needed by a non-Newtonian law or the
    normalisation); ``smooth_rate`` evaluates a non-Newtonian law at the kernel-smoothed rate
    (``terms.rate_smoothing``); ``normalise`` the normalisation pass (else μ̂ must equal μ on
    entry); a Newtonian fluid runs the gradient and normalisation passes only on the steps
    :func:`~suspsim.sph.terms.velocity_pass.normalisation_due` picks from
    ``normalisation_interval`` and ``normalisation_age`` and holds μ̂ in between;
    ``bulk_gradient`` the ∇a sums (B on, μ varying, no spin correction). ``has_bodies``: the
    scene has rigid bodies (angular velocities ``body_spin`` (B, 3), for
    ``terms.viscous.spin_free_velocity``; a (1, 3) array of zeros without bodies), whose
    particles (``body_of`` (N,) ≥ 0; −1 for fluid) have no pairs inside their own body in the
    list (``group`` of ``neighbours.build_neighbour_list``) and take their density and μ̂
    from the fluid around them (``density.body_particle_density``); their gradient, rate and
    inverse moment are 0 and the normalisation keeps their μ̂ (``velocity_pass``).
    ``spin_correction`` (``numerics.spin_correction``, which needs ``velocity_gradient``)
    takes the β term of fluid–fluid pairs relative to the particles' local spin
    (``terms.viscous.local_spin``; ``spin`` (N, 3) scratch holds each particle's), normalises
    by the strain rate alone and removes its bulk viscosity through the pressure
    (``terms.viscous.spin_bulk_pressure``).
    """
    shear_ly = shear_rate * box[1]
    code = summation_density(positions, box, offset, nl_start, nl_image_start, nl_neighbours,
                             kernel, h, rho, pair_start, pair_end, pair_j, geometry, pair_cross,
                             pair_image, scratch_1, bounds)
    if code != TABLE_OK:
        return code
    mass_density(rho, mass, volume)
    if has_bodies:
        n = rho.shape[0]
        body_particle_density(pair_start, pair_end, pair_j, geometry, body_of, kernel, h, rho,
                              rho_eq, c2, mass, viscosity_hat, grad_acc[:3 * n],
                              scratch_15[:, :3 * n], bounds, volume)
    held = (normalise and newtonian
            and not normalisation_due(normalisation_age, normalisation_interval))
    if velocity_gradient and not held:
        _gradient_sums(pair_start, pair_end, pair_j, geometry, pair_cross, pair_image, predicted,
                       volume, shear_ly, dimension, grad_acc, scratch_15, bounds)
        _gradient_finish(grad_acc, dimension, law_code, law_params, newtonian or smooth_rate,
                         normalise, beta, spin_correction, body_of, gradient, inverse_moment,
                         moment_trace, gdot, viscosity, strain, dissipation)
        if smooth_rate and not newtonian:
            smoothed_rate_viscosity(pair_start, pair_end, pair_j, geometry, kernel, h, volume,
                                    gradient, body_of, law_code, law_params,
                                    grad_acc[:RATE_WIDTH * rho.shape[0]], scratch_15, bounds,
                                    gdot, viscosity)
    if normalise and not held:
        if alpha != 0.0:
            _dissipation_sums(pair_start, pair_end, pair_j, geometry, volume, strain, diss_acc,
                              scratch_1, bounds)
        _normalisation_finish(diss_acc, dissipation, gradient, moment_trace, viscosity, alpha,
                              beta, spin_correction, dimension, body_of, factor, viscosity_hat)
    elif not newtonian:
        for i in range(viscosity.shape[0]):
            if body_of[i] < 0:
                viscosity_hat[i] = viscosity[i]
    force_sums(pair_start, pair_end, pair_j, geometry, pair_cross, pair_image, predicted, rho,
               volume, viscosity_hat, mass, rho_eq, c2, alpha, beta, bulk_factor, bulk_gradient,
               shear_ly, body_of, body_spin, spin_correction,
               spin_bulk_coefficient(spin_correction, dimension), gradient, pressure, spin,
               force_acc, force_scratch, bounds, virial)
    force_finish(force_acc, positions, rho, inverse_moment, gradient, mass, bulk_gradient,
                 body_force, box[1], accel_out)
    return TABLE_OK


@njit(**JIT_OPTIONS)
def advance_steps(n_steps, resume, step_count, dt, build_time, cutoff, skin, reference,
                  nl_cells, nl_cell_start, positions, velocities, accel, predicted, accel_new,
                  box, nl_start,
                  nl_image_start, nl_neighbours, kernel, h, mass, rho_eq, c2, shear_rate,
                  body_force, dimension, law_code, law_params, newtonian, velocity_gradient,
                  smooth_rate, normalise, normalisation_interval, normalisation_age, alpha, beta,
                  bulk_factor, bulk_gradient, has_bodies, body_of, body_spin, spin_correction,
                  rho, volume, pressure, spin, pair_start, pair_end, pair_j, geometry, pair_cross,
                  pair_image, gradient, inverse_moment, moment_trace, strain, dissipation, gdot,
                  viscosity, factor, viscosity_hat, grad_acc, diss_acc, force_acc, scratch_1,
                  scratch_15, force_scratch, bounds, virial):
    """Run up to ``n_steps`` steps from ``step_count``; returns (steps completed, stop).

    stop is :data:`DONE`, or :data:`REBUILD` or :data:`GROW_TABLE`: the drift of step
    ``step_count + completed + 1`` has been applied and the list must be rebuilt, or the pair
    table grown (``density``), before calling again with ``resume=True`` (module docstring).
    """
    done = 0
    while done < n_steps:
        time = (step_count + done + 1) * dt
        offset = lees_edwards_offset(shear_rate, box[0], box[1], time)
        if not resume:
            drift(positions, velocities, accel, dt)
            if list_outdated(positions, reference, shear_rate * (time - build_time), cutoff,
                             skin, 0.5 * box[1], box, offset, nl_cells, nl_cell_start,
                             nl_start, nl_neighbours, body_of,
                             np.int64(MAX_CHECKED_OUTLIERS)):
                return done, REBUILD
        resume = False
        predict(velocities, accel, dt, predicted)
        code = accelerations(
            positions, predicted, box, offset, nl_start, nl_image_start, nl_neighbours, kernel, h,
            mass, rho_eq, c2, shear_rate, body_force, dimension, law_code, law_params, newtonian,
            velocity_gradient, smooth_rate, normalise, normalisation_interval, normalisation_age,
            alpha, beta, bulk_factor, bulk_gradient, has_bodies, body_of, body_spin,
            spin_correction, rho, volume, pressure, spin, pair_start, pair_end, pair_j, geometry,
            pair_cross, pair_image, gradient, inverse_moment, moment_trace, strain, dissipation,
            gdot, viscosity, factor, viscosity_hat, grad_acc, diss_acc, force_acc, scratch_1,
            scratch_15, force_scratch, bounds, virial, accel_new)
        if code != TABLE_OK:
            return done, GROW_TABLE
        kick(velocities, accel, accel_new, dt)
        done += 1
    return done, DONE
