"""The measured error model and cost model of SPH fluid runs, and the tolerance-driven picker
(issue 7: ``suspsim run --tolerance``).

Error model. The expected error bound (error + 2 standard errors, as :mod:`.study`) of a run is
a sum of non-negative contributions of dimensionless drivers, each a simple law whose
coefficients are fitted on measured sweeps of training cases:

    E = a_(o,d) q^-p_d                  discretisation: q = h/Δx after snapping, per observable
                                        o (stress of Couette, velocity profile of Poiseuille)
                                        and dimension d (lucy kernel, start jitter 0.1); the
                                        order p_d per dimension (the kernel on a d-lattice)
      + b_(f,d) (h/ℓ)^r                 flow resolution: ℓ the flow's length [h]; Poiseuille
                                        ℓ = W (1 − ξ), the sheared width of the channel
                                        (ξ = τ_y/σ_wall the plug fraction), Couette ℓ = the
                                        periodic box side (finite size); per flow f and
                                        dimension d: the Newtonian channel measured 1.5–1.6 %
                                        at W = 3.75 h and 0.7–0.8 % at 5 h in 2D (q = 3–4)
                                        against 2.5 % and 1.4 % in 3D (q = 1.6)
      + c Wi                            compressibility, Wi = μγ̇/(ρc²)
      + k_d C_Δx^s                      time step (per dimension), C_Δx = δt μ_max/(ρΔx²) the
                                        viscous number on the lattice spacing that the run
                                        actually uses (= C_ν q² where the viscous limit binds;
                                        the acoustic or force limit may bind first), μ_max as
                                        :func:`~suspsim.sph.timestep.max_viscosity`
      + k_plug,d C_Δx^s (ξ/(1 − ξ))^t   time step of the plug (yield-stress channel, ξ the
                                        plug fraction): C_Δx is the viscous number of the
                                        particles at μ ≈ μ_max, and in a channel those are the
                                        plug's, a fraction ξ of the width; the explicit step
                                        resolves their viscous relaxation only coarsely at large
                                        C_Δx, and the plug's velocity error is carried into the
                                        profile through the sheared layers of width (1 − ξ)W
                                        that set its speed, hence the plug-to-sheared ratio
                                        ξ/(1 − ξ) (t fitted). Measured (q = 1.6, C = 0.4
                                        against 0.1 or 0.05): Bn = 1 (ξ = 0.27) +0.01 % at W =
                                        5 h, Bn = 3 (ξ = 0.45) +0.3 and +0.6 % at W = 7.5 and
                                        10 h, Bn = 5 (ξ = 0.54) +1.7 and +0.9 %, Bn = 10 (ξ =
                                        0.64) +2.5 and +2.5 %: steep in both C_Δx and ξ, so
                                        the fit takes large s and t
      + g_d / sqrt(units)               statistics of stress-averaged (Couette) runs, units =
                                        averaged strain units
      + y Bn^u                          yield stress in the channel: Bn the Bingham number of
                                        the channel (:func:`~suspsim.reference.poiseuille.
                                        bingham_number`; 0 without a yield stress), u fitted.
                                        Measured, not derived: the Bn = 1, 3, 5 and 10 channels
                                        kept a floor of about 0.9 %, 2.0–2.3 %, 4.2–4.4 % and
                                        5.3–6.4 % (W = 7.5–10 h) that q, the width and the
                                        time step (C down to 0.05) did not lower: growing
                                        slower than Bn (linear from Bn ≤ 5 extrapolated to
                                        9.7 % at Bn = 10), so the exponent u (≤ 1) is fitted;
                                        the model is used up to the largest trained Bn

The coefficients are fitted by non-negative asymmetric least squares on relative residuals
(the :data:`EXPECTILE` expectile: an under-prediction weighs EXPECTILE/(1 − EXPECTILE) times an
over-prediction, so the fit leans to an upper envelope), the exponents (p_d, r, s) by a grid
search for the tightest inflated envelope (:func:`envelope_score`: the model is used as a
bound, so what matters is how far the bound sits above the measurements on average). The sum
of magnitudes is conservative where signed errors cancel.

Inflation. The model is then inflated per class of flow and dimension
(:func:`inflation_class`) by a cross-validated bound (:func:`cross_validated_inflation`):
leave one case out (:func:`held_out_ratios`: refit without all of that case's runs, the
exponents searched within one grid step of the full fit's), take the measured/model ratio of
each of its runs that the fold's model would let the picker use (inside the fold's domain, its
class still trained), and inflate each class by the largest such held-out ratio, floored by
the largest in-sample ratio so the inflated model still bounds every training point; a class
without training points takes the largest inflation (``inflation``). The picker asks inflated
E ≤ tolerance (:data:`SAFETY` = 1): the held-out ratio is already the margin for a case the
model has not seen, and the earlier in-sample maximum with a 0.8 safety factor counted that
margin twice (the second blind set's 2D channel and Bingham channel picks met 5 % at 2.8-3×
the cheapest cost). Measured in the packaged fit (class: inflation; largest held-out ratio,
its case, held-out points/cases; largest in-sample ratio): Couette 2D 1.62; 1.33, Newtonian 2D,
4/2; 1.62. Couette 3D 1.81; 1.81, Papanastasiou Bn 9.9, 29/4; 1.80. Channel 2D 1.26; 1.21,
Newtonian Re 0.1, 18/2; 1.26. Channel 3D 2.35; 2.35, Bingham Bn 5, 59/7; 1.85. With the
in-sample maxima alone, 18 of the 110 held-out runs exceeded their fold's inflated bound, by up
to 1.34× (Couette 2D), 1.29× (channel 3D), 1.21× (channel 2D) and 1.04× (Couette 3D): the
in-sample bound is too small for a new case, by about what the 0.8 factor added. The largest
held-out ratio rather than a quantile: the channel 3D bound is not one case's outlier (three
cases held out at 2.35, 2.22 and 2.11: Bn = 5, the Newtonian channel and Re = 1), and the
picker's pick sits where the bound is tightest. Flow and dimension rather than flow alone: the
2D classes' bounds lie 10–46 % below the 3D ones; not the law class as well: in 3D the
rate-dependent in-sample maxima were within 4 % of the Newtonian ones, and 2D holds two
rate-dependent points. The exponent search scores the envelope of the per-class in-sample
inflation.

Time-step margin. A blow-up inside the calm range of its class caps the class below it (the
``unsafe`` logic of :func:`fit_in_sample`): the 2D channel at Re = 0.5 blew up at C_Δx = 0.67
(q = 2.5, W = 7.5 h, C = 0.2; density error 1.9 after 1097 steps, a slow growth) where the
Re = 0.1 channel ran calm up to 0.70, so the 2D Newtonian channel is capped below 0.666. As a
slow blow-up can sit just inside the calm range of other cases, every class's C_Δx range is
also shortened by :func:`stability_margin`, the smallest ratio of a blow-up's C_Δx to the
edge of the calm range its class had without it: 0.666/0.705 = 0.945 (the only blow-up inside
a calm range; the other one, 2D q = 2.4, W = 2.5 h at 0.80, lies above it), so no pick sits at
the very edge of a measured range.

Domain. The model is used only inside the measured range of each driver
(``bounds``; C_Δx per flow, dimension and law class, :func:`_step_class`: a viscous-limited
Papanastasiou Couette run at C_Δx = 0.77 was 44 % off while the Bingham channel, whose μ_max
= μ(0) is met only in the plug, stayed within 1 % up to C_Δx = 1.5; and, per class as well,
the step on the support radius, δt μ_max/(ρh²) = C_Δx/q², the number the viscous operator's
stability follows: the 3D Newtonian channel blew up at δt ν/h² = 0.1 (q = 1.6, C_Δx = 0.26, Re
0.1 and 0.25, Wi ≥ 0.003; every candidate of the fourth blind set's Re = 0.25 channel) and ran
at 0.0675, while q = 2.4 ran at C_Δx = 0.29 with δt ν/h² = 0.05, so C_Δx alone let the picker
step past the edge) and on the search grid
(:data:`GRID`), outside which runs blew up or are not measured: q < 1.5 (3D) blew up; q near
2 (:data:`RESOLUTION_GAP`) gave 5–37 % errors in every training case (lattice shells at
r = h); a channel with an odd number of rows across L_y (:func:`regular`); quintic blew up at
q = 1.6 in 3D and is not modelled; Wi = 0.03 blew up; a channel whose sheared width ℓ is below
:data:`MIN_SHEARED_WIDTH` (the Bn = 10 channel at W = 5 h, ℓ = 1.79 h, measured 31–35 %).

Cost model: CPU seconds ≈ k_d (N q^d n_steps)^α, N particles and n_steps computed exactly from
the scene (the automatic sound speed and time step of :mod:`suspsim.sph.timestep`), q^d ∝
neighbours per particle; k_d and α fitted in log space on the same runs' CPU times.

The picker (:func:`pick`) searches the grid of a case-like description (:class:`~.cases.Case`:
the physics fixed in dimensionless form, the numerics as settings) for the cheapest
configuration whose expected error meets the tolerance.

Commands::

    python -m suspsim.convergence.error_model fit OUT.json CASE_FILES.nc...
    python -m suspsim.convergence.error_model pick CASE TOLERANCE
"""
from __future__ import annotations

import dataclasses
import datetime
import functools
import itertools
import json
import math
import sys
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np
import xarray as xr

from suspsim.convergence.cases import Case, get_case
from suspsim.errors import InputError
from suspsim.reference.poiseuille import bingham_number
from suspsim.scene import Scene
from suspsim.sph.timestep import (SUPPORT, auto_sound_speed, max_viscosity, stable_time_step,
                                  stress_scale)

#: The configuration grid the picker searches (per dimension for the resolution) [choice: the
#: measured, stable range]. Widths and sides step by 1.25 h (1.25–1.5× in 3D cost between
#: neighbours; 2D q by 1.1–1.2×): a pick that has to round up to the next candidate pays at most
#: that step. With the coarser grid (sides 5, 7.5, 10 h; widths 2.5, 3.75, 5, 7.5, 10, 15 h; 2D
#: q 2.5, 3, 4, 5) the third blind set's picks cost 2.6–9.8× the cheapest configuration that met
#: the tolerance, partly because the next candidate up cost 2.5–3.4× the one below it. 3D q
#: stays 1.6, 2.4, 3.2: q = 2.8 would put the (2, 2, 0) lattice shell at r ≈ h, as q = 2 does
#: the (2, 0, 0) shell (:data:`RESOLUTION_GAP`), and no training run measured it.
GRID: dict[str, Any] = {
    "resolution": {3: (1.6, 2.4, 3.2), 2: (2.5, 2.75, 3.0, 3.5, 4.0, 5.0)},
    "dt_coefficient": (0.05, 0.1, 0.2, 0.3, 0.4),
    "wi_target": (1e-3, 3e-3, 1e-2),
    "side": (5.0, 6.25, 7.5, 8.75, 10.0),
    "units": (2, 3, 4, 6),
    "width": (2.5, 3.125, 3.75, 4.375, 5.0, 6.25, 7.5, 8.75, 10.0, 12.5, 15.0),
}
#: Snapped resolutions in this band are excluded: every training case measured 5–37 % error at
#: q = 2 (lattice shells at the support radius), against < 1.5 % at q = 1.6 and 2.4.
RESOLUTION_GAP = (1.8, 2.2)
#: Narrowest sheared width ℓ = W (1 − ξ) of a channel in the model [h] [choice: two kernel
#: supports]: the Bn = 10 channel at W = 5 h (ℓ = 1.79 h) measured 31–35 % at C = 0.4 and 0.1,
#: four times the 8.6 % of the Bn = 3 channel at ℓ = 2.06 h, a cliff that no power of h/ℓ
#: follows without over-predicting every wider channel.
MIN_SHEARED_WIDTH = 2.0
#: The settings the model holds fixed (kernel and start jitter of the training runs).
FIXED = {"kernel": "lucy", "jitter": 0.1}
#: Fraction of the tolerance the inflated expected error may use [1]: 1, as the
#: cross-validated inflation already bounds the held-out cases (module docstring).
SAFETY = 1.0
#: A training run measured above this multiple of the first fit is left out of the fit and
#: caps the domain's time step [choice].
OUTLIER_RATIO = 3.0
#: Expectile of the asymmetric least-squares fit [choice].
EXPECTILE = 0.9
#: Exponent grids of the fit.
EXPONENTS = {"p_2d": (0.5, 1.0, 1.5, 2.0, 3.0, 4.0), "p_3d": (0.5, 1.0, 1.5, 2.0, 3.0, 4.0),
             "r": (1.0, 1.5, 2.0, 2.5, 3.0, 4.0), "s": (1.0, 2.0, 4.0, 6.0, 8.0),
             "t": (1.0, 2.0, 4.0, 6.0), "u": (0.5, 0.75, 1.0)}
#: The packaged fitted model.
MODEL_FILE = "error_model.json"
#: Format of the model's JSON: 2 adds ``class_inflation`` (format 1 is read with the global
#: inflation for every class); the cross-validated inflation keeps format 2 (the same keys).
FORMAT = 2
_OBSERVABLE = {"couette": "stress", "poiseuille": "profile"}
#: Prefixes of the time-step bounds: C_Δx = δt μ_max/(ρΔx²) and δt μ_max/(ρh²) = C_Δx/q².
_STEP_PREFIXES = ("courant", "stepsupport")
_STEP_KEYS = tuple(prefix + "_" for prefix in _STEP_PREFIXES)


@dataclass(frozen=True)
class Drivers:
    """The dimensionless drivers and the size of one configuration: ``flow`` (couette or
    poiseuille), ``dimension``, ``resolution`` q [1], ``length`` ℓ [h], ``wi`` [1], ``courant``
    C_ν [1], ``units`` (averaged strain units; 0 for Poiseuille), ``n_particles``,
    ``n_steps``, ``bingham`` (the channel's Bingham number, 0 for Couette or without a yield
    stress), ``rows`` (lattice rows across the channel's L_y; 0 for Couette), ``newtonian``
    (the law's viscosity does not depend on the rate), ``plug`` (the channel's plug fraction ξ
    [1], :func:`plug_fraction`; 0 for Couette); C_Δx = δt μ_max/(ρΔx²) [1]."""

    flow: str
    dimension: int
    resolution: float
    length: float
    wi: float
    courant: float
    units: float
    n_particles: int
    n_steps: int
    bingham: float = 0.0
    rows: int = 0
    newtonian: bool = True
    plug: float = 0.0

    @property
    def observable(self) -> str:
        return _OBSERVABLE[self.flow]

    @property
    def work(self) -> float:
        """N q^d n_steps: particle-steps times neighbours per particle (∝ q^d) [1]."""
        return self.n_particles * self.resolution ** self.dimension * self.n_steps


def plug_fraction(scene: Scene) -> float:
    """ξ = τ_y/σ_wall of a Poiseuille scene [1] (0 without a yield stress), σ_wall the wall
    stress of each half of the split-force channel (:func:`~suspsim.sph.timestep.stress_scale`)."""
    law = scene.fluid.law
    if not law.spec.has_yield_stress:
        return 0.0
    return min(float(law.yield_stress) / stress_scale(scene), 0.99)


def drivers(scene: Scene, settings: Mapping[str, Any]) -> Drivers:
    """The drivers of ``scene`` built from ``settings`` (a case's full settings)."""
    return _numerics_variants(scene, settings, [{}])[0]


def _numerics_variants(scene: Scene, settings: Mapping[str, Any],
                       variants: Sequence[Mapping[str, float]]) -> list[Drivers]:
    """The drivers of ``scene`` with each of ``variants`` (numerics overrides) applied."""
    if scene.flow.type not in _OBSERVABLE or scene.inclusions.present:
        raise InputError(scene.source, "the error model covers fluid couette and poiseuille "
                         f"flows only, not {scene.flow.type}"
                         + (" with inclusions" if scene.inclusions.present else ""))
    bingham, rows, plug = 0.0, 0, 0.0
    if scene.flow.type == "poiseuille":
        rows, plug = scene.lattice_counts[1], plug_fraction(scene)
    if scene.flow.type == "couette":
        length, units = scene.box[1], float(settings["units"])
    else:
        length, units = 0.5 * scene.box[1] * (1.0 - plug), 0.0
        if scene.fluid.law.spec.has_yield_stress:
            bingham = float(bingham_number(scene.fluid.law, scene.density * scene.flow.body_force,
                                           0.5 * scene.box[1]))
    viscosity = max_viscosity(scene)
    n_particles = math.prod(scene.lattice_counts)
    out = []
    for variant in variants:
        sc = dataclasses.replace(scene, numerics=dataclasses.replace(scene.numerics, **variant))
        dt = stable_time_step(sc, auto_sound_speed(sc))
        out.append(Drivers(sc.flow.type, sc.dimension, sc.number_density ** (1.0 / sc.dimension),
                           length, float(sc.numerics.wi_target),
                           dt * viscosity / (sc.density * sc.lattice_spacing ** 2), units,
                           n_particles, max(1, round(sc.total_time / dt)), bingham, rows,
                           scene.fluid.law.name == "newtonian", plug))
    return out


def _features(d: Drivers, ex: Mapping[str, float]) -> dict[str, float]:
    """Each term's driver function (coefficient 1) at exponents ``ex``, keyed by coefficient
    name."""
    out = {f"disc_{d.observable}_{d.dimension}d": d.resolution ** -ex[f"p_{d.dimension}d"],
           f"flow_{d.flow}_{d.dimension}d": (SUPPORT / d.length) ** ex["r"], "wi": d.wi,
           f"courant_{d.dimension}d": d.courant ** ex["s"]}
    if d.units > 0:
        out[f"stat_{d.dimension}d"] = d.units ** -0.5
    if d.flow == "poiseuille":
        out["yield_poiseuille"] = d.bingham ** ex["u"]
    if d.plug > 0:
        out[f"courant_plug_{d.dimension}d"] = (d.courant ** ex["s"]
                                               * (d.plug / (1.0 - d.plug)) ** ex["t"])
    return out


@dataclass
class ErrorModel:
    """Fitted coefficients, exponents, inflation, driver bounds, cost model and provenance.
    ``class_inflation`` is each class's (:func:`inflation_class`) cross-validated bound on the
    measured/model ratio (module docstring); ``inflation``, the largest of them, is the
    fallback of a class missing from it (a model without it, format 1, inflates every class by
    ``inflation``)."""

    coefficients: dict[str, float]
    exponents: dict[str, float]
    inflation: float
    bounds: dict[str, list[float]]
    cost: dict[str, float]
    provenance: dict[str, Any] = field(default_factory=dict)
    residuals: dict[str, Any] = field(default_factory=dict)
    class_inflation: dict[str, float] = field(default_factory=dict)

    def _coefficient(self, name: str) -> float:
        if name in self.coefficients:
            return self.coefficients[name]
        if name.startswith("stat_"):
            # statistics of a dimension without stress-averaged training runs: the largest
            # measured coefficient
            stats = [v for k, v in self.coefficients.items() if k.startswith("stat_")]
            if stats:
                return max(stats)
        if name.startswith("flow_"):
            # a flow not measured in this dimension: the largest of its other dimensions
            flows = [v for k, v in self.coefficients.items()
                     if k.startswith(name.rsplit("_", 1)[0] + "_")]
            if flows:
                return max(flows)
        if name.startswith("disc_"):
            # a missing (observable, dimension) pair from the others: separable a_o × b_d, and
            # never below the other observable's coefficient in the same dimension
            _, obs, dim = name.split("_")
            other_obs = next((o for o in _OBSERVABLE.values() if o != obs), None)
            for other_dim in ("3d", "2d"):
                keys = (f"disc_{obs}_{other_dim}", f"disc_{other_obs}_{dim}",
                        f"disc_{other_obs}_{other_dim}")
                if other_dim != dim and all(k in self.coefficients for k in keys) \
                        and self.coefficients[keys[2]] > 0:
                    c = self.coefficients
                    return max(c[keys[0]] * c[keys[1]] / c[keys[2]], c[keys[1]])
        raise InputError("error model", f"no measured coefficient for '{name}': the model was "
                         f"fitted on {', '.join(sorted(self.coefficients))}")

    def terms(self, d: Drivers) -> dict[str, float]:
        """Each contribution to the (uninflated) expected error bound [1]."""
        return {name: self._coefficient(name) * value
                for name, value in _features(d, self.exponents).items()}

    def inflation_of(self, d: Drivers) -> float:
        """The inflation [1] applied to ``d``: its class's, else the global one."""
        return self.class_inflation.get(inflation_class(d), self.inflation)

    def expected_error(self, d: Drivers) -> float:
        """Inflated expected error bound [1] (module docstring)."""
        return self.inflation_of(d) * sum(self.terms(d).values())

    def expected_cost(self, d: Drivers) -> float:
        """Expected CPU time of one thread [s]."""
        return self.cost[f"k_{d.dimension}d"] * d.work ** self.cost["alpha"]

    def in_domain(self, d: Drivers) -> bool:
        """Every driver inside its measured range (training data), q outside the gap; the
        time step only bounded above (a smaller one is never less accurate), by the measured
        range of the same flow and dimension or else the tightest one of the dimension; the
        channel's Bingham number only above (the yield term is measured up to the largest
        trained Bn and is not extrapolated)."""
        if not regular(d):
            return False
        for name, value in _bounded(d).items():
            lo, hi = self._range(name, d.dimension)
            if name.startswith(_STEP_KEYS) or name == "bingham_poiseuille":
                # a smaller step, or a weaker yield stress (Bn = 0: Newtonian), is inside
                lo = 0.0
            if not lo * (1 - 1e-9) <= value <= hi * (1 + 1e-9):
                return False
        return True

    def _range(self, name: str, dimension: int) -> tuple[float, float]:
        """The measured range of a driver; for a per-flow driver (resolution, time step) not
        measured in this flow, the intersection of the other flows' ranges in the dimension;
        (inf, -inf) if none."""
        if name in self.bounds:
            return tuple(self.bounds[name])
        prefix = name.split("_")[0]
        others = [v for k, v in self.bounds.items()
                  if k.startswith(prefix + "_") and k.endswith(f"_{dimension}d")
                  and prefix in ("resolution",) + _STEP_PREFIXES]
        if prefix in _STEP_PREFIXES and not name.split("_")[2] == "newtonian":
            # a rate-dependent law without its own measured range: the tightest
            others = [min(others, key=lambda v: v[1])] if others else []
        if not others:
            return math.inf, -math.inf
        return max(lo for lo, _ in others), min(hi for _, hi in others)

    def to_json(self) -> dict[str, Any]:
        return {"format": FORMAT, "coefficients": self.coefficients,
                "exponents": self.exponents, "inflation": self.inflation,
                "class_inflation": self.class_inflation, "bounds": self.bounds,
                "cost": self.cost, "residuals": self.residuals, "provenance": self.provenance}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> "ErrorModel":
        """The model of ``data`` (format 1, without ``class_inflation``, or 2)."""
        if data.get("format", 1) not in (1, FORMAT):
            raise ValueError(f"format {data['format']!r} is not 1 or {FORMAT}")
        return cls(dict(data["coefficients"]), dict(data["exponents"]), float(data["inflation"]),
                   {k: list(v) for k, v in data["bounds"].items()}, dict(data["cost"]),
                   dict(data.get("provenance", {})), dict(data.get("residuals", {})),
                   {k: float(v) for k, v in data.get("class_inflation", {}).items()})


def inflation_class(d: Drivers) -> str:
    """The class of ``d`` that shares an inflation: its flow and dimension (module
    docstring)."""
    return f"{d.flow}_{d.dimension}d"


def class_maxima(ratios: Sequence[float], classes: Sequence[str]) -> dict[str, float]:
    """The largest of ``ratios`` [1] in each of ``classes`` (one class per ratio)."""
    out: dict[str, float] = {}
    for ratio, cls in zip(ratios, classes):
        out[cls] = max(out.get(cls, -math.inf), float(ratio))
    return out


def regular(d: Drivers) -> bool:
    """q outside :data:`RESOLUTION_GAP` and, in the split-force channel, an even number of
    lattice rows across L_y, so each half (force +g, −g) holds whole rows: odd counts put a
    row on the force's sign change and measured 11–18 % (2D, q = 2.5 and 3) against ≤ 1.6 %
    at the neighbouring even counts, or blew up; and a sheared width ℓ of at least
    :data:`MIN_SHEARED_WIDTH`."""
    if RESOLUTION_GAP[0] < d.resolution < RESOLUTION_GAP[1]:
        return False
    return d.flow != "poiseuille" or (d.rows % 2 == 0 and d.length >= MIN_SHEARED_WIDTH)


def _step_class(d: Drivers) -> str:
    """Flow, dimension and law class of the time-step range: a rate-dependent viscosity is
    stiffer (a viscous-limited Papanastasiou Couette run was 21 % off at the C_Δx = 0.51 a
    Newtonian one ran within 0.3 %)."""
    return f"{d.flow}_{'newtonian' if d.newtonian else 'rate_dependent'}_{d.dimension}d"


def _bounded(d: Drivers) -> dict[str, float]:
    """The drivers whose measured range limits the model, keyed as in ``bounds``."""
    out = {f"resolution_{d.flow}_{d.dimension}d": d.resolution,
           f"inverse_length_{d.flow}": 1 / d.length,
           "wi": d.wi, f"courant_{_step_class(d)}": d.courant,
           f"stepsupport_{_step_class(d)}": d.courant / d.resolution ** 2}
    if d.units > 0:
        out["units"] = d.units
    if d.flow == "poiseuille":
        out["bingham_poiseuille"] = d.bingham
    return out


@functools.lru_cache(maxsize=1)
def load_model(path: str | None = None) -> ErrorModel:
    """The model at ``path``, or the packaged one (:data:`MODEL_FILE`)."""
    if path is None:
        text = resources.files("suspsim.convergence").joinpath(MODEL_FILE).read_text("utf-8")
        source = f"suspsim/convergence/{MODEL_FILE}"
    else:
        try:
            text, source = Path(path).read_text(encoding="utf-8"), str(path)
        except OSError as err:
            raise InputError(path, f"cannot read the error model: {err.strerror}") from None
    try:
        return ErrorModel.from_json(json.loads(text))
    except (ValueError, KeyError) as err:
        raise InputError(source, f"not an error model: {err}") from None


# ---------------------------------------------------------------------------------------------
# Fitting


def training_points(datasets: Sequence[xr.Dataset]
                    ) -> list[tuple[Drivers, float, float, str]]:
    """(drivers, measured error bound [1], CPU time [s], case name) of every configuration in
    the modelled domain (lucy, jitter 0.1, 1e-3 ≤ Wi ≤ 0.01, q on the grid's range and outside
    the gap, Couette with ≥ 2 averaged units so a standard error exists); a run that blew up
    has NaN bound and cost (the 2D channel at Re = 0.5, q = 2.5, W = 7.5 h, C_Δx = 0.67)."""
    out = []
    for ds in datasets:
        case = get_case(ds.attrs["case"])
        if not isinstance(case, Case):
            continue
        for i in range(ds.sizes["configuration"]):
            row = ds.isel(configuration=i)
            bound, cpu = float(row["error_bound"]), float(row["cpu_time"])
            settings = {a.name: _value(row[a.name].item(), a.default) for a in case.axes}
            if any(settings[k] != v for k, v in FIXED.items()):
                continue
            if not GRID["wi_target"][0] <= settings["wi_target"] <= GRID["wi_target"][-1]:
                continue
            d = drivers(case.build(settings), settings)
            if not regular(d) or d.resolution < 0.9 * min(GRID["resolution"][d.dimension]):
                continue
            if d.flow == "couette" and d.units < 2:
                continue
            out.append((d, bound, cpu, case.name))
    return out


def _value(value, default):
    if isinstance(default, bool) or isinstance(default, str):
        return value
    return int(value) if isinstance(default, int) else float(value)


def fit_coefficients(points: Sequence[tuple[Drivers, float]], exponents: Mapping[str, float],
                     expectile: float = EXPECTILE, iterations: int = 20
                     ) -> tuple[dict[str, float], float]:
    """Non-negative coefficients minimising Σ w_i ((model_i − y_i)/y_i)² at fixed
    ``exponents``, w_i = ``expectile`` where the model is below y_i and 1 − ``expectile``
    elsewhere (iteratively reweighted NNLS); and that loss."""
    from scipy.optimize import nnls

    rows = [_features(d, exponents) for d, _ in points]
    names = sorted({k for row in rows for k in row})
    y = np.array([bound for _, bound in points])
    a = np.array([[row.get(n, 0.0) for n in names] for row in rows]) / y[:, None]
    weights = np.full(len(y), 0.5)
    for _ in range(iterations):
        root = np.sqrt(weights)
        coef, _ = nnls(a * root[:, None], root)
        residual = a @ coef - 1.0
        new = np.where(residual < 0, expectile, 1.0 - expectile)
        if np.array_equal(new, weights):
            break
        weights = new
    loss = float(np.sum(weights * residual ** 2))
    return dict(zip(names, map(float, coef))), loss


def envelope_score(model: "ErrorModel", pairs: Sequence[tuple[Drivers, float]]) -> float:
    """Mean log over-prediction [1] of the model inflated per class to bound every point of
    its class (:func:`inflation_class`): mean_i log(max_(j in class i)(y_j/m_j) / (y_i/m_i));
    smaller is a tighter upper envelope."""
    ratios = np.array([bound / sum(model.terms(d).values()) for d, bound in pairs])
    classes = [inflation_class(d) for d, _ in pairs]
    top = class_maxima(ratios, classes)
    return float(np.mean(np.log(np.array([top[c] for c in classes]) / ratios)))


def _fit_exponents(pairs: Sequence[tuple[Drivers, float]],
                   grid: Mapping[str, Sequence[float]] | None = None
                   ) -> tuple[dict[str, float], dict[str, float], float]:
    """Coefficients (expectile NNLS) at each exponent combination of ``grid`` (default
    :data:`EXPONENTS`); the combination whose inflated model is the tightest envelope
    (:func:`envelope_score`) wins."""
    grid = EXPONENTS if grid is None else grid
    best = None
    for combo in itertools.product(*grid.values()):
        exponents = dict(zip(grid, combo))
        coef, _ = fit_coefficients(pairs, exponents)
        score = envelope_score(ErrorModel(coef, exponents, 1.0, {}, {}), pairs)
        if best is None or score < best[2] - 1e-12:
            best = (coef, exponents, score)
    return best


def fit(datasets: Sequence[xr.Dataset], provenance: Mapping[str, Any] | None = None
        ) -> ErrorModel:
    """The error and cost models fitted on ``datasets`` (case files of :mod:`.study`):
    :func:`fit_points` on their :func:`training_points`."""
    return fit_points(training_points(datasets), provenance)


def fit_points(points: Sequence[tuple[Drivers, float, float, str]],
               provenance: Mapping[str, Any] | None = None, *,
               cross_validate: bool = True) -> ErrorModel:
    """The model fitted in sample (:func:`fit_in_sample`) on ``points`` ((drivers, bound [1],
    CPU [s], case name)), its per-class inflation raised to the leave-one-case-out bound
    (:func:`cross_validated_inflation`) unless ``cross_validate`` is false, and the time step's
    stability margin (:func:`stability_margin`) applied to its C_Δx ranges."""
    model = fit_in_sample(points)
    model.residuals["in_sample_class_inflation"] = dict(model.class_inflation)
    if cross_validate:
        held = held_out_ratios(points, model.exponents)
        model.class_inflation = cross_validated_inflation(model.class_inflation, held)
        model.inflation = max(model.class_inflation.values())
        model.residuals["held_out"] = {
            c: {"points": len(r), "cases": len({case for _, case in r}),
                "max_ratio": max(x for x, _ in r), "median_ratio": float(np.median(
                    [x for x, _ in r])), "max_case": max(r)[1]}
            for c, r in sorted(held.items())}
    model.provenance = {**dict(provenance or {}), **model.provenance,
                        "inflation_method": ("leave-one-case-out" if cross_validate
                                             else "in-sample")}
    return model


def fit_in_sample(points: Sequence[tuple[Drivers, float, float, str]],
                  grid: Mapping[str, Sequence[float]] | None = None) -> ErrorModel:
    """The error and cost models fitted on ``points`` ((drivers, bound [1], CPU [s], case
    name)), the exponents searched on ``grid`` (default :data:`EXPONENTS`), each class
    inflated by its largest in-sample measured/model ratio.

    A run that blew up inside the domain while the same geometry (flow, dimension, q, ℓ,
    units, Bn) finished at a smaller time step, or whose measured bound exceeds
    :data:`OUTLIER_RATIO` × the first fit while the same geometry ran within it at a smaller
    time step, is put down to the time step: it is left
    out of the fit and caps the domain's C_Δx (per flow and dimension) below its own (a
    measured stability/accuracy bound). Other runs all count, so the inflation covers them."""
    finished = [(d, bound, cpu) for d, bound, cpu, _ in points
                if math.isfinite(bound) and math.isfinite(cpu)]
    if len(finished) < 8:
        raise InputError("error model", f"{len(finished)} usable measurements; need at least 8")
    coef, exponents, _ = _fit_exponents([(d, b) for d, b, _ in finished], grid)
    first = ErrorModel(coef, exponents, 1.0, {}, {})
    def within(d, bound):
        return math.isfinite(bound) and bound <= OUTLIER_RATIO * sum(first.terms(d).values())

    def geometry(d):
        return (d.flow, d.dimension, round(d.resolution, 6), round(d.length, 6), d.units,
                round(d.bingham, 6))

    # the smallest step at which each geometry ran within the first fit; for a blow-up, ran
    # at all (a blow-up is the step's whether or not the finished runs fit well)
    calm, finished_at = {}, {}
    for d, bound, _, _ in points:
        if within(d, bound):
            calm[geometry(d)] = min(calm.get(geometry(d), math.inf), d.courant)
        if math.isfinite(bound):
            finished_at[geometry(d)] = min(finished_at.get(geometry(d), math.inf), d.courant)
    unsafe: dict[str, float] = {}
    failures: list[tuple[str, float, bool]] = []
    inliers = []
    for d, bound, cpu, _ in points:
        ran_smaller = (calm if math.isfinite(bound) else finished_at).get(geometry(d), math.inf)
        if within(d, bound) or ran_smaller >= d.courant:
            if math.isfinite(bound):
                inliers.append((d, bound, cpu))
        else:
            key = _step_class(d)
            unsafe[key] = min(unsafe.get(key, math.inf), d.courant)
            failures.append((key, d.courant, not math.isfinite(bound)))
    pairs = [(d, bound) for d, bound, _ in inliers]
    coef, exponents, score = _fit_exponents(pairs, grid)
    model = ErrorModel(coef, exponents, 1.0, {}, {})
    ratios = np.array([bound / sum(model.terms(d).values()) for d, bound in pairs])
    model.inflation = float(max(1.0, ratios.max()))
    classes = np.array([inflation_class(d) for d, _ in pairs])
    model.class_inflation = {c: max(1.0, r) for c, r in sorted(
        class_maxima(ratios, classes.tolist()).items())}
    model.residuals = {"n_points": len(pairs), "n_left_out": len(points) - len(pairs),
                       "envelope_score": score, "median_ratio": float(np.median(ratios)),
                       "max_ratio": float(ratios.max()), "min_ratio": float(ratios.min()),
                       "class_points": {c: int(np.sum(classes == c))
                                        for c in model.class_inflation},
                       "class_median_ratio": {c: float(np.median(ratios[classes == c]))
                                              for c in model.class_inflation}}
    for d, _ in pairs:
        if d.courant >= unsafe.get(_step_class(d), math.inf):
            continue
        for name, value in _bounded(d).items():
            lo, hi = model.bounds.get(name, [math.inf, -math.inf])
            model.bounds[name] = [min(lo, value), max(hi, value)]
    margin = stability_margin([d for d, _ in pairs], failures)
    model.bounds = {k: ([lo, hi * margin] if k.startswith(_STEP_KEYS) else [lo, hi])
                    for k, (lo, hi) in model.bounds.items()}
    model.cost = fit_cost([(d, cpu) for d, _, cpu in inliers])
    model.provenance = {"unsafe_courant": unsafe, "courant_margin": margin}
    return model


def held_out_ratios(points: Sequence[tuple[Drivers, float, float, str]],
                    exponents: Mapping[str, float] | None = None
                    ) -> dict[str, list[tuple[float, str]]]:
    """Leave-one-case-out ratios: for each case, :func:`fit_in_sample` on the other cases'
    points, and the measured/model ratio (uninflated) of each finished point of the left-out
    case that this fold's model would let the picker use (inside its domain) and whose class
    the fold still holds (a class's inflation is only applied where the class has training
    points); per class, (ratio [1], case) of every such point. With ``exponents`` (the full
    fit's) a fold searches only the exponents within one step of them on :data:`EXPONENTS`
    (:func:`neighbouring_exponents`; the full search takes 75 s CPU per fit)."""
    grid = None if exponents is None else neighbouring_exponents(exponents)
    out: dict[str, list[tuple[float, str]]] = {}
    for case in sorted({c for *_, c in points}):
        rest = [p for p in points if p[3] != case]
        if len({c for *_, c in rest}) < 2:
            continue
        try:
            fold = fit_in_sample(rest, grid)
        except InputError:
            continue
        for d, bound, _, c in points:
            if c != case or not math.isfinite(bound) or not fold.in_domain(d) \
                    or inflation_class(d) not in fold.class_inflation:
                continue
            try:
                model = sum(fold.terms(d).values())
            except InputError:
                continue
            out.setdefault(inflation_class(d), []).append((bound / model, case))
    return out


def neighbouring_exponents(exponents: Mapping[str, float]) -> dict[str, tuple[float, ...]]:
    """Per exponent, its value and its neighbours on :data:`EXPONENTS`."""
    out = {}
    for name, values in EXPONENTS.items():
        i = values.index(exponents[name])
        out[name] = tuple(values[max(0, i - 1):i + 2])
    return out


def cross_validated_inflation(in_sample: Mapping[str, float],
                              held: Mapping[str, Sequence[tuple[float, str]]]
                              ) -> dict[str, float]:
    """Per class, the larger of the in-sample inflation (the floor: the model still bounds
    every training point) and the largest held-out ratio of :func:`held_out_ratios`."""
    return {c: max(v, max((r for r, _ in held.get(c, ())), default=v))
            for c, v in in_sample.items()}


def stability_margin(inliers: Sequence[Drivers], failures: Sequence[tuple[str, float, bool]]
                     ) -> float:
    """Factor [1] (≤ 1) on the upper end of every C_Δx range: the smallest ratio, over the
    blow-ups among the time-step ``failures`` ((step class, C_Δx [1], blew up) of the runs
    that cap their class), of the blow-up's C_Δx to the edge of the calm range its class would
    have without it: the largest C_Δx of the class's fitted (``inliers``) runs below the
    class's other failures. 1 without a blow-up inside its calm range. A blow-up below the
    calm runs of other cases of its class means the edge of the calm range is not a
    stability edge for a new case (module docstring)."""
    margin = 1.0
    for i, (key, courant, blew_up) in enumerate(failures):
        if not blew_up:
            continue
        cap = min((c for j, (k, c, _) in enumerate(failures) if k == key and j != i),
                  default=math.inf)
        calm = [d.courant for d in inliers if _step_class(d) == key and d.courant < cap]
        if calm:
            margin = min(margin, courant / max(calm))
    return margin


def fit_cost(points: Sequence[tuple[Drivers, float]]) -> dict[str, float]:
    """log cpu = log k_d + α log(N q^d n_steps), least squares; k per dimension."""
    dims = sorted({d.dimension for d, _ in points})
    a = np.array([[math.log(d.work)] + [float(d.dimension == k) for k in dims]
                  for d, _ in points])
    y = np.log([cpu for _, cpu in points])
    sol, *_ = np.linalg.lstsq(a, y, rcond=None)
    resid = y - a @ sol
    out = {"alpha": float(sol[0]), "rms_log": float(np.sqrt(np.mean(resid ** 2)))}
    out.update({f"k_{k}d": float(math.exp(c)) for k, c in zip(dims, sol[1:])})
    return out


# ---------------------------------------------------------------------------------------------
# The picker


@dataclass(frozen=True)
class Choice:
    """The picked ``settings`` (a case's full settings), their ``drivers``, ``expected_error``
    [1] (inflated bound), ``expected_cost`` [s CPU], the error ``terms`` and the other
    candidates that met the target (settings, expected error, expected cost), cheapest
    first."""

    settings: dict[str, Any]
    drivers: Drivers
    expected_error: float
    expected_cost: float
    terms: dict[str, float]
    tolerance: float
    feasible: list[tuple[dict[str, Any], float, float]]


def candidate_settings(case: Case, dimension: int) -> list[dict[str, Any]]:
    """Every grid combination of the case's axes (others at their defaults, :data:`FIXED`)."""
    names = [a.name for a in case.axes if a.name in GRID]
    values = [GRID[n][dimension] if n == "resolution" else GRID[n] for n in names]
    return [case.settings({**FIXED, **dict(zip(names, combo))})
            for combo in itertools.product(*values)]


def evaluate(case: Case, model: ErrorModel, *, dimension: int | None = None
             ) -> list[tuple[dict[str, Any], Drivers, float, float]]:
    """(settings, drivers, expected error, expected cost) of every in-domain candidate; each
    geometry is built once and the time-step settings varied on it."""
    dimension = dimension or case.build(case.settings()).dimension
    numerics = {"dt_coefficient": "dt_viscous_coefficient", "wi_target": "wi_target"}
    groups: dict[str, list[dict[str, Any]]] = {}
    for settings in candidate_settings(case, dimension):
        key = json.dumps({k: v for k, v in settings.items() if k not in numerics},
                         sort_keys=True)
        groups.setdefault(key, []).append(settings)
    out = []
    for members in groups.values():
        variants = [{numerics[k]: float(m[k]) for k in numerics} for m in members]
        for settings, d in zip(members, _numerics_variants(case.build(members[0]), members[0],
                                                           variants)):
            if model.in_domain(d):
                out.append((settings, d, model.expected_error(d), model.expected_cost(d)))
    return out


def pick(case: Case, tolerance: float, model: ErrorModel | None = None, *,
         safety: float = SAFETY) -> Choice:
    """The cheapest candidate whose expected error ≤ ``safety`` × ``tolerance``; an InputError
    names the smallest reachable error when none does."""
    if not (isinstance(tolerance, (int, float)) and 0 < tolerance < 1):
        raise InputError("--tolerance", f"must be a relative error in (0, 1), got {tolerance!r}")
    model = model or load_model()
    rows = evaluate(case, model)
    if not rows:
        raise InputError("--tolerance", f"{case.name}: no configuration of the grid lies in "
                         "the error model's measured range")
    ok = sorted((r for r in rows if r[2] <= safety * tolerance), key=lambda r: r[3])
    if not ok:
        best = min(r[2] for r in rows)
        raise InputError("--tolerance", f"{case.name}: tolerance {tolerance:g} is not reachable "
                         f"within the modelled grid; the smallest expected error is {best:.3g} "
                         f"(needs ≤ {safety:g} × tolerance)")
    settings, d, error, cost = ok[0]
    return Choice(settings, d, error, cost, model.terms(d), float(tolerance),
                  [(s, e, c) for s, _, e, c in ok])


# ---------------------------------------------------------------------------------------------
# Command line


def _fit_command(out: str, files: Sequence[str]) -> int:
    datasets = [xr.load_dataset(f) for f in files]
    command = "python -m suspsim.convergence.error_model fit " + " ".join([out, *files])
    model = fit(datasets, {
        "datasets": [str(f) for f in files],
        "training_cases": sorted({ds.attrs["case"] for ds in datasets}),
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d"),
        "command": command})
    Path(out).write_text(json.dumps(model.to_json(), indent=1, sort_keys=True) + "\n",
                         encoding="utf-8")
    print(json.dumps({k: model.to_json()[k] for k in
                      ("coefficients", "exponents", "inflation", "class_inflation",
                       "residuals", "cost")}, indent=1))
    return 0


def _pick_command(case_name: str, tolerance: str) -> int:
    choice = pick(get_case(case_name), float(tolerance))
    print(json.dumps({"settings": choice.settings, "expected_error": choice.expected_error,
                      "expected_cost_s": choice.expected_cost, "terms": choice.terms,
                      "n_particles": choice.drivers.n_particles,
                      "n_steps": choice.drivers.n_steps}, indent=1))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        if len(argv) >= 3 and argv[0] == "fit":
            return _fit_command(argv[1], argv[2:])
        if len(argv) == 3 and argv[0] == "pick":
            return _pick_command(argv[1], argv[2])
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 1
    print(__doc__.split("Commands::")[1], file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
