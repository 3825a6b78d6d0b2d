"""Start-up of plane Couette flow of a generalized-Newtonian fluid from rest (seed 000 Fig. 1).

The SPH start-up of SPEC §2.7 shears a periodic box of height L with Lees–Edwards faces: a fluid
at rest whose images above and below move at ±V, V = γ̇ L. The velocity obeys

    ρ ∂u/∂t = ∂/∂y (μ(|∂u/∂y|) ∂u/∂y),      u(y + L, t) = u(y, t) + V,      u(y, 0) = 0,

with the shear stress continuous across the faces. The deviation w = u − γ̇ (y − L/2) is
periodic and starts as a sawtooth that is odd about y = 0 and about y = L/2; the equation keeps
both symmetries (the stress is an odd function of ∂u/∂y), so w = 0 on both planes for all
t > 0. The Lees–Edwards problem on [0, L) is therefore exactly plane Couette flow between walls
at y = 0 and y = L moving at −V/2 and +V/2 (:func:`couette_startup`).

Newtonian check [derived; separation of variables, ν = μ/ρ]: only the even sine modes of the
initial deviation are present,

    u(y, t) = V (y/L − 1/2) + Σ_{k≥1} (V/(kπ)) sin(2kπ y/L) exp(−4k²π² ν t/L²)

(:func:`newtonian_couette_startup`); the slowest mode decays with time constant L²/(4π²ν).

Numerics of :func:`couette_startup`: finite volumes of width Δ = L/N (cell means u_i, N cells),
face stresses τ((u_{i+1} − u_i)/Δ) with τ(γ̇) = μ(|γ̇|) γ̇ and half-cell gradients at the walls
(second order in Δ), integrated in time by SciPy's variable-order BDF with a tridiagonal
Jacobian sparsity: the zero-rate viscosity of a regularised yield-stress fluid makes the
problem too stiff for an explicit step. Bins of the SPH profile that contain whole cells are
compared exactly with cell means (:func:`bin_means`).

Symbols (SI units; any consistent units work the same way in simulation units):

========= ================================================== =========
symbol    meaning                                            unit
========= ================================================== =========
ρ         (density) mass density                             kg/m³
L         (gap) box height, wall-to-wall distance            m
V         (wall_speed) velocity jump across the box, γ̇ L     m/s
γ̇         imposed shear rate V/L                             1/s
y         height from the lower face/wall                    m
u         velocity along x                                   m/s
μ, ν      viscosity of the law (SPEC §1.1), μ/ρ              Pa s, m²/s
Δ, N      cell width L/N, number of cells                    m, 1
========= ================================================== =========
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.sparse import diags

from suspsim.errors import NumericalError
from suspsim.reference.shear import simple_shear_stress
from suspsim.rheology.laws import ConstitutiveLaw

#: Default number of finite-volume cells across the gap.
DEFAULT_CELLS = 480


def _check(density: float, gap: float, wall_speed: float, times) -> np.ndarray:
    if not (np.isfinite(density) and density > 0):
        raise ValueError(f"density must be > 0 kg/m³, got {density!r}")
    if not (np.isfinite(gap) and gap > 0):
        raise ValueError(f"gap must be > 0 m, got {gap!r}")
    if not np.isfinite(wall_speed):
        raise ValueError(f"wall speed must be finite, got {wall_speed!r} m/s")
    t = np.atleast_1d(np.asarray(times, dtype=float))
    if t.ndim != 1 or np.any(t < 0) or np.any(np.diff(t) < 0):
        raise ValueError("times must be a 1-D, non-decreasing sequence of values ≥ 0 s")
    return t


def cell_centres(gap: float, cells: int = DEFAULT_CELLS) -> np.ndarray:
    """Centres (i + ½) L/N [m] of the N finite-volume cells of :func:`couette_startup`."""
    return (np.arange(cells) + 0.5) * (gap / cells)


def couette_startup(law: ConstitutiveLaw, density: float, gap: float, wall_speed: float,
                    times, *, cells: int = DEFAULT_CELLS, rtol: float = 1e-8) -> np.ndarray:
    """Cell-mean velocities u [m/s], shape (len(times), cells), of Couette start-up from rest.

    ``law`` the fluid (SPEC §1.1), ``density`` ρ [kg/m³], ``gap`` L [m], ``wall_speed`` V [m/s]:
    walls at y = 0 and y = L move at −V/2 and +V/2 from t = 0 on (module docstring: the same
    flow as the Lees–Edwards box from rest); ``times`` [s] non-decreasing, ≥ 0 (t = 0 gives
    rest). Cell i spans [i, i + 1) L/N (:func:`cell_centres`). ``rtol`` is the BDF integrator's
    relative tolerance; the absolute one is rtol · V.
    """
    t_out = _check(density, gap, wall_speed, times)
    if cells < 2:
        raise ValueError(f"cells must be ≥ 2, got {cells!r}")
    width = gap / cells
    wall = 0.5 * wall_speed

    def rhs(_, u):
        padded = np.concatenate(([-wall], u, [wall]))
        steps = np.diff(padded)
        # The wall values sit half a cell from the outermost centres.
        steps[0] *= 2.0
        steps[-1] *= 2.0
        stress = simple_shear_stress(law, steps / width)
        return np.diff(stress) / (density * width)

    sparsity = diags([1.0, 1.0, 1.0], [-1, 0, 1], shape=(cells, cells))
    result = np.zeros((t_out.size, cells))
    later = t_out > 0
    if np.any(later):
        solution = solve_ivp(rhs, (0.0, t_out[-1]), np.zeros(cells), method="BDF",
                             t_eval=t_out[later], jac_sparsity=sparsity, rtol=rtol,
                             atol=rtol * max(abs(wall_speed), np.finfo(float).tiny))
        if not solution.success:
            raise NumericalError(f"Couette start-up: the BDF integration failed "
                                 f"({solution.message})")
        result[later] = solution.y.T
    return result


def newtonian_couette_startup(viscosity: float, density: float, gap: float, wall_speed: float,
                              times, y) -> np.ndarray:
    """Exact Newtonian start-up u(y, t) [m/s], shape (len(times), len(y)) (module docstring).

    ``viscosity`` μ [Pa s]; other arguments as in :func:`couette_startup`, ``y`` [m] in [0, L].
    The series is summed until its terms fall below 1e−17 V; at t = 0 it returns rest.
    """
    t = _check(density, gap, wall_speed, times)
    heights = np.asarray(y, dtype=float)
    if np.any((heights < 0) | (heights > gap)):
        raise ValueError(f"heights must lie in [0, L = {gap:g}] m")
    rate = 4.0 * np.pi ** 2 * (viscosity / density) / gap ** 2
    out = np.zeros((t.size, heights.size))
    for row, time in enumerate(t):
        if time == 0:
            continue
        # exp(−k² rate t) < 1e−17 beyond this k.
        terms = int(np.ceil(np.sqrt(39.2 / (rate * time)))) + 1
        k = np.arange(1, terms + 1)[:, None]
        modes = (np.sin(2.0 * np.pi * k * heights[None, :] / gap)
                 * (np.exp(-k ** 2 * rate * time) / (k * np.pi)))
        out[row] = wall_speed * (heights / gap - 0.5 + modes.sum(axis=0))
    return out


def bin_means(values: np.ndarray, bins: int) -> np.ndarray:
    """Means over ``bins`` equal bins of the last axis of cell values (cells divisible by bins)."""
    values = np.asarray(values, dtype=float)
    cells = values.shape[-1]
    if bins < 1 or cells % bins:
        raise ValueError(f"{cells} cells do not split into {bins} equal bins")
    return values.reshape(*values.shape[:-1], bins, cells // bins).mean(axis=-1)
