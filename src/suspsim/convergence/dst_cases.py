"""Validation cases of the 2D Wyart–Cates DST solver for the speed-against-error study:

- a flow-curve point (SPEC §1.3, §5.4; :class:`DSTPointCase`): stress control, error
  ⟨γ̇⟩/γ̇_WC − 1;
- the local model's channel (SPEC §5.7; :class:`DSTChannelCase`): error L2/peak against the
  ODE profile.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Mapping

from suspsim.convergence.case_base import Axis, CaseSettings, Run
from suspsim.validation.flows import Reading


@dataclass(frozen=True)
class DSTPointCase(CaseSettings):
    """A stress-controlled Wyart–Cates flow-curve point of the 2D DST solver
    (:func:`suspsim.dst.study.flow_curve`, scaled units η_s = σ* = L_y = 1, seed 002's
    φ_m, φ_0, β and K_f): error ⟨γ̇⟩/γ̇_WC(σ_in) − 1 against the steady Wyart–Cates curve
    (SPEC §1.3), with the batch-means standard error of ⟨γ̇⟩. Axes: the lattice (``n_y``
    particles across the gap, the resolution; ``n_x`` along it), ``epsilon`` (the density
    ε = K_f γ̇ ρ L_y²/η, which sets Re and the viscous step count) and the equilibration and
    averaging strains."""

    name: str
    description: str
    reference: str
    axes: tuple[Axis, ...]
    phi: float
    stress: float
    alpha: float

    def _point(self, settings, threads, equilibration, averaging):
        from suspsim.dst.study import flow_curve

        return flow_curve(self.phi, [self.stress], alpha=self.alpha,
                          lattice=(int(settings["n_x"]), int(settings["n_y"])), threads=threads,
                          epsilon=float(settings["epsilon"]), equilibration_strain=equilibration,
                          averaging_strain=averaging).isel(stress=0)

    def warm_up(self, settings: Mapping[str, Any], threads: int) -> None:
        """A run of 0.02 strain on the same lattice, so compiled code is loaded."""
        self._point(settings, threads, 0.01, 0.01)

    def execute(self, settings: Mapping[str, Any], threads: int) -> Run:
        """Run and read the point of ``settings`` (set-up and run are not timed apart)."""
        t0 = time.perf_counter()
        point = self._point(settings, threads, float(settings["equilibration_strain"]),
                            float(settings["averaging_strain"]))
        rate = float(point["wyart_cates_shear_rate"])
        reading = Reading(float(point["shear_rate"]) / rate - 1.0,
                          float(point["shear_rate_stderr"]) / rate)
        n_y = int(settings["n_y"])
        return Run(reading, int(point.attrs["n_particles"]), int(point["steps"]),
                   float(point["time_step"]), float(point["sound_speed"]), float("nan"),
                   float(n_y), 0.0, time.perf_counter() - t0)


def dst_flow_curve_point(phi: float = 0.54, stress: float = 2.5,
                         alpha: float = 0.02) -> DSTPointCase:
    """φ = 0.54 at σ_in = 2.5 σ* lies on the unstable branch (σ_β = 0.76, σ_α = 3.92);
    α = 0.02 is seed 002's strong non-locality scaled."""
    axes = (Axis("n_y", 20, "1", "fluid particles across the gap (the resolution)"),
            Axis("n_x", 14, "1", "fluid particles along the periodic direction"),
            Axis("epsilon", 0.1, "1", "K_f gdot rho L_y^2/eta, which sets the density"),
            Axis("equilibration_strain", 1.5, "1", "strain gdot_WC t discarded"),
            Axis("averaging_strain", 1.5, "1", "strain gdot_WC t averaged"))
    return DSTPointCase(f"dst_point_phi{phi:g}_sigma{stress:g}_alpha{alpha:g}",
                        f"DST point (2D), phi = {phi:g}, sigma = {stress:g}, alpha = {alpha:g}",
                        "steady Wyart-Cates curve (SPEC 1.3)", axes,
                        phi, stress, alpha)


@dataclass(frozen=True)
class DSTChannelCase(CaseSettings):
    """Channel flow of the local Wyart–Cates model (SPEC §5.7, α = 0) at ``phi`` and driving
    force F H/σ* = ``force_ratio``, the momentum protocol of
    :func:`suspsim.dst.channel_study.channel_sweep` (start from rest with f at its local steady
    value, one momentum time ρ L_y²/η(f = 0)): error L2/peak of the particle velocities against
    the local model's ODE profile, as the validation test. Axes: ``n_y`` (particles across the
    gap), ``n_x`` and ``density`` ρ (the momentum time, so the steps, go with ρ)."""

    name: str
    description: str
    reference: str
    axes: tuple[Axis, ...]
    phi: float
    force_ratio: float

    def _channel(self, settings, threads, lattice=None):
        from suspsim.dst.channel_study import channel_sweep

        lattice = lattice or (int(settings["n_x"]), int(settings["n_y"]))
        return channel_sweep(self.phi, [self.force_ratio], lattice=lattice, threads=threads,
                             density=float(settings["density"])).isel(force_ratio=0)

    def warm_up(self, settings: Mapping[str, Any], threads: int) -> None:
        """A 13 × 6 channel (the smallest periodic lattice), so compiled code is loaded."""
        self._channel(settings, threads, lattice=(13, 6))

    def execute(self, settings: Mapping[str, Any], threads: int) -> Run:
        """Run and read the channel of ``settings`` (set-up and run are not timed apart)."""
        t0 = time.perf_counter()
        flow = self._channel(settings, threads)
        return Run(Reading(float(flow["velocity_l2_error"]), float("nan")),
                   int(flow.attrs["n_particles"]), int(flow["steps"]), float("nan"),
                   float(flow["sound_speed"]), float("nan"), float(settings["n_y"]), 0.0,
                   time.perf_counter() - t0)


def dst_channel(phi: float = 0.54, force_ratio: float = 10.0) -> DSTChannelCase:
    """The validation's channel: φ = 0.54, F H/σ* = 10 (a shear-thickened wall layer)."""
    axes = (Axis("n_y", 20, "1", "fluid particles across the gap (the resolution)"),
            Axis("n_x", 14, "1", "fluid particles along the periodic direction"),
            Axis("density", 1.0, "sigma_star L_y2 eta_s-2", "density rho, which sets the "
                 "momentum time rho L_y^2/eta(0) run"))
    return DSTChannelCase(f"dst_channel_phi{phi:g}_force{force_ratio:g}",
                          f"DST channel (2D, local), phi = {phi:g}, F H/sigma* = {force_ratio:g}",
                          "local Wyart-Cates channel ODE (SPEC 5.7)", axes, phi, force_ratio)
