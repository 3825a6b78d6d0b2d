"""Compiled step loop of the DST solver (2D and 3D): rates, step size, predictor–corrector.

Rates (:func:`evaluate`), in this order, at a state (x, v, ρ, f, V_w):

1. rebuild the neighbour list if some particle moved more than skin/2;
2. fluid viscosity η_i = η(f_i) (a jammed particle, φ ≥ φ_J(f_i), stops the run) and Tait
   pressure p_i;
3. :func:`~suspsim.dst.passes.wall_pass` (dummy pressure, density, no-slip velocity), then
   :func:`~suspsim.dst.passes.fluid_pass` (dρ/dt, dv/dt, G, ∇²f, ...);
4. γ̇_i = sqrt(2 D:D), σ_i = η_i γ̇_i, Df_i/Dt = K_f γ̇_i (f̂(σ_i) − f_i) + α ∇²f_i;
5. stress control (SPEC §5.4): dV_w/dt = (σ_in A_w − F_r)/M_w with F_r = Σ_i m a_top,i the
   viscous drag of the fluid on the top wall (a_top,i the x-acceleration of i by the top-wall
   particles; the reaction is −m a_top,i), A_w = L_x (per unit depth in 2D; L_x L_z in 3D).

Step (:func:`advance_steps`, SPEC §5.2): δt = min(C_c h_sl/c, C_ν ρ0 h_sl²/η_max,
C_a sqrt(h_sl/a_max), C_α h_sl²/α) (Morris et al. 1997 with the quintic smoothing length; the
sound speed c bounds v_max + c by the Mach check), then the predictor–corrector
φ^(n+½) = φ^n + (δt/2) Dφ^n, φ^(n+1) = 2 φ^(n+½,c) − φ^n = φ^n + δt Dφ^(n+½) for x, v, ρ, f
and V_w (the top-wall particles move with V_w). f is kept in [0, 1] against round-off.
Optional shifting (Lind et al., J. Comput. Phys. 231, 1499 (2012), Eq. 21):
δx_i = −D ∇C_i with D = A h_sl |v_i| δt, |δx_i| ≤ 0.1 h_sl, then v_i and f_i are corrected
to first order (v_i += G_i δx_i, f_i += ∇f_i·δx_i), using the gradients of the half step.
(SPEC §5.5 writes an extra δt; Lind's D = A h |v| δt already makes δx a length.)

Blow-up checks after every step return an error code (Python raises NumericalError).

The dimension d (``Config.dimension``, 2 or 3; positions are (N, d)) picks the 2D or 3D
neighbour list and pair passes and the γ̇ of a d × d gradient; the per-particle loops run over
d components. No criterion above carries a factor of d (the kernel normalisation does).
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from suspsim.dst.neighbours import (OK, build_list, build_list_3d, needs_rebuild,
                                    needs_rebuild_3d)
from suspsim.dst.passes import fluid_pass, fluid_pass_3d, wall_pass, wall_pass_3d
from suspsim.dst.terms import (microstructure_rate, shear_rate_2d, shear_rate_3d,
                               suspension_viscosity, tait_pressure)
from suspsim.sph import JIT_OPTIONS

#: Codes returned by the compiled loop.
STEP_OK, NONFINITE, DENSITY_ERROR, MACH_LIMIT, JAMMED, LIST_OVERFLOW, NEAR_JAMMING = range(7)

#: Indices of the wall-state array: top-wall velocity V_w and its acceleration dV_w/dt.
WALL_VELOCITY, WALL_ACCELERATION = 0, 1

#: Everything constant during a run (ints, floats, bools; passed to the compiled loop as one);
#: ``lz`` is the periodic length along z (3D; unused in 2D).
Config = namedtuple("Config", [
    "dimension", "n_fluid", "n_bottom", "lx", "lz", "y_lo", "y_hi", "cutoff", "skin", "h_sl",
    "rho0", "c", "p_b",
    "mass", "g_x", "stress_control", "stress", "area", "wall_mass",
    "eta_s", "phi", "phi_m", "phi_0", "sigma_star", "beta", "K_f", "alpha",
    "courant", "viscous_number", "force_number", "diffusion_number",
    "shifting", "shifting_coefficient", "gradient_correction", "max_density_error",
    "max_mach", "max_viscosity_ratio"])

#: Per-particle work arrays of one rate evaluation (fluid rows first; walls fill the rest).
Buffers = namedtuple("Buffers", [
    "pressure", "eta", "v_visc", "drho", "acc", "acc_top", "grad", "grad_c", "lap_f", "grad_f",
    "gdot", "sigma", "df"])

#: Neighbour-list arrays: CSR start/neighbours, sort scratch, positions at the build, a flag
#: forcing the next build, and the count of builds so far.
ListArrays = namedtuple("ListArrays", ["start", "neighbours", "cell_of", "order", "reference",
                                       "force_rebuild", "builds"])


@njit(**JIT_OPTIONS)
def refresh_list(cfg, positions, lists):
    """Rebuild the list when needed (or forced); returns STEP_OK or LIST_OVERFLOW."""
    if cfg.dimension == 3:
        if lists.force_rebuild[0] == 0 and not needs_rebuild_3d(
                positions, lists.reference, cfg.lx, cfg.lz, cfg.skin):
            return STEP_OK
        code, _ = build_list_3d(positions, cfg.lx, cfg.lz, cfg.y_lo, cfg.y_hi, cfg.cutoff,
                                lists.start, lists.neighbours, lists.cell_of, lists.order)
    else:
        if lists.force_rebuild[0] == 0 and not needs_rebuild(positions, lists.reference,
                                                              cfg.lx, cfg.skin):
            return STEP_OK
        code, _ = build_list(positions, cfg.lx, cfg.y_lo, cfg.y_hi, cfg.cutoff, lists.start,
                             lists.neighbours, lists.cell_of, lists.order)
    if code != OK:
        lists.force_rebuild[0] = 1
        return LIST_OVERFLOW
    lists.reference[:, :] = positions
    lists.force_rebuild[0] = 0
    lists.builds[0] += 1
    return STEP_OK


@njit(**JIT_OPTIONS)
def particle_state(cfg, velocity, rho, f, buf):
    """Viscosity η_i = η(f_i), Tait pressure p_i and the velocity the viscous terms see, for
    every fluid particle; returns JAMMED at the first particle with φ ≥ φ_J(f_i)."""
    for i in range(cfg.n_fluid):
        eta = suspension_viscosity(f[i], cfg.eta_s, cfg.phi, cfg.phi_m, cfg.phi_0)
        if eta < 0.0:
            return JAMMED
        buf.eta[i] = eta
        buf.pressure[i] = tait_pressure(rho[i], cfg.rho0, cfg.c, cfg.p_b)
        for a in range(cfg.dimension):
            buf.v_visc[i, a] = velocity[i, a]
    return STEP_OK


@njit(**JIT_OPTIONS)
def pair_passes(cfg, positions, velocity, rho, f, wall, buf, lists):
    """The wall pass then the fluid pass (2D or 3D) on the current list."""
    nf = cfg.n_fluid
    v_wall = wall[WALL_VELOCITY]
    if cfg.dimension == 3:
        wall_pass_3d(nf, cfg.n_bottom, positions, velocity, rho, buf.pressure, buf.v_visc,
                     lists.start, lists.neighbours, cfg.lx, cfg.lz, cfg.h_sl, cfg.rho0, cfg.c,
                     cfg.p_b, cfg.g_x, v_wall, wall[WALL_ACCELERATION])
        fluid_pass_3d(nf, cfg.n_bottom, positions, velocity, buf.v_visc, rho, buf.pressure,
                      buf.eta, f, cfg.mass, lists.start, lists.neighbours, cfg.lx, cfg.lz,
                      cfg.h_sl, cfg.g_x, v_wall, cfg.gradient_correction, buf.drho, buf.acc,
                      buf.acc_top, buf.grad, buf.grad_c, buf.lap_f, buf.grad_f)
    else:
        wall_pass(nf, cfg.n_bottom, positions, velocity, rho, buf.pressure, buf.v_visc,
                  lists.start, lists.neighbours, cfg.lx, cfg.h_sl, cfg.rho0, cfg.c, cfg.p_b,
                  cfg.g_x, v_wall, wall[WALL_ACCELERATION])
        fluid_pass(nf, cfg.n_bottom, positions, velocity, buf.v_visc, rho, buf.pressure,
                   buf.eta, f, cfg.mass, lists.start, lists.neighbours, cfg.lx, cfg.h_sl,
                   cfg.g_x, v_wall, cfg.gradient_correction, buf.drho, buf.acc, buf.acc_top,
                   buf.grad, buf.grad_c, buf.lap_f, buf.grad_f)


@njit(**JIT_OPTIONS)
def finish_rates(cfg, f, wall, buf):
    """γ̇_i, σ_i and Df_i/Dt of every fluid particle, and the wall's acceleration from the drag
    the fluid pass gathered (module docstring, items 4 and 5)."""
    drag = 0.0
    for i in range(cfg.n_fluid):
        g = buf.grad[i]
        gdot = shear_rate_3d(g) if cfg.dimension == 3 else shear_rate_2d(g[0], g[1], g[2], g[3])
        buf.gdot[i] = gdot
        buf.sigma[i] = buf.eta[i] * gdot
        buf.df[i] = microstructure_rate(f[i], gdot, buf.eta[i], cfg.K_f, cfg.sigma_star,
                                        cfg.beta, cfg.alpha, buf.lap_f[i])
        drag += cfg.mass * buf.acc_top[i]
    if cfg.stress_control:
        wall[WALL_ACCELERATION] = (cfg.stress * cfg.area - drag) / cfg.wall_mass
    else:
        wall[WALL_ACCELERATION] = 0.0


@njit(**JIT_OPTIONS)
def evaluate(cfg, positions, velocity, rho, f, wall, buf, lists):
    """Rates at the given state into ``buf`` and wall[WALL_ACCELERATION]; returns a code."""
    code = refresh_list(cfg, positions, lists)
    if code != STEP_OK:
        return code
    code = particle_state(cfg, velocity, rho, f, buf)
    if code != STEP_OK:
        return code
    pair_passes(cfg, positions, velocity, rho, f, wall, buf, lists)
    finish_rates(cfg, f, wall, buf)
    return STEP_OK


@njit(inline="always", **JIT_OPTIONS)
def _norm2(vectors, i, d):
    """|vectors[i]|² over the first d components."""
    s = vectors[i, 0] ** 2 + vectors[i, 1] ** 2
    if d == 3:
        s += vectors[i, 2] ** 2
    return s


@njit(**JIT_OPTIONS)
def time_step(cfg, buf):
    """δt = min(C_c h/c, C_ν ρ0 h²/η_max, C_a sqrt(h/a_max), C_α h²/α), h = h_sl (Morris 1997)."""
    h = cfg.h_sl
    eta_max = 0.0
    a2_max = 0.0
    for i in range(cfg.n_fluid):
        eta_max = max(eta_max, buf.eta[i])
        a2_max = max(a2_max, _norm2(buf.acc, i, cfg.dimension))
    dt = cfg.courant * h / cfg.c
    if eta_max > 0.0:
        dt = min(dt, cfg.viscous_number * cfg.rho0 * h * h / eta_max)
    if a2_max > 0.0:
        dt = min(dt, cfg.force_number * math.sqrt(h / math.sqrt(a2_max)))
    if cfg.alpha > 0.0:
        dt = min(dt, cfg.diffusion_number * h * h / cfg.alpha)
    return dt


@njit(**JIT_OPTIONS)
def _move_top_wall(cfg, positions, source, dx):
    for w in range(cfg.n_fluid + cfg.n_bottom, positions.shape[0]):
        positions[w, 0] = source[w, 0] + dx
        for a in range(1, cfg.dimension):
            positions[w, a] = source[w, a]


@njit(**JIT_OPTIONS)
def _check(cfg, positions, velocity, rho, f, wall, eta):
    """Blow-up checks after a step: non-finite values, density error, Mach number, and a
    viscosity beyond max_viscosity_ratio η_s (near jamming γ̇ → 0 and δt_ν → 0, so f creeps
    towards φ_J without reaching it; the run would grind instead of failing)."""
    v2_max = 0.0
    err = 0.0
    for i in range(cfg.n_fluid):
        if eta[i] > cfg.max_viscosity_ratio * cfg.eta_s:
            return NEAR_JAMMING
        s = positions[i, 0] + positions[i, 1] + velocity[i, 0] + velocity[i, 1] + rho[i] + f[i]
        if cfg.dimension == 3:
            s += positions[i, 2] + velocity[i, 2]
        if not math.isfinite(s):
            return NONFINITE
        v2_max = max(v2_max, _norm2(velocity, i, cfg.dimension))
        err = max(err, abs(rho[i] / cfg.rho0 - 1.0))
    if not math.isfinite(wall[WALL_VELOCITY]):
        return NONFINITE
    if err > cfg.max_density_error:
        return DENSITY_ERROR
    if math.sqrt(v2_max) > cfg.max_mach * cfg.c:
        return MACH_LIMIT
    return STEP_OK


@njit(**JIT_OPTIONS)
def advance_steps(cfg, n_steps, t_stop, positions, velocity, rho, f, wall, half_positions,
                  half_velocity, half_rho, half_f, buf, lists, clock):
    """Advance up to ``n_steps`` predictor–corrector steps, stopping before any step that would
    start at time >= ``t_stop``; returns (code, steps done).

    ``clock`` = [time, last δt] is updated in place. On a nonzero code the state is that after
    the last completed step (a list overflow leaves the current step undone).
    """
    nf = cfg.n_fluid
    n = positions.shape[0]
    d = cfg.dimension
    for step in range(n_steps):
        if clock[0] >= t_stop:
            return STEP_OK, step
        code = evaluate(cfg, positions, velocity, rho, f, wall, buf, lists)
        if code != STEP_OK:
            return code, step
        dt = time_step(cfg, buf)
        half = 0.5 * dt
        v_wall0 = wall[WALL_VELOCITY]
        a_wall0 = wall[WALL_ACCELERATION]
        # Predictor: half step with the rates at n.
        for i in range(nf):
            for a in range(d):
                half_positions[i, a] = positions[i, a] + half * velocity[i, a]
                half_velocity[i, a] = velocity[i, a] + half * buf.acc[i, a]
            half_rho[i] = rho[i] + half * buf.drho[i]
            half_f[i] = min(max(f[i] + half * buf.df[i], 0.0), 1.0)
        for w in range(nf, n):
            for a in range(d):
                half_positions[w, a] = positions[w, a]
            half_rho[w] = rho[w]
        _move_top_wall(cfg, half_positions, positions, half * v_wall0)
        wall[WALL_VELOCITY] = v_wall0 + half * a_wall0
        # Corrector: rates at n + ½, then φ^(n+1) = φ^n + δt Dφ^(n+½).
        code = evaluate(cfg, half_positions, half_velocity, half_rho, half_f, wall, buf, lists)
        if code != STEP_OK:
            wall[WALL_VELOCITY] = v_wall0
            wall[WALL_ACCELERATION] = a_wall0
            return code, step
        v_wall_half = wall[WALL_VELOCITY]
        for i in range(nf):
            for a in range(d):
                positions[i, a] += dt * half_velocity[i, a]
                velocity[i, a] += dt * buf.acc[i, a]
            rho[i] += dt * buf.drho[i]
            f[i] = min(max(f[i] + dt * buf.df[i], 0.0), 1.0)
        _move_top_wall(cfg, positions, positions, dt * v_wall_half)
        wall[WALL_VELOCITY] = v_wall0 + dt * wall[WALL_ACCELERATION]
        if cfg.shifting:
            _shift(cfg, positions, velocity, f, buf, dt)
        for i in range(n):
            positions[i, 0] -= cfg.lx * math.floor(positions[i, 0] / cfg.lx)
        clock[0] += dt
        clock[1] = dt
        code = _check(cfg, positions, velocity, rho, f, wall, buf.eta)
        if code != STEP_OK:
            return code, step + 1
    return STEP_OK, n_steps


@njit(**JIT_OPTIONS)
def _shift(cfg, positions, velocity, f, buf, dt):
    """Lind et al. 2012 shifting δx = −A h |v| δt ∇C, clipped at 0.1 h, with Taylor corrections
    (δx_z = 0 in 2D)."""
    h = cfg.h_sl
    cap = 0.1 * h
    d = cfg.dimension
    for i in range(cfg.n_fluid):
        speed = math.sqrt(_norm2(velocity, i, d))
        D = cfg.shifting_coefficient * h * speed * dt
        sx = -D * buf.grad_c[i, 0]
        sy = -D * buf.grad_c[i, 1]
        sz = -D * buf.grad_c[i, 2] if d == 3 else 0.0
        size = math.sqrt(sx * sx + sy * sy + sz * sz)
        if size > cap:
            sx *= cap / size
            sy *= cap / size
            sz *= cap / size
        g = buf.grad[i]
        positions[i, 0] += sx
        positions[i, 1] += sy
        gf = buf.grad_f[i]
        if d == 3:
            positions[i, 2] += sz
            for a in range(3):
                velocity[i, a] += g[3 * a] * sx + g[3 * a + 1] * sy + g[3 * a + 2] * sz
            f[i] = min(max(f[i] + gf[0] * sx + gf[1] * sy + gf[2] * sz, 0.0), 1.0)
        else:
            velocity[i, 0] += g[0] * sx + g[1] * sy
            velocity[i, 1] += g[2] * sx + g[3] * sy
            f[i] = min(max(f[i] + gf[0] * sx + gf[1] * sy, 0.0), 1.0)


def allocate_buffers(n_particles: int, dimension: int = 2) -> Buffers:
    """Zeroed work arrays for ``n_particles`` (fluid and wall) in ``dimension`` d: vectors
    (N, d), the velocity gradient (N, d²) row by row."""
    n, d = int(n_particles), int(dimension)
    z1 = lambda: np.zeros(n)  # noqa: E731
    z2 = lambda k=d: np.zeros((n, k))  # noqa: E731
    return Buffers(pressure=z1(), eta=z1(), v_visc=z2(), drho=z1(), acc=z2(), acc_top=z1(),
                   grad=z2(d * d), grad_c=z2(), lap_f=z1(), grad_f=z2(), gdot=z1(), sigma=z1(),
                   df=z1())


def allocate_lists(n_particles: int, capacity: int, dimension: int = 2) -> ListArrays:
    """Neighbour-list arrays with ``capacity`` pair slots (a rebuild is forced at first use)."""
    n = int(n_particles)
    return ListArrays(start=np.zeros(n + 1, dtype=np.int64),
                      neighbours=np.zeros(int(capacity), dtype=np.int64),
                      cell_of=np.zeros(n, dtype=np.int64), order=np.zeros(n, dtype=np.int64),
                      reference=np.zeros((n, int(dimension))),
                      force_rebuild=np.ones(1, dtype=np.int64),
                      builds=np.zeros(1, dtype=np.int64))
