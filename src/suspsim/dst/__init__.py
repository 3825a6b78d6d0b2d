"""Wall-bounded SPH for discontinuous shear thickening in 2D and 3D (seed 002; SPEC §1.3, §5).

A solver separate from the periodic Lees–Edwards one of :mod:`suspsim.sph`: Morris viscous
operator, Tait EOS with background pressure, Adami dummy-particle walls, predictor–corrector,
and a Wyart–Cates microstructure f per particle. Walls lie at y = 0 and y = L_y; x is periodic,
and in 3D (``Geometry(..., n_z=...)``, scenes with ``dimension: 3``) z as well. The 2D and 3D
runs share every module; the pair passes and the neighbour list have a 3D form each.

- :mod:`~suspsim.dst.parameters`: fluid (``eta_s, phi, phi_m, phi_0, sigma_star, beta, K_f,
  alpha``), geometry, flows (:class:`StressCouette`, :class:`Channel`), numerics;
- :mod:`~suspsim.dst.terms`: one compiled function per equation (EOS, continuity, pressure,
  Morris viscous, Laplacian, γ̇, Maron–Pierce viscosity, microstructure rate);
- :mod:`~suspsim.dst.neighbours`: full CSR list, x (and z) periodic, y bounded;
- :mod:`~suspsim.dst.passes`: wall pass (Adami 2012) and fluid pass;
- :mod:`~suspsim.dst.integrator`: rate evaluation, step size, predictor–corrector, shifting;
- :mod:`~suspsim.dst.simulation`: :class:`DSTSimulation` (advance, sample, profiles,
  snapshot, branch statistics, state/restore);
- :mod:`~suspsim.dst.scene` and :mod:`~suspsim.dst.run`: DST scene files and their
  ``suspsim run`` (the run loop of :mod:`suspsim.run`);
- :mod:`~suspsim.dst.study`: stress-controlled flow curves;
- :mod:`~suspsim.dst.channel_study`: channel flow against driving force (Fig. 7–8).
"""
from suspsim.dst.parameters import Channel, Geometry, Numerics, StressCouette, WyartCatesFluid
from suspsim.dst.simulation import DSTSimulation

__all__ = ["Channel", "DSTSimulation", "Geometry", "Numerics", "StressCouette",
           "WyartCatesFluid"]
