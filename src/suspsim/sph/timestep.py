"""Automatic sound speed and stable time step (SPEC §2.2, §2.6).

Sound speed [choice, SPEC §2.2 and the probe]: the larger of the viscous criterion and the Mach
criterion,

    c = max( sqrt(σ_s/(ρ Wi)), v_s/MACH_TARGET ),

with Wi = ``numerics.wi_target`` (1e−3: the probe found the Morris minimum leaves ≈ +4 % stress
through the pressure and 1e−4 turns the lattice plastic), σ_s the stress scale and v_s the
velocity scale relative to the imposed flow: Couette σ_s = μ(γ̇) γ̇, v_s = γ̇ L_y/2 from rest
(the initial jump across the sheared faces) or γ̇ h from the linear profile (the velocity
difference across a neighbourhood); Poiseuille σ_s = ρ g L_y/4 (the wall stress of each half)
and v_s the reference centre-line velocity (``reference.poiseuille``).

Time step [SPEC §2.6; coefficients measured by ``tests/unit/sph/test_simulation.py``]:

    δt = min( C_ν ρ h²/μ_max, C_c h/(c + v_s), C_a sqrt(h/g) ),

C_ν = ``numerics.dt_viscous_coefficient`` (0.05; the probe found 0.09 stable), C_c =
:data:`ACOUSTIC_COEFFICIENT`, C_a = :data:`FORCE_COEFFICIENT`, h the support radius. μ_max is
the largest viscosity the run can meet [choice]: μ(0) where γ̇ can vanish (a start from rest,
the Poiseuille centre line), μ(γ̇/2) in Couette from the linear profile (local rates stay near
γ̇; halving it covers the lattice's fluctuations).

Symbols: c sound speed [h τ^−1]; ρ nominal density [m h^−d]; μ viscosity; γ̇ imposed rate;
g body acceleration [h τ^−2]; L_y box height [h]; h support radius (1 in scene units).
"""
from __future__ import annotations

import functools
import math

from suspsim.reference.poiseuille import poiseuille_profile
from suspsim.rheology.laws import make_law
from suspsim.scene import Scene

#: Target Mach number of the velocity scale (Morris et al. 1997) [choice].
MACH_TARGET = 0.1
#: C_c in δt ≤ C_c h/(c + v_s) for the Lucy kernel (support h), measured stable.
ACOUSTIC_COEFFICIENT = 0.25
#: C_a in δt ≤ C_a sqrt(h/g) (Morris et al. 1997) [choice].
FORCE_COEFFICIENT = 0.25
#: Support radius in scene units.
SUPPORT = 1.0


def stress_scale(scene: Scene) -> float:
    """σ_s: μ(γ̇)γ̇ for Couette, the wall stress ρ g L_y/4 for split-force Poiseuille."""
    if scene.flow.type == "couette":
        rate = scene.flow.shear_rate
        return float(scene.fluid.law.viscosity(rate)) * rate
    return scene.density * scene.flow.body_force * scene.box[1] / 4.0


def velocity_scale(scene: Scene) -> float:
    """v_s relative to the imposed flow (module docstring)."""
    if scene.flow.type == "couette":
        rate = scene.flow.shear_rate
        return rate * (0.5 * scene.box[1] if scene.run.start == "rest" else SUPPORT)
    law = scene.fluid.law
    return _centre_velocity(law.name, tuple(sorted(law.params.items())),
                            scene.density * scene.flow.body_force, 0.5 * scene.box[1])


@functools.lru_cache(maxsize=256)
def _centre_velocity(law: str, params: tuple, force_density: float, half: float) -> float:
    """Centre-line velocity [h τ^-1] of the half-channel ``half`` [h] (cached: the quadrature
    is slow and the error model's picker asks for it once per candidate time step)."""
    return float(poiseuille_profile(make_law(law, dict(params)), force_density, half, 0.5 * half))


def auto_sound_speed(scene: Scene) -> float:
    """c = max(sqrt(σ_s/(ρ Wi)), v_s/MACH_TARGET) (module docstring)."""
    viscous = math.sqrt(stress_scale(scene) / (scene.density * scene.numerics.wi_target))
    return max(viscous, velocity_scale(scene) / MACH_TARGET)


def max_viscosity(scene: Scene) -> float:
    """μ_max (module docstring): μ(0), or μ(γ̇/2) for Couette from the linear profile."""
    law = scene.fluid.law
    if scene.flow.type == "couette" and scene.run.start == "linear":
        return float(law.viscosity(0.5 * scene.flow.shear_rate))
    return float(law.viscosity(0.0))


def stable_time_step(scene: Scene, sound_speed: float, *,
                     acoustic_coefficient: float = ACOUSTIC_COEFFICIENT) -> float:
    """δt = min(C_ν ρ h²/μ_max, C_c h/(c + v_s), C_a sqrt(h/g)) (module docstring)."""
    limits = [scene.numerics.dt_viscous_coefficient * scene.density * SUPPORT ** 2
              / max_viscosity(scene),
              acoustic_coefficient * SUPPORT / (sound_speed + velocity_scale(scene))]
    if scene.flow.body_force > 0:
        limits.append(FORCE_COEFFICIENT * math.sqrt(SUPPORT / scene.flow.body_force))
    return min(limits)
