"""Parameters of a wall-bounded DST run (2D or 3D): fluid, geometry, flow, numerics (SPEC §1.3, §5).

Every class validates itself when built and raises :class:`~suspsim.errors.InputError` naming
the key to change. Units are any consistent set (seed 002: SI; the validation uses scaled units,
see ``tests/validation/test_dst.py``); the tables below give SI.

=============== ========================================================= =========
name            meaning                                                   unit
=============== ========================================================= =========
eta_s           solvent viscosity η_s                                     Pa s
phi             solid volume fraction φ                                   1
phi_m, phi_0    frictional, frictionless jamming fraction φ_m < φ_0       1
sigma_star      onset stress σ* of frictional contacts                    Pa
beta            sharpness β of f̂ = exp(−(σ*/σ)^β)                         1
K_f             relaxation constant of f (rate K_f γ̇)                     1
alpha           diffusivity α of f (non-locality)                         m²/s
n_x, n_y        fluid particles along x (periodic) and across the gap     1
n_z             fluid particles along z (periodic; 3D only, None in 2D)   1
gap             wall-to-wall distance L_y; Δx = gap/n_y, L_x = n_x Δx      m
smoothing_ratio h_sl/Δx of the quintic spline (seed 002: 1.1)             1
density         reference density ρ0                                      kg/m³
sound_speed     artificial sound speed c (None: the Morris criteria)      m/s
=============== ========================================================= =========
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

from suspsim.errors import InputError
from suspsim.rheology.wyart_cates import WyartCates

_SOURCE = "dst parameters"


def _positive(owner, name, value, allow_zero=False):
    ok = value >= 0.0 if allow_zero else value > 0.0
    if not (ok and math.isfinite(value)):
        bound = ">= 0" if allow_zero else "> 0"
        raise InputError(_SOURCE, f"{owner}.{name} = {value!r} must be finite and {bound}",
                         key=name)


@dataclass(frozen=True)
class WyartCatesFluid:
    """Wyart–Cates suspension with microstructure dynamics (SPEC §1.3).

    Df/Dt = K_f γ̇ (f̂(σ) − f) + α ∇²f, σ = η γ̇, f̂ = exp(−(σ*/σ)^β),
    φ_J = f φ_m + (1 − f) φ_0, η = η_s (1 − φ/φ_J)^−2.
    Names exactly as in the scene: eta_s, phi, phi_m, phi_0, sigma_star, beta, K_f, alpha.
    φ = 0 with K_f = α = 0 is a Newtonian fluid of viscosity η_s (:meth:`newtonian`).
    """

    eta_s: float
    phi: float
    phi_m: float
    phi_0: float
    sigma_star: float
    beta: float = 2.0
    K_f: float = 1.0
    alpha: float = 0.0

    def __post_init__(self):
        for field in fields(self):
            value = getattr(self, field.name)
            try:
                object.__setattr__(self, field.name, float(value))
            except (TypeError, ValueError):
                raise InputError(_SOURCE, f"fluid.{field.name} = {value!r} is not a number",
                                 key=field.name) from None
        for name in ("eta_s", "sigma_star", "beta"):
            _positive("fluid", name, getattr(self, name))
        for name in ("K_f", "alpha"):
            _positive("fluid", name, getattr(self, name), allow_zero=True)
        if not (0.0 < self.phi_m < self.phi_0 <= 1.0):
            raise InputError(_SOURCE, f"need 0 < phi_m < phi_0 <= 1; got phi_m = {self.phi_m}, "
                             f"phi_0 = {self.phi_0}", key="phi_m")
        if not (0.0 <= self.phi < self.phi_0):
            raise InputError(_SOURCE, f"phi = {self.phi} must satisfy 0 <= phi < phi_0 = "
                             f"{self.phi_0} (at phi_0 the suspension is jammed at every stress)",
                             key="phi")

    @classmethod
    def newtonian(cls, eta_s: float) -> "WyartCatesFluid":
        """A Newtonian fluid of viscosity η_s: φ = 0, no microstructure dynamics."""
        return cls(eta_s=eta_s, phi=0.0, phi_m=0.5, phi_0=0.6, sigma_star=1.0, beta=2.0,
                   K_f=0.0, alpha=0.0)

    @property
    def is_newtonian(self) -> bool:
        return self.phi == 0.0

    def steady_law(self) -> WyartCates:
        """The steady law of :mod:`suspsim.rheology.wyart_cates` (φ > 0 only)."""
        return WyartCates(self.eta_s, self.phi, self.phi_m, self.phi_0, self.sigma_star,
                          self.beta)

    def viscosity(self, f) -> float:
        """η(f) [Pa s]; raises InputError where φ ≥ φ_J(f) (jammed)."""
        phi_j = f * self.phi_m + (1.0 - f) * self.phi_0
        if self.phi >= phi_j:
            raise InputError(_SOURCE, f"phi = {self.phi} >= phi_J(f = {f:.4g}) = {phi_j:.4g}: "
                             "the suspension is jammed; lower phi or the stress", key="phi")
        return self.eta_s / (1.0 - self.phi / phi_j) ** 2

    def frictional_fraction(self, stress) -> float:
        """f̂(σ) [1] (0 for the Newtonian fluid)."""
        if self.is_newtonian or stress <= 0.0:
            return 0.0
        return math.exp(-(self.sigma_star / stress) ** self.beta)

    def shear_rate(self, stress) -> float:
        """Steady γ̇(σ) = σ/η(f̂(σ)) [1/s]."""
        return stress / self.viscosity(self.frictional_fraction(stress))


@dataclass(frozen=True)
class Geometry:
    """Lattice of n_x × n_y fluid particles filling 0 < y < gap, x periodic over n_x Δx; with
    ``n_z``, a 3D lattice n_x × n_y × n_z, z periodic over n_z Δx as well.

    Walls lie exactly at y = 0 and y = gap; ``wall_layers`` rows of dummy particles sit outside
    (None: enough for the quintic support 3 h_sl, i.e. ceil(3 · smoothing_ratio)).
    """

    n_x: int
    n_y: int
    gap: float
    smoothing_ratio: float = 1.1
    wall_layers: int | None = None
    n_z: int | None = None

    def __post_init__(self):
        for name in ("n_x", "n_y") + (() if self.n_z is None else ("n_z",)):
            value = getattr(self, name)
            if int(value) != value or value < 4:
                raise InputError(_SOURCE, f"geometry.{name} = {value!r} must be an integer >= 4",
                                 key=name)
            object.__setattr__(self, name, int(value))
        object.__setattr__(self, "gap", float(self.gap))
        object.__setattr__(self, "smoothing_ratio", float(self.smoothing_ratio))
        _positive("geometry", "gap", self.gap)
        _positive("geometry", "smoothing_ratio", self.smoothing_ratio)
        needed = math.ceil(3.0 * self.smoothing_ratio - 1e-12)
        if self.wall_layers is None:
            object.__setattr__(self, "wall_layers", needed)
        elif int(self.wall_layers) < needed:
            raise InputError(_SOURCE, f"geometry.wall_layers = {self.wall_layers} is fewer than "
                             f"the {needed} the kernel support 3 h_sl needs", key="wall_layers")
        # A periodic direction needs the cell grid of the list to hold 3 cells of h + skin.
        for name in ("n_x",) + (() if self.n_z is None else ("n_z",)):
            if getattr(self, name) < 3 * (3.0 * self.smoothing_ratio * 1.2) + 1:
                raise InputError(_SOURCE, f"geometry.{name} = {getattr(self, name)} is too small "
                                 f"for the periodic direction; need {name} >= "
                                 f"{math.ceil(10.8 * self.smoothing_ratio) + 1}", key=name)

    @property
    def dimension(self) -> int:
        """2, or 3 with ``n_z``."""
        return 2 if self.n_z is None else 3

    @property
    def depth(self) -> float | None:
        """Periodic length L_z = n_z Δx [m] in 3D (None in 2D)."""
        return None if self.n_z is None else self.n_z * self.spacing

    @property
    def spacing(self) -> float:
        """Lattice spacing Δx = gap/n_y [m]."""
        return self.gap / self.n_y

    @property
    def length(self) -> float:
        """Periodic length L_x = n_x Δx [m]."""
        return self.n_x * self.spacing

    @property
    def smoothing_length(self) -> float:
        """Quintic smoothing length h_sl [m]; the support radius is 3 h_sl."""
        return self.smoothing_ratio * self.spacing


@dataclass(frozen=True)
class StressCouette:
    """Stress-controlled shear (SPEC §5.4): bottom wall fixed, top wall driven by σ_in.

    M_w dV_w/dt = σ_in A_w − F_r, A_w = L_x per unit depth (2D) or L_x L_z (3D); ``wall_mass``
    M_w [kg/m per unit depth in 2D, kg in 3D] (None: the total mass of the top wall's dummy
    particles [choice]).
    """

    stress: float
    wall_mass: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "stress", float(self.stress))
        _positive("flow", "stress", self.stress)
        if self.wall_mass is not None:
            object.__setattr__(self, "wall_mass", float(self.wall_mass))
            _positive("flow", "wall_mass", self.wall_mass)


@dataclass(frozen=True)
class Channel:
    """Channel between fixed walls driven by a body acceleration ``body_force`` g along x [m/s²].

    The force density of SPEC §5.7 is F = ρ0 g.
    """

    body_force: float

    def __post_init__(self):
        object.__setattr__(self, "body_force", float(self.body_force))
        _positive("flow", "body_force", self.body_force)


@dataclass(frozen=True)
class Numerics:
    """Numerical settings (SPEC §5.1, §5.2, §5.5).

    density ρ0; sound_speed c (None: the Morris 1997 criteria, c = max(10 V, sqrt(σ/(ρ0 δ)),
    sqrt(g L_y/δ)) with δ = ``density_tolerance``); ``background_pressure`` p_b of the Tait EOS
    (γ = 7); step coefficients on the smoothing length h_sl (Morris 1997: 0.25 sound/force,
    0.125 viscous and diffusive). ``viscous_number`` defaults to 0.3 [measured]: with the
    quintic kernel (h_sl = 1.1 Δx) and this predictor–corrector, the local DST channel at
    F H/σ* = 10 (η varying 32-fold) ran stably with identical profiles (L2 1.73 %) at 0.25
    and 0.5 and blew up within 30 steps at 0.75; ``shifting`` Lind et al. 2012 with D = A h |v| δt;
    ``gradient_correction`` G M2⁻¹ for γ̇ (exact for linear fields on any arrangement);
    ``skin`` of the neighbour list in units of h_sl; blow-up limits ``max_density_error``
    (|ρ/ρ0 − 1|), ``max_mach`` and ``max_viscosity_ratio`` (η_max/η_s, near jamming).
    """

    density: float = 1000.0
    sound_speed: float | None = None
    density_tolerance: float = 0.01
    background_pressure: float = 0.0
    courant: float = 0.25
    viscous_number: float = 0.3
    force_number: float = 0.25
    diffusion_number: float = 0.125
    shifting: bool = False
    shifting_coefficient: float = 2.0
    gradient_correction: bool = True
    skin: float = 0.3
    max_density_error: float = 0.05
    max_mach: float = 0.3
    max_viscosity_ratio: float = 1e5

    def __post_init__(self):
        for field in fields(self):
            value = getattr(self, field.name)
            if field.name in ("sound_speed",) and value is None:
                continue
            if field.name in ("shifting", "gradient_correction"):
                object.__setattr__(self, field.name, bool(value))
                continue
            object.__setattr__(self, field.name, float(value))
            _positive("numerics", field.name, getattr(self, field.name),
                      allow_zero=field.name == "background_pressure")
