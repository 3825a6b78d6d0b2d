"""Pressure: linear equation of state and the symmetric pressure pair force (SPEC §2.2).

Symbols:

====== ================================================= ==============
symbol meaning                                           unit
====== ================================================= ==============
P      pressure                                          [m h^(2−d) τ^−2]
ρ      summation density m Σ_q W                         [m h^−d]
ρ_eq   nominal density N m / V (not the running mean)    [m h^−d]
c      artificial sound speed                            [h τ^−1]
m      particle mass                                     [m]
F      kernel factor −W'(r)/r                            [h^−(d+2)]
====== ================================================= ==============
"""
from __future__ import annotations

from numba import njit

from suspsim.sph import JIT_OPTIONS


@njit(inline="always", **JIT_OPTIONS)
def equation_of_state(rho, rho_eq, c2):
    """P = c² (ρ − ρ_eq) [SPEC §2.2; ρ_eq = N m/V as the probe found, not the mean of ρ]."""
    return c2 * (rho - rho_eq)


@njit(inline="always", **JIT_OPTIONS)
def pressure_term(rho, rho_eq, c2, mass):
    """m² P/ρ², one particle's share of the pressure pair force (:func:`pressure_pair`)."""
    return mass * mass * equation_of_state(rho, rho_eq, c2) / (rho * rho)


@njit(inline="always", **JIT_OPTIONS)
def pressure_pair(term_i, term_j, f):
    """Scalar k with force f_ij = k r_ij on i from j: k = m² (P_i/ρ_i² + P_j/ρ_j²) F(r_ij),
    from the particles' :func:`pressure_term`.

    Seed 000 Eq. 18 (times m): dv_i/dt = m Σ_j (P_i/ρ_i² + P_j/ρ_j²) F r_ij; antisymmetric in
    (i, j) because r_ji = −r_ij.
    """
    return (term_i + term_j) * f
