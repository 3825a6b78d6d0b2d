"""Automatic sound speed and stable time step (SPEC §2.2, §2.6).

Sound speed [choice, SPEC §2.2 and the probe]: the larger of the viscous criterion and the Mach
criterion,

    c = max( sqrt(σ_s/(ρ Wi)) f(φ), v_s/MACH_TARGET ),

with Wi = ``numerics.wi_target`` (1e−3: the probe found the Morris minimum leaves ≈ +4 % stress
through the pressure and 1e−4 turns the lattice plastic), σ_s the stress scale and v_s the
velocity scale relative to the imposed flow, and f(φ) the crowding of rigid bodies at volume
fraction φ (1 without). A dense suspension squeezes fluid through gaps whose width falls with
φ, and the stress there grows as a/ḡ (ḡ the mean surface gap): above
:data:`CROWDING_REFERENCE_PHI`, f = :func:`crowding_factor` = sqrt(ḡ(φ_ref)/ḡ(φ)),
ḡ/a = (φ_m/φ)^(1/3) − 1 with φ_m = :data:`CLOSE_PACKING` [choice: meant to hold the fluid's
density error in the gaps near its level at φ_ref, where the fluid's own c ran every packing;
measured 0.15–0.28 at φ = 0.4–0.5, README]. The scales: Couette σ_s = μ(γ̇) γ̇, v_s = γ̇ L_y/2
from rest (the initial jump across the sheared faces) or γ̇ h from the linear profile (the
velocity difference across a neighbourhood); Poiseuille σ_s = ρ g L_y/4 (the wall stress of
each half) and v_s the reference centre-line velocity (``reference.poiseuille``).

Time step [SPEC §2.6; coefficients measured by ``tests/unit/sph/test_simulation.py``]:

    δt = min( C_ν ρ h²/μ_max, C_c h/(c + v_s), C_a sqrt(h/g) ),

C_ν = ``numerics.dt_viscous_coefficient`` (0.05; the probe found 0.09 stable) divided by the
viscous stiffness κ = (α + β)/(α + β)_B of the pair form's weights (``terms.viscous``): the
coefficient was measured with the bulk correction B, (α + β)_B = 5/3 in 3D and 1 in 2D; without
it the pair force along r is α = d + 2, three (3D) or four (2D) times stiffer, and a run at the
step of the corrected form blew up within 100 steps; ``numerics.spin_correction`` doubles β
(κ = 3/2 in 3D, 2 in 2D). C_c =
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
from suspsim.sph.terms.viscous import viscous_weights

#: Target Mach number of the velocity scale (Morris et al. 1997) [choice].
MACH_TARGET = 0.1
#: φ above which the sound speed grows with the crowding of the bodies [choice: the densest φ
#: at which every packing of the dense-suspension and sand studies ran with the fluid's c].
CROWDING_REFERENCE_PHI = 0.3
#: Random close packing of monodisperse spheres, φ_m of the mean gap (Torquato et al. 2000).
CLOSE_PACKING = 0.64
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


def mean_gap(phi: float) -> float:
    """ḡ/a = (φ_m/φ)^(1/3) − 1 [1]: the mean surface gap of bodies of radius a at volume
    fraction φ, their spacing scaled from close packing φ_m = :data:`CLOSE_PACKING` (floored
    at 0.01 so that φ near φ_m stays finite)."""
    return max((CLOSE_PACKING / phi) ** (1.0 / 3.0) - 1.0, 0.01)


def crowding_factor(phi: float) -> float:
    """sqrt(ḡ(φ_ref)/ḡ(φ)) above φ_ref = :data:`CROWDING_REFERENCE_PHI`, else 1 [1]: the
    sound speed's factor for the gap stress of a dense suspension (module docstring)."""
    if phi <= CROWDING_REFERENCE_PHI:
        return 1.0
    return math.sqrt(mean_gap(CROWDING_REFERENCE_PHI) / mean_gap(phi))


def auto_sound_speed(scene: Scene, phi: float | None = None) -> float:
    """c = max(sqrt(σ_s/(ρ Wi)) f(φ), v_s/MACH_TARGET) (module docstring), f the
    :func:`crowding_factor` of the bodies' volume fraction ``phi`` [1] (default: the scene's
    ``inclusions.phi``; a packing file's own φ is known only once it is read)."""
    viscous = math.sqrt(stress_scale(scene) / (scene.density * scene.numerics.wi_target))
    phi = scene.inclusions.phi if phi is None else phi
    return max(viscous * crowding_factor(phi), velocity_scale(scene) / MACH_TARGET)


def max_viscosity(scene: Scene) -> float:
    """μ_max (module docstring): μ(0), or μ(γ̇/2) for Couette from the linear profile."""
    law = scene.fluid.law
    if scene.flow.type == "couette" and scene.run.start == "linear":
        return float(law.viscosity(0.5 * scene.flow.shear_rate))
    return float(law.viscosity(0.0))


def viscous_stiffness(scene: Scene) -> float:
    """κ = (α + β)/(α + β)_B [1]: the largest pair weight of the scene's viscous form against
    the bulk-corrected form's, for which C_ν was measured (module docstring)."""
    return (sum(viscous_weights(scene.dimension, scene.numerics.bulk_correction,
                                scene.numerics.spin_correction))
            / sum(viscous_weights(scene.dimension, True)))


def stable_time_step(scene: Scene, sound_speed: float, *,
                     acoustic_coefficient: float = ACOUSTIC_COEFFICIENT) -> float:
    """δt = min(C_ν ρ h²/μ_max, C_c h/(c + v_s), C_a sqrt(h/g)) (module docstring)."""
    limits = [scene.numerics.dt_viscous_coefficient * scene.density * SUPPORT ** 2
              / (max_viscosity(scene) * viscous_stiffness(scene)),
              acoustic_coefficient * SUPPORT / (sound_speed + velocity_scale(scene))]
    if scene.flow.body_force > 0:
        limits.append(FORCE_COEFFICIENT * math.sqrt(SUPPORT / scene.flow.body_force))
    return min(limits)
