"""Stress-controlled DST flow curves: one :class:`DSTSimulation` per imposed stress (issue 5).

:func:`flow_curve` is the set-up and equilibration of the validation test
(``tests/validation/test_dst.py``, which calls it) as a pure function returning an
:class:`xarray.Dataset` on the dimension ``stress``; :func:`flow_curve_dataset` builds that
Dataset from per-point records (so plots can be tested on synthetic data) and
:func:`spanning_stresses` gives a grid that crosses both turning points.

Scaled units [choice, SPEC §7]: length L_y (the gap) = 1, viscosity η_s = 1, stress σ* = 1, so
time is counted in η_s/σ* and rates in σ*/η_s (0.2 s and 5 /s for seed 002). Seed 002's
α = 1e−5 m²/s (strong non-locality) becomes α η_s/(σ* L_y²) = 0.02, its 1e−8 m²/s
(moderate) 2e−5. Variables carry ``units = "1"`` and their dimension in ``simulation_units``
(``sigma_star``, ``eta_s``, ``L_y``), as in :mod:`suspsim.io.variables`.

One point (SPEC §5.4):

1. fluid ``WyartCatesFluid(1, φ, φ_m, φ_0, 1, β, K_f, α)``, flow ``StressCouette(σ_in)``,
   geometry ``Geometry(n_x, n_y, 1)`` (3D: ``n_z`` too, :func:`lattice_geometry`), start at
   the fixed point f = f̂(σ_in), V_w = γ̇_WC L_y;
2. density ρ = ε σ_in/(K_f γ̇_WC²), i.e. ε = K_f γ̇ ρ L_y²/η (momentum time over
   microstructure time) = 0.1 by default: momentum follows the microstructure, so the
   homogeneous state on the unstable branch stays homogeneous; Re = ρ γ̇ L_y²/η = ε/K_f. All
   steady states are independent of ρ (Stokes flow); the Morris sound speed (δ = 1 %);
3. equilibrate for ``equilibration_strain`` (γ̇_WC t, default 1.5), then take ``samples``
   equally spaced samples over the next ``averaging_strain`` (default 1.5) — an unstable
   homogeneous state would have drifted by then (perturbations grow like
   e^(K_f γ̇ t · |S|), S = d ln γ̇/d ln σ);
4. report the means of the domain averages ⟨γ̇⟩, ⟨σ⟩ = ⟨η γ̇⟩, V_w/L_y and ⟨f⟩ over the
   samples, with batch-means standard errors (``n_blocks`` consecutive blocks,
   :func:`suspsim.analysis.blocking.batch_means`). The simulation has no error estimate of its
   own. The blocks are ≈ 0.19 strain long, shorter than the microstructure relaxation
   1/(K_f γ̇) = 1 strain, so the error is the sampling scatter of this window; it does not
   measure a slow drift or the bias of the finite lattice.

The number of steps is set from the step size at the start (strain / (γ̇_WC δt)); with the
viscous step limit δt = 0.3 ρ h_sl²/η it is ≈ (L_y/h_sl)²/(0.3 ε) per strain unit whatever
σ_in is (≈ 11 000 at n_y = 20, ε = 0.1).
"""
from __future__ import annotations

import json
import logging
import math
import shlex
import sys
import time as wallclock
from datetime import datetime, timezone

import numpy as np
import xarray as xr

from suspsim.analysis.blocking import batch_means
from suspsim.dst.parameters import Geometry, Numerics, StressCouette, WyartCatesFluid
from suspsim.dst.simulation import DSTSimulation
from suspsim.errors import InputError
from suspsim.io.provenance import provenance

log = logging.getLogger(__name__)

#: Seed 002's jamming fractions and onset sharpness; K_f = 1 [SPEC §1.3 choice].
SEED_002 = {"phi_m": 0.562, "phi_0": 0.693, "beta": 2.0, "K_f": 1.0}
#: Seed 002's non-localities α [m²/s] scaled by σ* L_y²/η_s (σ* = 0.005 Pa, L_y = 0.01 m).
STRONG_NONLOCALITY, MODERATE_NONLOCALITY, LOCAL = 0.02, 2e-5, 0.0

UNIT_SYSTEM = ("scaled units: length L_y (wall-to-wall gap) = 1, viscosity eta_s (solvent) = 1, "
               "stress sigma* (onset stress) = 1; time eta_s/sigma*, rate sigma*/eta_s; "
               "variables have units '1' and state their dimension in simulation_units")
REFERENCES = (
    "Wyart & Cates, Phys. Rev. Lett. 112, 098302 (2014) (steady law); "
    "seed 002 (2D SPH of DST with microstructure Df/Dt = K_f gdot (f_hat - f) + alpha lap f); "
    "Morris, Fox & Zhu, J. Comput. Phys. 136, 214 (1997) (SPH viscous operator, step); "
    "Adami, Hu & Adams, J. Comput. Phys. 231, 7057 (2012) (walls)")

_RATE = "sigma_star eta_s-1"
_STRESS = "sigma_star"

#: name -> (long_name, simulation_units or None, comment or None); every output variable.
FLOW_CURVE_VARIABLES = {
    "stress": ("imposed shear stress sigma_in on the top wall", _STRESS, None),
    "shear_rate": ("domain- and time-averaged shear-rate magnitude <sqrt(2 D:D)>", _RATE,
                   "mean over the samples of the fluid-particle average"),
    "shear_rate_stderr": ("standard error of shear_rate (batch means of the samples)", _RATE,
                          None),
    "wall_shear_rate": ("time-averaged top-wall velocity over the gap V_w/L_y", _RATE, None),
    "wall_shear_rate_stderr": ("standard error of wall_shear_rate (batch means)", _RATE, None),
    "measured_stress": ("domain- and time-averaged shear stress <eta gdot>", _STRESS, None),
    "measured_stress_stderr": ("standard error of measured_stress (batch means)", _STRESS, None),
    "frictional_fraction": ("domain- and time-averaged fraction of frictional contacts <f>",
                            None, None),
    "steady_frictional_fraction": ("steady fraction f_hat(sigma_in) = exp(-(sigma*/sigma_in)^"
                                   "beta)", None, None),
    "wyart_cates_shear_rate": ("steady Wyart-Cates shear rate sigma_in/eta(f_hat(sigma_in))",
                               _RATE, None),
    "lower_branch_fraction": ("share psi1 of particles with sigma_i < sigma_beta at the end",
                              None, "NaN where the steady curve has no turning points"),
    "upper_branch_fraction": ("share psi2 of particles with sigma_i > sigma_alpha at the end",
                              None, "NaN where the steady curve has no turning points"),
    "density": ("reference density rho0 of the run, epsilon sigma_in/(K_f gdot_WC^2)",
                "sigma_star L_y2 eta_s-2", None),
    "sound_speed": ("artificial sound speed (Morris criteria)", "sigma_star L_y eta_s-1",
                    None),
    "time_step": ("step size at the start", "eta_s sigma_star-1", None),
    "steps": ("predictor-corrector steps of the run", None, None),
    "simulated_time": ("simulated time at the end of the run", "eta_s sigma_star-1", None),
    "reynolds_number": ("Reynolds number rho V L_y/eta_min at the start", None, None),
    "mach_number": ("Mach number V/c at the start", None, None),
    "wall_time": ("wall-clock time of the run (set-up and stepping)", None, None),
}
_PHYSICAL_UNITS = {"wall_time": "s"}


def lattice_geometry(lattice) -> Geometry:
    """The unit-gap Geometry of ``lattice`` = (n_x, n_y) or, in 3D, (n_x, n_y, n_z)."""
    return Geometry(int(lattice[0]), int(lattice[1]), 1.0,
                    n_z=int(lattice[2]) if len(lattice) > 2 else None)


def flow_curve(phi: float, stresses, *, alpha: float = STRONG_NONLOCALITY,
               lattice: tuple[int, ...] = (14, 20), threads: int = 1, epsilon: float = 0.1,
               equilibration_strain: float = 1.5, averaging_strain: float = 1.5,
               samples: int = 16, n_blocks: int = 8, phi_m: float = SEED_002["phi_m"],
               phi_0: float = SEED_002["phi_0"], beta: float = SEED_002["beta"],
               K_f: float = SEED_002["K_f"]) -> xr.Dataset:
    """Stress-controlled flow curve of a Wyart–Cates suspension at ``phi`` (module docstring).

    Parameters
    ----------
    phi : solid volume fraction φ [1], 0 < φ < φ_0.
    stresses : imposed stresses σ_in [σ*], positive (one run each, in the given order).
    alpha : diffusivity of f [L_y² σ*/η_s] (:data:`STRONG_NONLOCALITY` = seed 002's 1e−5 m²/s).
    lattice : fluid particles (n_x periodic, n_y across the gap); a third number n_z (periodic)
        makes the run 3D.
    threads : numba threads per run.
    epsilon : momentum time over microstructure time, sets ρ (and Re = ε/K_f).
    equilibration_strain, averaging_strain : γ̇_WC t discarded, then averaged.
    samples, n_blocks : samples over the averaging window, batch-means blocks (samples must be
        a multiple of n_blocks, n_blocks ≥ 2).
    phi_m, phi_0, beta, K_f : the rest of the fluid (seed 002 defaults).

    Returns the Dataset of :func:`flow_curve_dataset`. Raises InputError for bad parameters and
    NumericalError (from the solver) when a run blows up.
    """
    stresses = np.atleast_1d(np.asarray(stresses, dtype=float))
    if stresses.ndim != 1 or stresses.size == 0 or np.any(~(stresses > 0)):
        raise InputError("flow_curve", f"stresses must be positive numbers, got "
                         f"{stresses.tolist()}", key="stresses")
    if int(samples) != samples or int(n_blocks) != n_blocks or n_blocks < 2 \
            or samples % n_blocks:
        raise InputError("flow_curve", f"samples = {samples} must be a multiple of n_blocks = "
                         f"{n_blocks} >= 2", key="samples")
    for name, value in (("epsilon", epsilon), ("equilibration_strain", equilibration_strain),
                        ("averaging_strain", averaging_strain), ("K_f", K_f)):
        if not (value > 0 and math.isfinite(value)):
            raise InputError("flow_curve", f"{name} = {value!r} must be positive (the density "
                             "rule needs K_f > 0)", key=name)
    fluid = WyartCatesFluid(eta_s=1.0, phi=phi, phi_m=phi_m, phi_0=phi_0, sigma_star=1.0,
                            beta=beta, K_f=K_f, alpha=alpha)
    geometry = lattice_geometry(lattice)
    settings = {"epsilon": float(epsilon), "equilibration_strain": float(equilibration_strain),
                "averaging_strain": float(averaging_strain), "samples": int(samples),
                "n_blocks": int(n_blocks), "threads": int(threads)}
    records = [_point(fluid, geometry, float(s), **settings) for s in stresses]
    return flow_curve_dataset(fluid, geometry, stresses, records, settings)


def _point(fluid, geometry, stress, *, epsilon, equilibration_strain, averaging_strain,
           samples, n_blocks, threads) -> dict:
    """One stress-controlled run; the record of :func:`flow_curve_dataset`."""
    start = wallclock.perf_counter()
    rate = fluid.shear_rate(stress)
    density = epsilon * stress / (fluid.K_f * rate ** 2)
    sim = DSTSimulation(fluid, StressCouette(stress), geometry, Numerics(density=density),
                        threads=threads)
    described = sim.describe()
    dt = described["dt"]
    sim.advance(int(math.ceil(equilibration_strain / rate / dt)))
    every = int(math.ceil(averaging_strain / rate / dt / samples))
    series = []
    for _ in range(samples):
        sim.advance(every)
        series.append(sim.sample())
    branches = sim.branch_statistics()
    record = {"time_step": dt, "density": density, "sound_speed": sim.sound_speed,
              "reynolds_number": described["reynolds"], "mach_number": described["mach"],
              "steps": sim.steps, "simulated_time": sim.time,
              "lower_branch_fraction": branches["psi1"],
              "upper_branch_fraction": branches["psi2"],
              "n_particles": sim.n_fluid + 2 * sim.n_wall}
    for name, key in (("shear_rate", "shear_rate"), ("wall_shear_rate", "wall_shear_rate"),
                      ("measured_stress", "stress"), ("frictional_fraction", "fraction")):
        estimate = batch_means([s[key] for s in series], n_blocks)
        record[name] = estimate.mean
        if name != "frictional_fraction":
            record[f"{name}_stderr"] = estimate.stderr
    record["wall_time"] = wallclock.perf_counter() - start
    log.info("phi %g sigma_in %.4g: <gdot>/gdot_WC %.4f, <sigma>/sigma_in %.4f, %d steps, "
             "%.1f s", fluid.phi, stress, record["shear_rate"] / rate,
             record["measured_stress"] / stress, sim.steps, record["wall_time"])
    return record


def flow_curve_dataset(fluid: WyartCatesFluid, geometry: Geometry, stresses, records,
                       settings: dict, *, command: str | None = None) -> xr.Dataset:
    """The flow-curve Dataset on ``stress`` from one record (dict) per imposed stress.

    Each record holds the measured variables of :data:`FLOW_CURVE_VARIABLES` (the steady-law
    ones are computed here from ``fluid``) and ``n_particles``; ``settings`` holds epsilon,
    the strains, samples, n_blocks and threads. Global attributes: :func:`study_attributes`.
    """
    stresses = np.asarray(stresses, dtype=float)
    if len(records) != stresses.size:
        raise ValueError(f"{len(records)} records for {stresses.size} stresses")
    law = fluid.steady_law()
    computed = {"wyart_cates_shear_rate": np.asarray(law.shear_rate(stresses), dtype=float),
                "steady_frictional_fraction": np.asarray(law.frictional_fraction(stresses),
                                                         dtype=float)}
    data = {}
    for name in FLOW_CURVE_VARIABLES:
        if name == "stress":
            continue
        values = (computed[name] if name in computed
                  else np.array([float(r.get(name, math.nan)) for r in records]))
        if name == "steps":
            values = values.astype(np.int64)
        data[name] = ("stress", values, _attrs(name))
    dataset = xr.Dataset(data, coords={"stress": ("stress", stresses, _attrs("stress"))})
    dataset.attrs = study_attributes(
        fluid, geometry, records, settings, command=command,
        title=f"Stress-controlled {geometry.dimension}D SPH flow curve of a Wyart-Cates "
              f"suspension, phi = {fluid.phi:g}, alpha = {fluid.alpha:g}",
        source="suspsim.dst.study.flow_curve",
        configuration={"stresses": stresses.tolist()})
    return dataset


def study_attributes(fluid: WyartCatesFluid, geometry: Geometry, records, settings: dict, *,
                     title: str, source: str, command: str | None = None,
                     extra: dict | None = None, extra_units: dict | None = None,
                     configuration: dict | None = None) -> dict:
    """Global attributes of a DST study Dataset (flow curve, channel sweep).

    CF ``Conventions``, ``title``, ``source`` (version, git sha and the producing function
    ``source``), ``history`` (time and ``command``, default the process's argv),
    ``references``, ``unit_system``, every fluid, geometry and ``settings`` parameter, the
    steady law's ``regime`` and turning points (NaN without), the study's ``extra`` scalars,
    ``parameter_units`` (JSON; scaled units of the dimensional parameters, completed by
    ``extra_units``), ``configuration`` (all parameters, ``extra`` and ``configuration`` as
    JSON), ``n_particles`` of the first record, ``wall_time_s`` (sum over the records [s]),
    ``completed`` and the provenance.
    """
    law = fluid.steady_law()
    extra = extra or {}
    parameters = {
        "eta_s": fluid.eta_s, "phi": fluid.phi, "phi_m": fluid.phi_m, "phi_0": fluid.phi_0,
        "sigma_star": fluid.sigma_star, "beta": fluid.beta, "K_f": fluid.K_f,
        "alpha": fluid.alpha, "n_x": geometry.n_x, "n_y": geometry.n_y, "gap": geometry.gap,
        "smoothing_ratio": geometry.smoothing_ratio, "wall_layers": geometry.wall_layers,
        **({} if geometry.n_z is None else {"n_z": geometry.n_z}), **settings}
    units = {"eta_s": "eta_s", "sigma_star": "sigma_star", "alpha": "L_y2 sigma_star eta_s-1",
             "gap": "L_y", "sigma_beta": _STRESS, "sigma_alpha": _STRESS, "gdot_max": _RATE,
             "gdot_min": _RATE, **(extra_units or {})}
    points = {"sigma_beta": math.nan, "gdot_max": math.nan, "sigma_alpha": math.nan,
              "gdot_min": math.nan}
    turning = law.turning_points()
    if turning is not None:
        points = {k: float(v) for k, v in turning._asdict().items()}
    prov = provenance()
    wall = float(np.nansum([r.get("wall_time", math.nan) for r in records]))
    when = datetime.now(timezone.utc).isoformat(timespec="seconds")
    command = shlex.join(sys.argv) if command is None else command
    return {
        "Conventions": "CF-1.10", "title": title,
        "source": f"suspsim {prov['suspsim_version']} (git {prov['git_sha']}), {source}",
        "history": f"{when}: {command}", "references": REFERENCES, "unit_system": UNIT_SYSTEM,
        **parameters, "regime": law.regime(), **points, **extra,
        "parameter_units": json.dumps(units),
        "configuration": json.dumps({**parameters, **extra, **(configuration or {})}),
        "n_particles": int(records[0].get("n_particles", 0)) if records else 0,
        "wall_time_s": wall, "completed": 1, **prov}


def _attrs(name: str, table: dict | None = None) -> dict[str, str]:
    long_name, scaled, comment = (FLOW_CURVE_VARIABLES if table is None else table)[name]
    out = {"units": _PHYSICAL_UNITS.get(name, "1"), "long_name": long_name}
    if scaled:
        out["simulation_units"] = scaled
    if comment:
        out["comment"] = comment
    return out


def spanning_stresses(fluid: WyartCatesFluid, count: int = 13, *, low: float = 0.2,
                      high: float = 40.0, inside: int | None = None) -> np.ndarray:
    """``count`` stresses [σ*] from ``low`` to ``high``, log-spaced, crossing both turning points.

    With an S-curve (σ_β < σ_α, both inside (low, high)): ``inside`` stresses (default
    count // 3) log-spaced strictly between σ_β and σ_α, the rest split between
    [low, σ_β) and (σ_α, high], each log-spaced, so the unstable branch is sampled as densely
    as the stable ones. Without (CST, or σ_α = σ_J for φ ≥ φ_m): log-spaced over [low, high].
    """
    count = int(count)
    if count < 3 or not (0 < low < high):
        raise InputError("spanning_stresses", "need count >= 3 and 0 < low < high", key="count")
    turning = None if fluid.is_newtonian else fluid.steady_law().turning_points()
    if turning is None or not (low < turning.sigma_beta < turning.sigma_alpha < high):
        return np.geomspace(low, high, count)
    inside = count // 3 if inside is None else int(inside)
    outside = count - inside
    below = outside // 2 + outside % 2
    above = outside - below
    sb, sa = turning.sigma_beta, turning.sigma_alpha
    return np.concatenate([np.geomspace(low, sb, below + 1)[:-1],
                           np.geomspace(sb, sa, inside + 2)[1:-1],
                           np.geomspace(sa, high, above + 1)[1:]])


# --------------------------------------------------------------------------- stress splitting
#: name -> (long_name, simulation_units or None, comment or None) of :func:`stress_splitting`.
SPLITTING_VARIABLES = {
    "stress": ("imposed shear stress sigma_in on the top wall", _STRESS, None),
    "q": ("stress coordinate q = (sigma_in - sigma_beta)/(sigma_alpha - sigma_beta)", None,
          "0 < q < 1 on the unstable branch"),
    "psi1": ("time-averaged share of particles with sigma_i < sigma_beta", None, None),
    "psi1_stderr": ("standard error of psi1 (batch means)", None, None),
    "psi2": ("time-averaged share of particles with sigma_i > sigma_alpha", None, None),
    "psi2_stderr": ("standard error of psi2 (batch means)", None, None),
    "psi_sum": ("psi1 + psi2, share of particles on a stable branch", None, None),
    "wall_shear_rate": ("time-averaged top-wall velocity over the gap V_w/L_y", _RATE, None),
    "wall_shear_rate_stderr": ("standard error of wall_shear_rate (batch means)", _RATE, None),
    "shear_rate": ("domain- and time-averaged shear-rate magnitude <sqrt(2 D:D)>", _RATE, None),
    "shear_rate_stderr": ("standard error of shear_rate (batch means)", _RATE, None),
    "measured_stress": ("domain- and time-averaged stress <eta gdot>", _STRESS, None),
    "measured_stress_stderr": ("standard error of measured_stress (batch means)", _STRESS, None),
    "frictional_fraction": ("domain- and time-averaged fraction of frictional contacts <f>",
                            None, None),
    "lower_branch_stress": ("sigma1, lower stable branch stress at wall_shear_rate", _STRESS,
                            "NaN where the branch has no such rate"),
    "upper_branch_stress": ("sigma2, upper stable branch stress at wall_shear_rate", _STRESS,
                            "NaN where the branch has no such rate"),
    "lever_rule": ("lever-rule share (sigma2 - sigma_in)/(sigma2 - sigma1) at wall_shear_rate",
                   None, "the prediction for psi1 at the measured common rate"),
    "lever_rule_domain_rate": ("lever-rule share at the domain-averaged rate shear_rate", None,
                               None),
    "psi1_minus_lever": ("time average of psi1 - lever rule at the instantaneous V_w/L_y", None,
                         None),
    "psi1_minus_lever_stderr": ("standard error of psi1_minus_lever (batch means)", None,
                                "the statistical error of the lever-rule comparison"),
    "wyart_cates_shear_rate": ("steady Wyart-Cates shear rate at sigma_in", _RATE, None),
    "wyart_cates_lever_rule": ("lever-rule share at the Wyart-Cates rate gdot(sigma_in) "
                               "(seed 002 Fig. 5 line)", None, None),
    "initial_perturbation": ("rms of the random perturbation added to f = f_hat(sigma_in)",
                             None, None),
    "density": ("reference density rho0 of the run", "sigma_star L_y2 eta_s-2", None),
    "sound_speed": ("artificial sound speed", "sigma_star L_y eta_s-1", None),
    "steps": ("predictor-corrector steps of the run", None, None),
    "simulated_time": ("simulated time at the end of the run", "eta_s sigma_star-1", None),
    "wall_time": ("wall-clock time of the run (set-up and stepping)", None, None),
}


def stress_splitting(phi: float, stresses, *, alpha: float = LOCAL,
                     lattice: tuple[int, ...] = (14, 12), threads: int = 1,
                     epsilon: float = 0.1, perturbation: float = 0.01, seed: int = 1,
                     equilibration_strain: float = 20.0, averaging_strain: float = 20.0,
                     samples: int = 40, n_blocks: int = 8,
                     phi_m: float = SEED_002["phi_m"], phi_0: float = SEED_002["phi_0"],
                     beta: float = SEED_002["beta"], K_f: float = SEED_002["K_f"]
                     ) -> xr.Dataset:
    """Stress splitting of the local model (SPEC §5.6; seed 002 Fig. 5): one run per stress.

    Set-up as :func:`flow_curve` (scaled units, ρ from ε = K_f γ̇ ρ L_y²/η at the Wyart–Cates
    rate γ̇_WC(σ_in)), with three differences:

    * **Start**: f_i = f̂(σ_in) + ``perturbation`` · N(0, 1) per particle (clipped to [0, 1],
      generator ``seed``), V_w = γ̇_WC L_y. The homogeneous fixed point on the unstable branch
      is unstable to particle-scale perturbations at α = 0 (a particle with more contacts
      carries more stress at the common rate, so f̂(σ_i) rises: the rate-controlled slope is
      negative there); seed 002 seeds it with the uncorrelated SPH noise of γ̇_i and finds the
      same steady split from relaxed, steady and over-structured starts. On the regular
      lattice in affine shear (corrected gradients are exact for linear fields) that noise
      starts near round-off, so an explicit uncorrelated perturbation of 1 % (≈ 1.3 % of f̂
      at σ_in = 2σ*) stands for it [choice]; it starts the split within ≈ 3 strain units
      (measured at φ = 0.54, σ_in = 2σ*, 14 × 12).
    * **Sound speed**: c = max(Morris, sqrt(σ2/(ρ δ))) with σ2 the upper-branch stress at
      γ̇_WC, the largest stress a split particle carries (δ = 1 %). With the Morris value from
      σ_in the density error passed 5 % at strain 13 of the split (measured, 14 × 20, σ_in = 2).
    * **Time**: at σ_in = 2σ* (14 × 12, measured) the split starts after ≈ 3 strain units
      (γ̇_WC t), ψ1 reaches 0.61 by 10 and then creeps (0.64 at 20, 0.69 at 60) while the
      rate settles ≈ 20 % below γ̇_WC; the window is therefore not free of a slow drift,
      which the batch-means errors (blocks of 2.5 strain units) do not include;
      ``equilibration_strain`` (default 20) is discarded, then ``samples`` equally spaced
      samples over ``averaging_strain`` (default 20) give ψ1, ψ2, V_w/L_y, ⟨γ̇⟩, ⟨σ⟩ and the
      lever rule at each sample's V_w/L_y, with batch-means errors over ``n_blocks`` blocks.
      The runs advance by simulated time (the step shrinks as particles reach the viscous
      upper branch).

    The lever rule (SPEC §5.6) is evaluated at the measured common rate, the time-averaged
    V_w/L_y (``lever_rule``; also at ⟨γ̇⟩, ``lever_rule_domain_rate``), with σ1, σ2 from
    :meth:`~suspsim.rheology.wyart_cates.WyartCates.branch_stress`; ``wyart_cates_lever_rule``
    is the seed's Fig. 5 line at γ̇_WC(σ_in). ``psi1_minus_lever`` is the time average of
    ψ1(t) − lever(V_w(t)/L_y), whose batch-means error is the statistical error of the
    comparison (fluctuations of V_w move both).

    Returns a Dataset on ``stress`` (variables :data:`SPLITTING_VARIABLES`, attributes
    :func:`study_attributes`). Raises InputError for stresses outside (σ_β, σ_α) or a law
    without turning points.
    """
    stresses = np.atleast_1d(np.asarray(stresses, dtype=float))
    fluid = WyartCatesFluid(eta_s=1.0, phi=phi, phi_m=phi_m, phi_0=phi_0, sigma_star=1.0,
                            beta=beta, K_f=K_f, alpha=alpha)
    law = fluid.steady_law()
    turning = law.turning_points()
    if turning is None or not math.isfinite(turning.sigma_alpha):
        raise InputError("stress_splitting", f"phi = {phi} has no unstable branch with a "
                         "flowing upper branch (need DST, phi < phi_m)", key="phi")
    if stresses.ndim != 1 or stresses.size == 0 or np.any(
            ~((stresses > turning.sigma_beta) & (stresses < turning.sigma_alpha))):
        raise InputError("stress_splitting", f"stresses {stresses.tolist()} must lie inside "
                         f"the unstable range ({turning.sigma_beta:.4g}, "
                         f"{turning.sigma_alpha:.4g})", key="stresses")
    if int(samples) != samples or int(n_blocks) != n_blocks or n_blocks < 2 \
            or samples % n_blocks:
        raise InputError("stress_splitting", f"samples = {samples} must be a multiple of "
                         f"n_blocks = {n_blocks} >= 2", key="samples")
    geometry = lattice_geometry(lattice)
    settings = {"epsilon": float(epsilon), "perturbation": float(perturbation),
                "seed": int(seed), "equilibration_strain": float(equilibration_strain),
                "averaging_strain": float(averaging_strain), "samples": int(samples),
                "n_blocks": int(n_blocks), "threads": int(threads)}
    records = [_split_point(fluid, law, geometry, float(s), **settings) for s in stresses]
    data = {}
    for name in SPLITTING_VARIABLES:
        if name == "stress":
            continue
        values = np.array([float(r[name]) for r in records])
        if name == "steps":
            values = values.astype(np.int64)
        data[name] = ("stress", values, _attrs(name, SPLITTING_VARIABLES))
    dataset = xr.Dataset(data, coords={"stress": ("stress", stresses,
                                                  _attrs("stress", SPLITTING_VARIABLES))})
    dataset.attrs = study_attributes(
        fluid, geometry, records, settings,
        title=f"Stress splitting of the local Wyart-Cates model in {geometry.dimension}D SPH "
              f"stress-controlled shear, phi = {phi:g}, alpha = {alpha:g}",
        source="suspsim.dst.study.stress_splitting",
        configuration={"stresses": np.asarray(stresses, dtype=float).tolist()})
    return dataset


def splitting_sound_speed(law, stress: float, density: float, gap: float = 1.0,
                          tolerance: float = 0.01) -> float:
    """Sound speed [L/T] for a stress-controlled run that may split (:func:`stress_splitting`).

    c = max(10 γ̇ L_y, sqrt(σ_in/(ρ δ)), sqrt(σ2/(ρ δ))): the Morris 1997 criteria at the
    Wyart–Cates rate γ̇ = γ̇_WC(σ_in) of ``law`` (a :class:`~suspsim.rheology.wyart_cates.
    WyartCates`) and density tolerance δ, raised to the upper-branch stress σ2 at γ̇, the
    largest stress a split particle carries. Where the upper branch has no such rate (σ2
    NaN: stable lower branch below γ̇_min, CST) the Morris value alone.
    """
    rate = float(law.shear_rate(stress))
    sound = max(10.0 * rate * gap, math.sqrt(stress / (density * tolerance)))
    upper = float(law.branch_stress(rate, "upper")) if law.turning_points() else math.nan
    return max(sound, math.sqrt(upper / (density * tolerance))) if math.isfinite(upper) \
        else sound


def _split_point(fluid, law, geometry, stress, *, epsilon, perturbation, seed,
                 equilibration_strain, averaging_strain, samples, n_blocks, threads) -> dict:
    """One split run; the record of :func:`stress_splitting`."""
    start = wallclock.perf_counter()
    turning = law.turning_points()
    rate = fluid.shear_rate(stress)
    density = epsilon * stress / (fluid.K_f * rate ** 2)
    sound = splitting_sound_speed(law, stress, density, geometry.gap)
    sim = DSTSimulation(fluid, StressCouette(stress), geometry,
                        Numerics(density=density, sound_speed=sound), threads=threads)
    rng = np.random.default_rng(seed)
    f0 = fluid.frictional_fraction(stress)
    sim.set_state(fraction=np.clip(f0 + perturbation * rng.standard_normal(sim.n_fluid),
                                   0.0, 1.0))
    t_eq = equilibration_strain / rate
    sim.advance(2 ** 62, until=t_eq)
    series = {k: [] for k in ("psi1", "psi2", "wall", "rate", "stress", "f", "diff")}
    for k in range(samples):
        sim.advance(2 ** 62, until=t_eq + (k + 1) * averaging_strain / rate / samples)
        sample, branches = sim.sample(), sim.branch_statistics()
        series["psi1"].append(branches["psi1"])
        series["psi2"].append(branches["psi2"])
        series["wall"].append(sample["wall_shear_rate"])
        series["rate"].append(sample["shear_rate"])
        series["stress"].append(sample["stress"])
        series["f"].append(sample["fraction"])
        series["diff"].append(branches["psi1"]
                              - float(law.lever_rule(stress, sample["wall_shear_rate"])))
    est = {k: batch_means(v, n_blocks) for k, v in series.items()}
    wall_rate = est["wall"].mean
    record = {
        "q": (stress - turning.sigma_beta) / (turning.sigma_alpha - turning.sigma_beta),
        "psi1": est["psi1"].mean, "psi1_stderr": est["psi1"].stderr,
        "psi2": est["psi2"].mean, "psi2_stderr": est["psi2"].stderr,
        "psi_sum": est["psi1"].mean + est["psi2"].mean,
        "wall_shear_rate": wall_rate, "wall_shear_rate_stderr": est["wall"].stderr,
        "shear_rate": est["rate"].mean, "shear_rate_stderr": est["rate"].stderr,
        "measured_stress": est["stress"].mean, "measured_stress_stderr": est["stress"].stderr,
        "frictional_fraction": est["f"].mean,
        "lower_branch_stress": float(law.branch_stress(wall_rate, "lower")),
        "upper_branch_stress": float(law.branch_stress(wall_rate, "upper")),
        "lever_rule": float(law.lever_rule(stress, wall_rate)),
        "lever_rule_domain_rate": float(law.lever_rule(stress, est["rate"].mean)),
        "psi1_minus_lever": est["diff"].mean, "psi1_minus_lever_stderr": est["diff"].stderr,
        "wyart_cates_shear_rate": rate,
        "wyart_cates_lever_rule": float(law.lever_rule(stress, rate)),
        "initial_perturbation": perturbation, "density": density, "sound_speed": sound,
        "steps": sim.steps, "simulated_time": sim.time, "n_particles": sim.n_particles,
        "wall_time": wallclock.perf_counter() - start}
    log.info("phi %g sigma_in %.4g (q %.3f): psi1 %.3f +- %.3f, psi2 %.3f, lever %.3f "
             "(WC %.3f), V_w/L_y/gdot_WC %.3f, %d steps, %.0f s", fluid.phi, stress,
             record["q"], record["psi1"], record["psi1_stderr"], record["psi2"],
             record["lever_rule"], record["wyart_cates_lever_rule"], wall_rate / rate,
             sim.steps, record["wall_time"])
    return record
