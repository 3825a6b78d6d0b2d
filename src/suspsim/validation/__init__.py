"""Validation computations: SPH runs paired with their continuum references, as datasets.

* :mod:`~suspsim.validation.startup` — start-up of Lees–Edwards Couette flow of a
  Papanastasiou fluid from rest (seed 000 Fig. 1) against the 1D finite-volume solution of
  :mod:`suspsim.reference.couette_startup`.
"""
