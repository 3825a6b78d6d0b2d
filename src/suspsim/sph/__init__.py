"""Smoothed-particle hydrodynamics of variable-viscosity fluids (SPEC §2; Martys et al. 2010).

Foundation of the solver, built for speed (numba, one or two cores):

- :mod:`~suspsim.sph.kernels`: Lucy and quintic-spline kernels W(r), F(r) = −W'(r)/r and the
  integer codes that select them inside compiled loops;
- :mod:`~suspsim.sph.boundaries`: periodic and Lees–Edwards minimum image, wrap and image
  velocity (SPEC §2.7);
- :mod:`~suspsim.sph.neighbours`: cell sort, CSR half Verlet list with skin (split into pairs
  inside the box and pairs across a face), rebuild criterion that discounts affine shear;
- :mod:`~suspsim.sph.chunks`: helpers for race-free parallel pair passes over a half list;
- :mod:`~suspsim.sph.density`: summation density (SPEC §2.2), the reference pair pass, which
  also writes the step's pair table (j, r_ij, F, LE image index) for the later passes;
- :mod:`~suspsim.sph.bench_density`: hand-run benchmark of list build and density pass.

Conventions: positions, velocities are (N, 3) float64 (a 2D scene keeps z ≡ 0); the box is
[0, L_x) × [0, L_y) × [0, L_z), x the flow and y the gradient direction; h is the kernel's
support radius.
"""

#: Compilation options of the hot numba functions (kernels, minimum image, pair passes).
#: error_model='numpy': division by zero gives inf/nan instead of raising, which removes a test
#: and an exception path per division. fastmath 'arcp' lets LLVM turn x/L into x·(1/L) and hoist
#: 1/L and kernel normalisations out of pair loops; 'contract' allows fused multiply-adds (each
#: changes a result by at most an ulp). No 'nnan'/'ninf'/'reassoc': NaNs must propagate so that
#: blow-ups stay visible, and sums keep their written order.
JIT_OPTIONS = dict(cache=True, error_model="numpy", fastmath={"arcp", "contract"})
