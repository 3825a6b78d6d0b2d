"""Pair passes of the DST solver: the wall pass and the fluid pass (SPEC §5.1, §5.3).

Particles are ordered fluid [0, n_f), bottom wall [n_f, n_f + n_w), top wall [n_f + n_w, N).
Both passes loop over the particles they write (``prange``, race-free over a full list).

1. :func:`wall_pass` (Adami, Hu & Adams, J. Comput. Phys. 231, 7057 (2012), Eqs. 22–23, 27):
   for each dummy particle w, Shepard sums over its fluid neighbours f,

       p_w = Σ_f [p_f + ρ_f (g − a_w)·x_wf] W_wf / Σ_f W_wf,    ρ_w = EOS⁻¹(p_w),
       ṽ_w = Σ_f v_f W_wf / Σ_f W_wf,    v_w,visc = 2 v_w,prescribed − ṽ_w   (no slip).

   A dummy particle without fluid neighbours (outer layers) gets p_b, ρ0 and the wall velocity.
2. :func:`fluid_pass`: for each fluid particle i, over all neighbours j (fluid and wall):
   continuity dρ_i/dt (walls with their prescribed velocity), momentum (pressure + Morris
   viscous with the no-slip velocity v_w,visc; a wall-fluid pair uses η_i for the wall
   [choice]), the velocity gradient G_i (walls with v_w,visc [choice: a linear extrapolation
   across the wall, so γ̇ is right next to it]), the colour gradient ∇C_i = Σ_j V_j ∇_iW_ij
   (shifting), and, over fluid neighbours only (zero flux through the walls [choice]),
   ∇²f_i and ∇f_i. The viscous acceleration that the top-wall particles exert on i is kept
   apart (its reaction drives the stress-controlled wall, SPEC §5.4).

Symbols as in :mod:`~suspsim.dst.terms`; W, F the quintic spline of the run's dimension with
smoothing length h_sl (support 3 h_sl), g the body acceleration along x, a_w the wall
acceleration along x. Each pass has a 2D and a 3D form (``*_3d``: z periodic, a third velocity
component, the 3 × 3 gradient and moment matrix); the equations are the same, and the 2D pair
loop carries no z terms. The dimension enters only through the kernel's normalisation:
7/(478π h_sl²) in 2D and 1/(120π h_sl³) in 3D (:mod:`suspsim.sph.kernels`; the exact integral,
where Morris et al. 1997 print 3/(359π), 0.3 % larger).
"""
from __future__ import annotations

import math

from numba import njit, prange

from suspsim.dst.neighbours import pair_vector, pair_vector_3d
from suspsim.dst.terms import (continuity_pair, continuity_pair_3d, laplacian_pair,
                               morris_viscous_pair, pressure_pair, tait_density)
from suspsim.sph import JIT_OPTIONS
from suspsim.sph.kernels import quintic_f_2d, quintic_f_3d, quintic_w_2d, quintic_w_3d

_PARALLEL = dict(JIT_OPTIONS, parallel=True)


@njit(**JIT_OPTIONS)
def moment_corrected(gxx, gxy, gyx, gyy, mxx, mxy, myy):
    """G M2⁻¹ with M2 = Σ_j V_j F x_ij x_ijᵀ (symmetric; ≈ I for a full, regular support).

    G_ab = Σ_j V_j F (v_i − v_j)_a (x_ij)_b = A_ac M2_cb for a linear field v = A x, so G M2⁻¹
    is exact for linear fields on any arrangement (Bonet & Lok 1999). Falls back to G when
    M2 is singular (a particle without neighbours).
    """
    det = mxx * myy - mxy * mxy
    if not det > 0.0:
        return gxx, gxy, gyx, gyy
    ixx = myy / det
    iyy = mxx / det
    ixy = -mxy / det
    return (gxx * ixx + gxy * ixy, gxx * ixy + gxy * iyy,
            gyx * ixx + gyy * ixy, gyx * ixy + gyy * iyy)


@njit(**_PARALLEL)
def wall_pass(n_fluid, n_bottom, positions, velocity, rho, pressure, v_visc, start, neighbours,
              lx, h_sl, rho0, c, p_b, g_x, wall_velocity, wall_acceleration):
    """Fill ``pressure``, ``rho`` and ``v_visc`` of the dummy particles (Adami et al. 2012).

    The bottom wall is at rest, the top wall moves with ``wall_velocity`` along x and
    accelerates with ``wall_acceleration``.
    """
    n = positions.shape[0]
    support2 = 9.0 * h_sl * h_sl
    for w in prange(n_fluid, n):
        vwx = 0.0 if w < n_fluid + n_bottom else wall_velocity
        awx = 0.0 if w < n_fluid + n_bottom else wall_acceleration
        sw = 0.0
        sp = 0.0
        svx = 0.0
        svy = 0.0
        xw = positions[w, 0]
        yw = positions[w, 1]
        for k in range(start[w], start[w + 1]):
            j = neighbours[k]
            if j >= n_fluid:
                continue
            dx, dy = pair_vector(xw, yw, positions[j, 0], positions[j, 1], lx)
            r2 = dx * dx + dy * dy
            if r2 >= support2:
                continue
            wgt = quintic_w_2d(math.sqrt(r2), h_sl)
            sw += wgt
            sp += (pressure[j] + rho[j] * (g_x - awx) * dx) * wgt
            svx += velocity[j, 0] * wgt
            svy += velocity[j, 1] * wgt
        if sw > 0.0:
            p = sp / sw
            pressure[w] = p
            rho[w] = tait_density(p, rho0, c, p_b)
            v_visc[w, 0] = 2.0 * vwx - svx / sw
            v_visc[w, 1] = -svy / sw
        else:
            pressure[w] = p_b
            rho[w] = rho0
            v_visc[w, 0] = vwx
            v_visc[w, 1] = 0.0


@njit(**_PARALLEL)
def fluid_pass(n_fluid, n_bottom, positions, velocity, v_visc, rho, pressure, eta, f, mass,
               start, neighbours, lx, h_sl, g_x, wall_velocity, corrected, drho, acc, acc_top,
               grad, grad_c, lap_f, grad_f):
    """Rates and gradients of every fluid particle i (see the module docstring).

    Writes dρ/dt (``drho``), dv/dt (``acc``, body force included), the x-acceleration from the
    top wall's viscous pull (``acc_top``), G_i = Σ_j V_j (v_j − v_i) ⊗ ∇_iW_ij (``grad`` as
    G_xx, G_xy, G_yx, G_yy with G_ab ≈ ∂v_a/∂x_b), ∇C_i (``grad_c``), ∇²f_i (``lap_f``) and
    ∇f_i (``grad_f``). V_j = m/ρ_j. With ``corrected``, G_i ← G_i M2_i⁻¹ (see
    :func:`moment_corrected`).
    """
    support2 = 9.0 * h_sl * h_sl
    top = n_fluid + n_bottom
    for i in prange(n_fluid):
        xi = positions[i, 0]
        yi = positions[i, 1]
        vxi = velocity[i, 0]
        vyi = velocity[i, 1]
        rho_i = rho[i]
        p_i = pressure[i]
        eta_i = eta[i]
        f_i = f[i]
        d_rho = 0.0
        ax = g_x
        ay = 0.0
        a_top = 0.0
        gxx = 0.0
        gxy = 0.0
        gyx = 0.0
        gyy = 0.0
        cx = 0.0
        cy = 0.0
        mxx = 0.0
        mxy = 0.0
        myy = 0.0
        lap = 0.0
        fx = 0.0
        fy = 0.0
        for k in range(start[i], start[i + 1]):
            j = neighbours[k]
            dx, dy = pair_vector(xi, yi, positions[j, 0], positions[j, 1], lx)
            r2 = dx * dx + dy * dy
            if r2 >= support2:
                continue
            F = quintic_f_2d(math.sqrt(r2), h_sl)
            rho_j = rho[j]
            vol_j = mass / rho_j
            fluid_j = j < n_fluid
            if fluid_j:
                cvx = vxi - velocity[j, 0]
                cvy = vyi - velocity[j, 1]
                eta_j = eta[j]
            else:
                cvx = vxi - (0.0 if j < top else wall_velocity)
                cvy = vyi
                eta_j = eta_i
            d_rho += continuity_pair(mass, cvx, cvy, dx, dy, F)
            s = pressure_pair(mass, p_i, rho_i, pressure[j], rho_j, F)
            ax += s * dx
            ay += s * dy
            uvx = vxi - v_visc[j, 0]
            uvy = vyi - v_visc[j, 1]
            sv = morris_viscous_pair(mass, eta_i, eta_j, rho_i, rho_j, r2, F, h_sl)
            ax += sv * uvx
            ay += sv * uvy
            if j >= top:
                a_top += sv * uvx
            # G_ab = Σ V_j (v_j − v_i)_a (∇_iW)_b, ∇_iW = −x_ij F, v_j − v_i = −uv.
            wf = vol_j * F
            gxx += wf * uvx * dx
            gxy += wf * uvx * dy
            gyx += wf * uvy * dx
            gyy += wf * uvy * dy
            cx -= wf * dx
            cy -= wf * dy
            mxx += wf * dx * dx
            mxy += wf * dx * dy
            myy += wf * dy * dy
            if fluid_j:
                df = f[j] - f_i
                lap += laplacian_pair(vol_j, f_i, f[j], r2, F, h_sl)
                fx -= wf * df * dx
                fy -= wf * df * dy
        drho[i] = d_rho
        acc[i, 0] = ax
        acc[i, 1] = ay
        acc_top[i] = a_top
        if corrected:
            gxx, gxy, gyx, gyy = moment_corrected(gxx, gxy, gyx, gyy, mxx, mxy, myy)
        grad[i, 0] = gxx
        grad[i, 1] = gxy
        grad[i, 2] = gyx
        grad[i, 3] = gyy
        grad_c[i, 0] = cx
        grad_c[i, 1] = cy
        lap_f[i] = lap
        grad_f[i, 0] = fx
        grad_f[i, 1] = fy


@njit(**JIT_OPTIONS)
def moment_corrected_3d(gxx, gxy, gxz, gyx, gyy, gyz, gzx, gzy, gzz, mxx, mxy, mxz, myy, myz,
                        mzz):
    """G M2⁻¹ in 3D (see :func:`moment_corrected`), M2⁻¹ by cofactors; G when M2 is singular.

    Returns the 9 components G_ab row by row (a = x, y, z).
    """
    c00 = myy * mzz - myz * myz
    c01 = mxz * myz - mxy * mzz
    c02 = mxy * myz - mxz * myy
    det = mxx * c00 + mxy * c01 + mxz * c02
    if not det > 0.0:
        return gxx, gxy, gxz, gyx, gyy, gyz, gzx, gzy, gzz
    i00 = c00 / det
    i01 = c01 / det
    i02 = c02 / det
    i11 = (mxx * mzz - mxz * mxz) / det
    i12 = (mxy * mxz - mxx * myz) / det
    i22 = (mxx * myy - mxy * mxy) / det
    return (gxx * i00 + gxy * i01 + gxz * i02, gxx * i01 + gxy * i11 + gxz * i12,
            gxx * i02 + gxy * i12 + gxz * i22,
            gyx * i00 + gyy * i01 + gyz * i02, gyx * i01 + gyy * i11 + gyz * i12,
            gyx * i02 + gyy * i12 + gyz * i22,
            gzx * i00 + gzy * i01 + gzz * i02, gzx * i01 + gzy * i11 + gzz * i12,
            gzx * i02 + gzy * i12 + gzz * i22)


@njit(**_PARALLEL)
def wall_pass_3d(n_fluid, n_bottom, positions, velocity, rho, pressure, v_visc, start,
                 neighbours, lx, lz, h_sl, rho0, c, p_b, g_x, wall_velocity, wall_acceleration):
    """:func:`wall_pass` in 3D (x and z periodic over L_x, L_z)."""
    n = positions.shape[0]
    support2 = 9.0 * h_sl * h_sl
    for w in prange(n_fluid, n):
        vwx = 0.0 if w < n_fluid + n_bottom else wall_velocity
        awx = 0.0 if w < n_fluid + n_bottom else wall_acceleration
        sw = 0.0
        sp = 0.0
        svx = 0.0
        svy = 0.0
        svz = 0.0
        xw = positions[w, 0]
        yw = positions[w, 1]
        zw = positions[w, 2]
        for k in range(start[w], start[w + 1]):
            j = neighbours[k]
            if j >= n_fluid:
                continue
            dx, dy, dz = pair_vector_3d(xw, yw, zw, positions[j, 0], positions[j, 1],
                                        positions[j, 2], lx, lz)
            r2 = dx * dx + dy * dy + dz * dz
            if r2 >= support2:
                continue
            wgt = quintic_w_3d(math.sqrt(r2), h_sl)
            sw += wgt
            sp += (pressure[j] + rho[j] * (g_x - awx) * dx) * wgt
            svx += velocity[j, 0] * wgt
            svy += velocity[j, 1] * wgt
            svz += velocity[j, 2] * wgt
        if sw > 0.0:
            p = sp / sw
            pressure[w] = p
            rho[w] = tait_density(p, rho0, c, p_b)
            v_visc[w, 0] = 2.0 * vwx - svx / sw
            v_visc[w, 1] = -svy / sw
            v_visc[w, 2] = -svz / sw
        else:
            pressure[w] = p_b
            rho[w] = rho0
            v_visc[w, 0] = vwx
            v_visc[w, 1] = 0.0
            v_visc[w, 2] = 0.0


@njit(**_PARALLEL)
def fluid_pass_3d(n_fluid, n_bottom, positions, velocity, v_visc, rho, pressure, eta, f, mass,
                  start, neighbours, lx, lz, h_sl, g_x, wall_velocity, corrected, drho, acc,
                  acc_top, grad, grad_c, lap_f, grad_f):
    """:func:`fluid_pass` in 3D; ``grad`` holds the 9 components G_ab at 3a + b."""
    support2 = 9.0 * h_sl * h_sl
    top = n_fluid + n_bottom
    for i in prange(n_fluid):
        xi = positions[i, 0]
        yi = positions[i, 1]
        zi = positions[i, 2]
        vxi = velocity[i, 0]
        vyi = velocity[i, 1]
        vzi = velocity[i, 2]
        rho_i = rho[i]
        p_i = pressure[i]
        eta_i = eta[i]
        f_i = f[i]
        d_rho = 0.0
        ax = g_x
        ay = 0.0
        az = 0.0
        a_top = 0.0
        gxx = gxy = gxz = gyx = gyy = gyz = gzx = gzy = gzz = 0.0
        cx = cy = cz = 0.0
        mxx = mxy = mxz = myy = myz = mzz = 0.0
        lap = 0.0
        fx = fy = fz = 0.0
        for k in range(start[i], start[i + 1]):
            j = neighbours[k]
            dx, dy, dz = pair_vector_3d(xi, yi, zi, positions[j, 0], positions[j, 1],
                                        positions[j, 2], lx, lz)
            r2 = dx * dx + dy * dy + dz * dz
            if r2 >= support2:
                continue
            F = quintic_f_3d(math.sqrt(r2), h_sl)
            rho_j = rho[j]
            vol_j = mass / rho_j
            fluid_j = j < n_fluid
            if fluid_j:
                cvx = vxi - velocity[j, 0]
                cvy = vyi - velocity[j, 1]
                cvz = vzi - velocity[j, 2]
                eta_j = eta[j]
            else:
                cvx = vxi - (0.0 if j < top else wall_velocity)
                cvy = vyi
                cvz = vzi
                eta_j = eta_i
            d_rho += continuity_pair_3d(mass, cvx, cvy, cvz, dx, dy, dz, F)
            s = pressure_pair(mass, p_i, rho_i, pressure[j], rho_j, F)
            ax += s * dx
            ay += s * dy
            az += s * dz
            uvx = vxi - v_visc[j, 0]
            uvy = vyi - v_visc[j, 1]
            uvz = vzi - v_visc[j, 2]
            sv = morris_viscous_pair(mass, eta_i, eta_j, rho_i, rho_j, r2, F, h_sl)
            ax += sv * uvx
            ay += sv * uvy
            az += sv * uvz
            if j >= top:
                a_top += sv * uvx
            wf = vol_j * F
            gxx += wf * uvx * dx
            gxy += wf * uvx * dy
            gxz += wf * uvx * dz
            gyx += wf * uvy * dx
            gyy += wf * uvy * dy
            gyz += wf * uvy * dz
            gzx += wf * uvz * dx
            gzy += wf * uvz * dy
            gzz += wf * uvz * dz
            cx -= wf * dx
            cy -= wf * dy
            cz -= wf * dz
            mxx += wf * dx * dx
            mxy += wf * dx * dy
            mxz += wf * dx * dz
            myy += wf * dy * dy
            myz += wf * dy * dz
            mzz += wf * dz * dz
            if fluid_j:
                df = f[j] - f_i
                lap += laplacian_pair(vol_j, f_i, f[j], r2, F, h_sl)
                fx -= wf * df * dx
                fy -= wf * df * dy
                fz -= wf * df * dz
        drho[i] = d_rho
        acc[i, 0] = ax
        acc[i, 1] = ay
        acc[i, 2] = az
        acc_top[i] = a_top
        if corrected:
            gxx, gxy, gxz, gyx, gyy, gyz, gzx, gzy, gzz = moment_corrected_3d(
                gxx, gxy, gxz, gyx, gyy, gyz, gzx, gzy, gzz, mxx, mxy, mxz, myy, myz, mzz)
        grad[i, 0] = gxx
        grad[i, 1] = gxy
        grad[i, 2] = gxz
        grad[i, 3] = gyx
        grad[i, 4] = gyy
        grad[i, 5] = gyz
        grad[i, 6] = gzx
        grad[i, 7] = gzy
        grad[i, 8] = gzz
        grad_c[i, 0] = cx
        grad_c[i, 1] = cy
        grad_c[i, 2] = cz
        lap_f[i] = lap
        grad_f[i, 0] = fx
        grad_f[i, 1] = fy
        grad_f[i, 2] = fz
