"""Analytic and quadrature reference solutions that SPH validation and plots compare against.

* :mod:`~suspsim.reference.shear` — simple (Lees–Edwards Couette) shear and the inverse flow
  curve γ̇(τ) of any law of SPEC §1.1 (SPEC §6.1).
* :mod:`~suspsim.reference.poiseuille` — plane Poiseuille flow, its flux, the split-force
  periodic set-up of SPEC §2.7 and the channel Bingham number (SPEC §6.2).
* :mod:`~suspsim.reference.couette_startup` — start-up of Couette flow from rest (the
  Lees–Edwards box of seed 000 Fig. 1): 1D finite volumes for any law, Newtonian series.
* :mod:`~suspsim.reference.dst_channel` — steady local Wyart–Cates channel flow (SPEC §5.7).
* :mod:`~suspsim.reference.inverse_biviscous` — inverse-biviscous DST flow curve (rate plateau)
  and its channel flow, the comparison model of seed 002 Fig. 8.
"""
from suspsim.reference.couette_startup import couette_startup, newtonian_couette_startup
from suspsim.reference.poiseuille import (bingham_number, force_density_for_bingham,
                                          poiseuille_flow_rate, poiseuille_profile,
                                          split_force_poiseuille_profile)
from suspsim.reference.shear import (couette_velocity_profile, inverse_stress,
                                     simple_shear_stress)

__all__ = [
    "bingham_number", "couette_startup", "couette_velocity_profile", "force_density_for_bingham",
    "inverse_stress", "newtonian_couette_startup", "poiseuille_flow_rate", "poiseuille_profile",
    "simple_shear_stress", "split_force_poiseuille_profile",
]
