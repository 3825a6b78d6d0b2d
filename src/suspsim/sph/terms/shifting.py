"""Particle shifting (Lind et al. 2012; SPEC §5.5): keep the fluid's particles evenly spread.

After each step every fluid particle moves by

    δr_i = −D ∇C_i,   ∇C_i = Σ_j V_j ∇W(r_ij) = −Σ_j V_j F(r_ij) r_ij,   D = A h² γ_s δt,

clipped to |δr_i| ≤ :data:`MAX_SHIFT` h, down the gradient of the particle concentration C
(Lind, Xu, Stansby & Rogers 2012, J. Comput. Phys. 231, 1499, Eq. 15, with their ‖v‖ replaced
by γ_s h, a velocity difference across one kernel, so that D does not depend on the frame
[choice]). γ_s is ``numerics.shifting_rate``: the imposed shear rate of a Couette flow by
default; a flow without one (bodies driven through fluid at rest) names its own scale. Its
velocity is carried along the local gradient, v_i += δr_i · ∇v_i (Lind's Taylor correction,
with the step's corrected gradient; a Newtonian fluid's is up to
``numerics.normalisation_interval`` − 1 steps old, ``velocity_pass.normalisation_due``).
Body particles stay rigid; they count in C, so fluid is pushed off dense body shells too.
With ``numerics.shifting_at_bodies: tangential`` a fluid particle beside a body loses the
component of δr_i along n_i = ∇C_b,i = −Σ_{j ∈ bodies} V_j F(r_ij) r_ij, the gradient of the
bodies' own concentration, which points into the nearest body: the fluid is spread along the
surface but not moved across it, as Lind et al. treat a free surface [choice]. Why: shifting
across the surface layer slows the body's coupling to the fluid, more the larger A (each
shifted particle takes the interpolated velocity of where it lands, and beside a rigid shell
that interpolation is one-sided): at A = 100 a torque-free sphere turned at 0.919 × γ̇/2 with
full shifting and at 0.928–1.010 (four runs) tangential, and one sphere's total stress gives
Einstein's [η] = 2.34 (3.51 at the default A = 30; docs/suspensions.md, 2026-12-06). It is an
option, not the default, until the two-sphere squeeze calibration holds at A = 100
(``scene_rules``).

Why: a disordered SPH fluid under shear builds up an anisotropic particle structure whose
pressure forces add an elastic-like shear stress. Measured (Newtonian, n = 4.096 h⁻³, 7.5 h box,
lattice jittered by ±0.5 spacing and relaxed, strain 2–8): σ_xy/(μγ̇) = 1.64 at
Wi = μγ̇/(ρc²) = 10⁻³ without shifting, 1.27 with A = 30; 1.22 at Wi = 10⁻² without, 1.005 with
A = 30 and 0.997 with A = 100 (a lattice start gives 0.991). Numerical only; off by default
for a fluid alone, whose lattice start carries no such structure, on with inclusions.
Its cost: shifting stirs the fluid. A disordered fluid keeps |∇C| ≈ 0.05 h⁻¹ however long it
is shifted, so particles move through it at A h² γ_s |∇C| (1.5 γ̇ h at A = 30) and the fluid
answers with isotropic velocity fluctuations (rms 0.82 γ̇ h at A = 30, fluid alone). A Newtonian
stress averages them out; a shear-thinning law does not. The default A = 3 in a non-Newtonian
matrix (``scene_rules.AUTO_SHIFTING_NON_NEWTONIAN``; 30 in a Newtonian one, where the squeeze
force needs it) gives the same Newtonian η_r as A = 30 (φ = 0.1:
1.248 and 1.244; φ = 0.3: 2.86 and 2.80; a = 2.5 h, 15 h box) with a quarter of the stir
(rms 0.22 γ̇ h; the fully disordered fluid alone then reads σ_xy/(μγ̇) = 1.090, 1.043 at A = 30
and 0.993 at A = 100); without shifting η_r climbs (1.73 at φ = 0.1 by strain 4).
``terms.rate_smoothing`` takes the rest of the stir out of the rate the law sees.

Symbols: V_j = m/ρ_j [h^d]; F = −W'/r [h^−(d+2)]; r_ij = r_i − r_j [h]; A shifting coefficient
[1] (``numerics.shifting``); h support radius; γ_s shifting rate [τ⁻¹]; δt step [τ].
"""
from __future__ import annotations

import math

from numba import njit, prange

from suspsim.sph import JIT_OPTIONS

#: Largest shift per step [h] (SPEC §5.5: 0.1 h).
MAX_SHIFT = 0.1


@njit(parallel=True, **JIT_OPTIONS)
def shift_particles(force_acc, column, tangential, body_of, coefficient, rate, dt, h, gradient,
                    positions, velocities):
    """Shift every fluid particle (module docstring) down ∇C, which the step's force pass summed
    into each particle's w values of ``force_acc`` (flat (w N,), ``force_pass.force_width``)
    from ``column`` on; with ``tangential`` the bodies' part ∇C_b follows it and the shift
    loses its component along ∇C_b; ``gradient`` (N, 9) the step's ∂_k v_l
    (``terms.gradient``)."""
    width = force_acc.shape[0] // positions.shape[0]
    diffusion = coefficient * h * h * abs(rate) * dt
    for i in prange(positions.shape[0]):
        if body_of[i] >= 0:
            continue
        b = width * i + column
        dx = -diffusion * force_acc[b]
        dy = -diffusion * force_acc[b + 1]
        dz = -diffusion * force_acc[b + 2]
        if tangential:
            nx, ny, nz = force_acc[b + 3], force_acc[b + 4], force_acc[b + 5]
            n2 = nx * nx + ny * ny + nz * nz
            if n2 > 0.0:
                along = (dx * nx + dy * ny + dz * nz) / n2
                dx -= along * nx
                dy -= along * ny
                dz -= along * nz
        size = math.sqrt(dx * dx + dy * dy + dz * dz)
        if size > MAX_SHIFT * h:
            scale = MAX_SHIFT * h / size
            dx *= scale
            dy *= scale
            dz *= scale
        g = gradient[i]
        for l in range(3):
            velocities[i, l] += dx * g[l] + dy * g[3 + l] + dz * g[6 + l]
        positions[i, 0] += dx
        positions[i, 1] += dy
        positions[i, 2] += dz
