"""`DSTSimulation`: a wall-bounded Wyart–Cates SPH run in 2D or 3D (seed 002; SPEC §1.3, §5).

Set-up: a lattice of n_x × n_y fluid particles fills 0 < y < L_y (spacing Δx, x periodic over
L_x = n_x Δx, mass m = ρ0 Δx² per unit depth); walls lie exactly at y = 0 and y = L_y with
``wall_layers`` rows of dummy particles at y = −(k + ½)Δx and L_y + (k + ½)Δx. In 3D
(``Geometry.n_z``) the lattice, walls included, repeats over n_z planes, z periodic over
L_z = n_z Δx, m = ρ0 Δx³, and the driven wall's area is A_w = L_x L_z. Flows:

* :class:`~suspsim.dst.parameters.StressCouette` — bottom wall fixed, top wall driven by σ_in
  through M_w dV_w/dt = σ_in A_w − F_r; starts (SPEC §5.4) from f = f̂(σ_in), the matching rate
  γ̇_0 = σ_in/η(f) (= γ̇(σ_in) of the steady law), v_x = γ̇_0 y and V_w = γ̇_0 L_y (with
  ``initial_fraction``, γ̇_0 = σ_in/⟨η(f)⟩ of the given f);
* :class:`~suspsim.dst.parameters.Channel` — both walls fixed, body acceleration g along x;
  starts from rest with f = f̂(|ρ0 g (L_y/2 − y)|), the local steady state of the stress the
  body force imposes [choice; ``initial_fraction`` overrides].

:meth:`DSTSimulation.advance` runs the compiled loop of :mod:`~suspsim.dst.integrator` (its
docstring gives the step order). Sound speed (SPEC §5.1 note) when not given: the Morris 1997
criteria with velocity scale V (Couette γ̇_0 L_y; channel F H²/(2 η(f=0)), an upper bound),
stress scale σ (σ_in or F H) and density tolerance δ: c = max(10 V, sqrt(σ/(ρ0 δ)),
sqrt(g L_y/δ)).
"""
from __future__ import annotations

import logging
import math

import numba
import numpy as np

from suspsim.dst import integrator as _int
from suspsim.dst.parameters import Channel, Geometry, Numerics, StressCouette, WyartCatesFluid
from suspsim.errors import InputError, NumericalError
from suspsim.threads import use_threads

log = logging.getLogger(__name__)

_MESSAGES = {
    _int.NONFINITE: "non-finite state (blow-up): lower numerics.viscous_number or "
                    "numerics.courant, or raise numerics.sound_speed",
    _int.DENSITY_ERROR: "density error max|rho/rho0 - 1| exceeds numerics.max_density_error: "
                        "raise numerics.sound_speed (now {c:.4g}) or lower the driving; if it "
                        "grew within a few steps, lower numerics.viscous_number (unstable step)",
    _int.MACH_LIMIT: "Mach number v_max/c exceeds numerics.max_mach: raise numerics.sound_speed "
                     "(now {c:.4g}); if it grew within a few steps, lower "
                     "numerics.viscous_number (unstable step)",
    _int.JAMMED: "a particle jammed (phi >= phi_J(f)): lower fluid.params.phi or the imposed "
                 "stress",
    _int.NEAR_JAMMING: "a particle's viscosity exceeds numerics.max_viscosity_ratio * eta_s "
                       "(approaching jamming, phi -> phi_J(f)): lower fluid.params.phi or the "
                       "imposed stress, or raise numerics.max_viscosity_ratio",
}


class DSTSimulation:
    """An SPH run (2D or 3D) of a Wyart–Cates suspension between walls (module docstring).

    Parameters
    ----------
    fluid : WyartCatesFluid
        η_s [Pa s], φ, φ_m, φ_0 [1], σ* [Pa], β [1], K_f [1], α [m²/s].
    flow : StressCouette or Channel
        σ_in [Pa] (and M_w [kg/m in 2D, kg in 3D]) or the body acceleration g [m/s²].
    geometry : Geometry
        n_x, n_y (and n_z in 3D), gap L_y [m], h_sl/Δx, wall layers.
    numerics : Numerics, optional
        ρ0 [kg/m³], sound speed [m/s], step coefficients, shifting, blow-up limits.
    threads : int, optional
        numba threads for the pair passes (default 1). Measured on the shared 2-core machine
        with 392 particles: 0.2 ms/step on 2 threads and 0.3 ms on 1 when idle, but 25 ms vs
        0.35 ms on 2 vs 1 threads at load 6 (the thread pool waits on busy cores) — use more
        threads only for large lattices on cores of your own.
    initial_fraction : callable y -> f, optional
        Initial frictional fraction of the fluid particles (overrides the flow's default).
    """

    def __init__(self, fluid: WyartCatesFluid, flow, geometry: Geometry,
                 numerics: Numerics | None = None, *, threads: int | None = None,
                 initial_fraction=None):
        if not isinstance(fluid, WyartCatesFluid):
            raise InputError("DSTSimulation", "fluid must be a WyartCatesFluid", key="fluid")
        if not isinstance(flow, (StressCouette, Channel)):
            raise InputError("DSTSimulation", "flow must be StressCouette or Channel", key="flow")
        self.fluid, self.flow, self.geometry = fluid, flow, geometry
        self.numerics = numerics if numerics is not None else Numerics()
        self.threads = int(min(threads or 1, numba.config.NUMBA_NUM_THREADS))
        self._build(initial_fraction)
        log.debug("DST run set up: %s", self.describe())

    # ------------------------------------------------------------------ set-up
    def _build(self, initial_fraction):
        geo, num, fluid = self.geometry, self.numerics, self.fluid
        dx, ly, lx = geo.spacing, geo.gap, geo.length
        d = self.dimension = geo.dimension
        layers = geo.wall_layers
        h_sl = geo.smoothing_length
        xs = (np.arange(geo.n_x) + 0.5) * dx
        zs = () if d == 2 else ((np.arange(geo.n_z) + 0.5) * dx,)

        def lattice(ys):
            return np.column_stack([c.ravel() for c in np.meshgrid(xs, ys, *zs, indexing="ij")])

        wy = (np.arange(layers) + 0.5) * dx
        fluid_xy = lattice((np.arange(geo.n_y) + 0.5) * dx)
        bottom, top = lattice(-wy), lattice(ly + wy)
        self.positions_all = np.ascontiguousarray(np.vstack([fluid_xy, bottom, top]))
        self.n_fluid, self.n_wall = len(fluid_xy), len(bottom)
        n = len(self.positions_all)
        rho0 = num.density
        mass = rho0 * dx * dx if d == 2 else rho0 * dx * dx * dx
        y = fluid_xy[:, 1]

        couette = isinstance(self.flow, StressCouette)
        if couette:
            stress = self.flow.stress
            f_init = np.full(self.n_fluid, fluid.frictional_fraction(stress))
            if initial_fraction is not None:
                f_init = np.clip(np.array([float(initial_fraction(yy)) for yy in y]), 0.0, 1.0)
            # the rate that matches σ_in with the initial microstructure (its mean viscosity)
            rate0 = stress / float(np.mean([fluid.viscosity(f) for f in f_init]))
            velocity_scale = rate0 * ly
            stress_scale = stress
            g_x = 0.0
            wall_mass = (self.flow.wall_mass if self.flow.wall_mass is not None
                         else mass * self.n_wall)
            v_init = np.zeros((self.n_fluid, d))
            v_init[:, 0] = rate0 * y
            wall_velocity = rate0 * ly
        else:
            g_x = self.flow.body_force
            force = rho0 * g_x
            half = ly / 2.0
            stress = 0.0
            stress_scale = force * half
            velocity_scale = force * half * half / (2.0 * fluid.viscosity(0.0))
            wall_mass = 1.0
            f_init = np.array([fluid.frictional_fraction(abs(force * (half - yy))) for yy in y])
            if initial_fraction is not None:
                f_init = np.clip(np.array([float(initial_fraction(yy)) for yy in y]), 0.0, 1.0)
            v_init = np.zeros((self.n_fluid, d))
            wall_velocity = 0.0
            rate0 = None
        for f in (f_init.min(), f_init.max()):
            fluid.viscosity(f)  # InputError if jammed at the start
        delta = num.density_tolerance
        c = num.sound_speed
        if c is None:
            c = max(10.0 * velocity_scale, math.sqrt(stress_scale / (rho0 * delta)),
                    math.sqrt(g_x * ly / delta))
        self.sound_speed = float(c)
        self.initial_shear_rate = rate0
        skin = num.skin * h_sl
        cutoff = 3.0 * h_sl + skin
        lz = 0.0 if d == 2 else geo.depth
        for name, length in (("n_x", lx),) + (() if d == 2 else (("n_z", lz),)):
            if length < 3.0 * cutoff:
                raise InputError("DSTSimulation", f"periodic length {length:g} holds fewer than "
                                 f"3 list cells of {cutoff:g}; raise geometry.{name}", key=name)
        self.config = _int.Config(
            dimension=d, n_fluid=self.n_fluid, n_bottom=self.n_wall, lx=lx, lz=lz,
            y_lo=-(layers + 1) * dx, y_hi=ly + (layers + 1) * dx, cutoff=cutoff, skin=skin,
            h_sl=h_sl, rho0=rho0, c=c, p_b=num.background_pressure, mass=mass, g_x=g_x,
            stress_control=couette, stress=stress, area=lx if d == 2 else lx * lz,
            wall_mass=wall_mass, eta_s=fluid.eta_s, phi=fluid.phi, phi_m=fluid.phi_m,
            phi_0=fluid.phi_0, sigma_star=fluid.sigma_star, beta=fluid.beta, K_f=fluid.K_f,
            alpha=fluid.alpha, courant=num.courant,
            viscous_number=num.viscous_number, force_number=num.force_number,
            diffusion_number=num.diffusion_number, shifting=num.shifting,
            shifting_coefficient=num.shifting_coefficient,
            gradient_correction=num.gradient_correction,
            max_density_error=num.max_density_error, max_mach=num.max_mach,
            max_viscosity_ratio=num.max_viscosity_ratio)
        self.velocity_all = np.zeros((n, d))
        self.velocity_all[:self.n_fluid] = v_init
        self.velocity_all[self.n_fluid + self.n_wall:, 0] = wall_velocity
        self.rho_all = np.full(n, rho0)
        self.f_all = np.zeros(n)
        self.f_all[:self.n_fluid] = f_init
        self.wall = np.array([wall_velocity, 0.0])
        self.clock = np.zeros(2)
        self._half = (np.zeros((n, d)), np.zeros((n, d)), np.zeros(n), np.zeros(n))
        self._buffers = _int.allocate_buffers(n, d)
        # lattice sites within the list cutoff: the disc (2D) or ball (3D) of radius r_c
        sites = (math.pi * (cutoff / dx) ** 2 if d == 2
                 else 4.0 / 3.0 * math.pi * (cutoff / dx) ** 3)
        self._lists = _int.allocate_lists(n, int(1.5 * sites * n) + 64, d)
        self.steps = 0
        self._evaluated = False
        self._wall_acceleration = 0.0
        self._turning = None

    # ------------------------------------------------------------------ running
    def _grow_lists(self):
        """Replace the full neighbour array by one 1.3 times the pairs the last build needed."""
        need = int(self._lists.start[-1])
        self._lists = self._lists._replace(
            neighbours=np.zeros(int(1.3 * need) + 64, dtype=np.int64))

    def _run(self, function, *args):
        use_threads(self.threads)
        while True:
            result = function(*args)
            code = result[0] if isinstance(result, tuple) else result
            if code != _int.LIST_OVERFLOW:
                return result
            self._grow_lists()
            args = tuple(self._lists if isinstance(a, _int.ListArrays) else a for a in args)

    def advance(self, n_steps: int, until: float | None = None) -> None:
        """Advance ``n_steps`` predictor–corrector steps, or fewer where a step would start at
        a time >= ``until`` [s] (so a run can stop on the first step at or past a time, however
        it splits its calls); NumericalError on a blow-up."""
        t_stop = math.inf if until is None else float(until)
        remaining = int(n_steps)
        while remaining > 0:
            h_pos, h_vel, h_rho, h_f = self._half
            use_threads(self.threads)
            code, done = _int.advance_steps(
                self.config, remaining, t_stop, self.positions_all, self.velocity_all,
                self.rho_all, self.f_all, self.wall, h_pos, h_vel, h_rho, h_f, self._buffers,
                self._lists, self.clock)
            self.steps += done
            remaining -= done
            self._evaluated = False
            if code == _int.LIST_OVERFLOW:
                self._grow_lists()
                continue
            if code != _int.STEP_OK:
                raise NumericalError(f"DST run stopped at step {self.steps}, t = "
                                     f"{self.time:.6g}: "
                                     + _MESSAGES[code].format(c=self.sound_speed))
            return

    def _evaluate(self):
        """Rates at the current state into the buffers, for diagnostics. The state is left as
        it was: the wall acceleration, which the next step's wall pass reads, and the dummy
        densities are restored, so sampling (``snapshot``, ``sample``, ``dt``, ...) never
        changes the trajectory."""
        if not self._evaluated:
            wall, dummy_rho = self.wall.copy(), self.rho_all[self.n_fluid:].copy()
            code = self._run(_int.evaluate, self.config, self.positions_all, self.velocity_all,
                             self.rho_all, self.f_all, self.wall, self._buffers, self._lists)
            self._wall_acceleration = float(self.wall[_int.WALL_ACCELERATION])
            self.wall[:] = wall
            self.rho_all[self.n_fluid:] = dummy_rho
            if code != _int.STEP_OK:
                raise NumericalError(_MESSAGES[code].format(c=self.sound_speed))
            self._evaluated = True

    # ------------------------------------------------------------------ state
    @property
    def time(self) -> float:
        """Simulated time [s]."""
        return float(self.clock[0])

    @property
    def dt(self) -> float:
        """Current stable step [s] (the step the next advance starts with)."""
        self._evaluate()
        return float(_int.time_step(self.config, self._buffers))

    @property
    def step_count(self) -> int:
        """Steps taken (the name the run loop of :mod:`suspsim.run` reads)."""
        return self.steps

    @property
    def last_dt(self) -> float:
        """The last step taken [s] (0 before the first); unlike :attr:`dt`, no evaluation."""
        return float(self.clock[1])

    @property
    def rebuild_count(self) -> int:
        """Neighbour-list builds since the list was allocated (start or restore) [1]."""
        return int(self._lists.builds[0])

    @property
    def n_particles(self) -> int:
        """Fluid and wall particles."""
        return self.n_fluid + 2 * self.n_wall

    @property
    def wall_velocity(self) -> float:
        """Top-wall velocity V_w [m/s]."""
        return float(self.wall[_int.WALL_VELOCITY])

    def health(self) -> tuple[bool, str]:
        """Always ``(True, "ok")``: the compiled loop checks every step for blow-up and
        :meth:`advance` raises NumericalError naming the limit (the run loop's protocol)."""
        return True, "ok"

    def state(self) -> dict:
        """Everything :meth:`restore` needs to continue bit for bit: positions, velocities,
        densities and f of all particles, the wall state [V_w, dV_w/dt], the clock [t, last δt],
        the step count, and the neighbour list's build positions, staleness and capacity (the
        list is rebuilt from those, so sums run in the same order)."""
        lists = self._lists
        return {"positions": self.positions_all.copy(), "velocity": self.velocity_all.copy(),
                "density": self.rho_all.copy(), "fraction": self.f_all.copy(),
                "wall": self.wall.copy(), "clock": self.clock.copy(), "steps": int(self.steps),
                "list_reference": lists.reference.copy(),
                "list_stale": int(lists.force_rebuild[0]),
                "list_capacity": int(lists.neighbours.shape[0])}

    def restore(self, state: dict) -> None:
        """Continue from :meth:`state` of a run built with the same parameters.

        Raises ValueError when the arrays do not fit this run's particles.
        """
        n = self.positions_all.shape[0]
        for name, target in (("positions", self.positions_all), ("velocity", self.velocity_all),
                             ("density", self.rho_all), ("fraction", self.f_all),
                             ("wall", self.wall), ("clock", self.clock)):
            value = np.asarray(state[name], dtype=float)
            if value.shape != target.shape:
                raise ValueError(f"state {name} has shape {value.shape}, this run needs "
                                 f"{target.shape}")
            target[...] = value
        self.steps = int(state["steps"])
        self._lists = _int.allocate_lists(n, int(state["list_capacity"]), self.dimension)
        if not int(state["list_stale"]):
            reference = np.ascontiguousarray(np.asarray(state["list_reference"], dtype=float))
            self._run(_int.refresh_list, self.config, reference, self._lists)
        self._evaluated = False

    def snapshot(self) -> dict:
        """Per-particle copies of the fluid: x, y [m], v_x, v_y [m/s] (3D: z, v_z too), rho,
        f [1], eta [Pa s], shear_rate [1/s], stress [Pa] (σ = η γ̇), pressure."""
        self._evaluate()
        nf = self.n_fluid
        b = self._buffers
        out = {"x": self.positions_all[:nf, 0].copy(), "y": self.positions_all[:nf, 1].copy(),
               "v_x": self.velocity_all[:nf, 0].copy(), "v_y": self.velocity_all[:nf, 1].copy(),
               "rho": self.rho_all[:nf].copy(), "f": self.f_all[:nf].copy(),
               "eta": b.eta[:nf].copy(), "shear_rate": b.gdot[:nf].copy(),
               "stress": b.sigma[:nf].copy(), "pressure": b.pressure[:nf].copy()}
        if self.dimension == 3:
            out["z"] = self.positions_all[:nf, 2].copy()
            out["v_z"] = self.velocity_all[:nf, 2].copy()
        return out

    def rates(self) -> dict:
        """Rates and gradients of the fluid particles at the current state (copies):
        drho_dt, acceleration (n_f, d), velocity_gradient (n_f, d, d) with [a, b] = ∂v_a/∂x_b,
        laplacian_f, gradient_f (n_f, d), df_dt, colour_gradient ∇C (n_f, d) with
        C_i = Σ_j V_j W_ij (≈ 0 in a regular arrangement; shifting drives it down), and the
        top-wall dV_w/dt."""
        self._evaluate()
        nf = self.n_fluid
        b = self._buffers
        return {"drho_dt": b.drho[:nf].copy(), "acceleration": b.acc[:nf].copy(),
                "velocity_gradient": b.grad[:nf].reshape(nf, self.dimension,
                                                         self.dimension).copy(),
                "laplacian_f": b.lap_f[:nf].copy(), "gradient_f": b.grad_f[:nf].copy(),
                "df_dt": b.df[:nf].copy(), "colour_gradient": b.grad_c[:nf].copy(),
                "wall_acceleration": self._wall_acceleration}

    def set_state(self, *, velocity=None, fraction=None, positions=None) -> None:
        """Overwrite fluid velocities (n_f, d), fractions f (n_f,) or positions (n_f, d)."""
        nf = self.n_fluid
        for value, target in ((velocity, self.velocity_all), (positions, self.positions_all)):
            if value is not None:
                target[:nf] = np.asarray(value, dtype=float).reshape(nf, self.dimension)
        if fraction is not None:
            self.f_all[:nf] = np.asarray(fraction, dtype=float).reshape(nf)
        if positions is not None:
            self._lists.force_rebuild[0] = 1
        self._evaluated = False

    def sample(self) -> dict:
        """Time-series sample: time, wall_velocity, domain-averaged stress σ = ⟨η γ̇⟩,
        shear_rate ⟨γ̇⟩, fraction ⟨f⟩, mean_velocity ⟨v_x⟩, wall_shear_rate V_w/L_y, the
        largest |ρ/ρ0 − 1| (density_error) and the Mach number max |v|/c (mach)."""
        snap = self.snapshot()
        speed = np.sqrt(snap["v_x"] ** 2 + snap["v_y"] ** 2 + snap.get("v_z", 0.0) ** 2)
        return {"time": self.time, "wall_velocity": self.wall_velocity,
                "stress": float(snap["stress"].mean()),
                "shear_rate": float(snap["shear_rate"].mean()),
                "fraction": float(snap["f"].mean()),
                "mean_velocity": float(snap["v_x"].mean()),
                "wall_shear_rate": self.wall_velocity / self.geometry.gap,
                "density_error": float(np.max(np.abs(snap["rho"] / self.numerics.density - 1))),
                "mach": float(speed.max()) / self.sound_speed}

    def profiles(self, bins: int) -> dict:
        """Bin-averaged v_x and f against y over [0, L_y] in ``bins`` equal bins.

        Returns y (bin centres), velocity, fraction, stress, shear_rate, viscosity and count
        per bin (NaN in an empty bin).
        """
        bins = int(bins)
        if bins < 1:
            raise ValueError("bins must be >= 1")
        snap = self.snapshot()
        edges = np.linspace(0.0, self.geometry.gap, bins + 1)
        index = np.clip(np.searchsorted(edges, snap["y"], side="right") - 1, 0, bins - 1)
        count = np.bincount(index, minlength=bins).astype(float)

        def mean(values):
            total = np.bincount(index, weights=values, minlength=bins)
            return np.where(count > 0, total / np.maximum(count, 1.0), np.nan)

        return {"y": 0.5 * (edges[:-1] + edges[1:]), "velocity": mean(snap["v_x"]),
                "fraction": mean(snap["f"]), "stress": mean(snap["stress"]),
                "shear_rate": mean(snap["shear_rate"]), "viscosity": mean(snap["eta"]),
                "count": count}

    def branch_statistics(self) -> dict:
        """ψ1 = share of σ_i < σ_β, ψ2 = share of σ_i > σ_α, q = (σ_in − σ_β)/(σ_α − σ_β).

        Turning points of the steady law (SPEC §5.6); NaN values when the curve has none.
        q needs the stress-controlled flow (NaN for the channel).
        """
        turning = self.turning_points()
        if turning is None or not math.isfinite(turning.sigma_alpha):
            return {"psi1": math.nan, "psi2": math.nan, "q": math.nan}
        sigma = self.snapshot()["stress"]
        sb, sa = turning.sigma_beta, turning.sigma_alpha
        q = ((self.flow.stress - sb) / (sa - sb) if isinstance(self.flow, StressCouette)
             else math.nan)
        return {"psi1": float(np.mean(sigma < sb)), "psi2": float(np.mean(sigma > sa)),
                "q": float(q)}

    def turning_points(self):
        """Turning points of the steady law (computed once), None without (CST, Newtonian)."""
        if self._turning is None:
            self._turning = ((None,) if self.fluid.is_newtonian
                             else (self.fluid.steady_law().turning_points(),))
        return self._turning[0]

    def describe(self) -> dict:
        """Numbers worth logging: particles, h_sl, c, δt and its limits, Reynolds number."""
        cfg = self.config
        self._evaluate()
        eta_max = float(self._buffers.eta[:self.n_fluid].max())
        eta_min = float(self._buffers.eta[:self.n_fluid].min())
        h = cfg.h_sl
        v = (self.initial_shear_rate * self.geometry.gap if self.initial_shear_rate is not None
             else cfg.rho0 * cfg.g_x * (self.geometry.gap / 2) ** 2 / (2.0 * eta_min))
        return {"fluid_particles": self.n_fluid, "wall_particles": 2 * self.n_wall,
                "h_sl": h, "sound_speed": cfg.c, "dt": self.dt,
                "dt_sound": cfg.courant * h / cfg.c,
                "dt_viscous": cfg.viscous_number * cfg.rho0 * h * h / eta_max,
                "dt_diffusion": (cfg.diffusion_number * h * h / cfg.alpha if cfg.alpha > 0
                                 else math.inf),
                "reynolds": cfg.rho0 * v * self.geometry.gap / eta_min,
                "mach": v / cfg.c}
