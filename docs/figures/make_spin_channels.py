"""Fluid-only channel flows with and without ``numerics.spin_correction``.

    python docs/figures/make_spin_channels.py

Runs the exact-solution channels of ``tests/validation/test_sph_flows.py`` (at its full sizes,
through :mod:`suspsim.validation.flows`, two threads) twice, the spin correction off and on, and
prints the L2 error of the time-averaged profile relative to its peak: Newtonian Poiseuille in
3D (n = 4.096 h⁻³) and 2D (16 h⁻²), W = 5 h; split-force Papanastasiou Poiseuille at Bn = 1
in 3D and 2D (W = 5 h) and at Bn = 10 in 3D (W = 10 h, from the Newtonian profile). The
correction is exact in the continuum for every one of them (``terms.viscous.local_spin``), so
what it changes is discretisation error. Writes nothing.
"""
import time

from suspsim.validation.flows import (DENSITY_2D_POISEUILLE, DENSITY_3D, bingham_channel_error,
                                      newtonian_channel_error)

CASES = {
    "newtonian 3D, W = 5 h": lambda **kw: newtonian_channel_error(3, DENSITY_3D, **kw),
    "newtonian 2D, W = 5 h": lambda **kw: newtonian_channel_error(2, DENSITY_2D_POISEUILLE,
                                                                  **kw),
    "Bn = 1 3D, W = 5 h": lambda **kw: bingham_channel_error(1.0, 3, 10.0, 0.8 * 5.12,
                                                             0.2 * 5.12, **kw),
    "Bn = 1 2D, W = 5 h": lambda **kw: bingham_channel_error(1.0, 2, 10.0, 0.8 * 5.12,
                                                             0.2 * 5.12, lateral=8.0, **kw),
    "Bn = 10 3D, W = 10 h": lambda **kw: bingham_channel_error(
        10.0, 3, 20.0, 12.0, 4.0, lateral=3.75, newtonian_start=True, **kw),
}


def main() -> None:
    for spin in (False, True):
        for name, run in CASES.items():
            t0 = time.perf_counter()
            error = run(numerics={"spin_correction": spin})
            print(f"spin_correction={str(spin).lower():5s} {name:22s} L2/peak {error:.4f} "
                  f"({time.perf_counter() - t0:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
