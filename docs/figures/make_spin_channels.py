"""Fluid-only channel flows with and without ``numerics.spin_correction``.

    python docs/figures/make_spin_channels.py

Runs four exact-solution channels of ``tests/validation/test_sph_flows.py`` (its helpers, at
its full sizes, two threads) twice, the spin correction off and on, and prints the L2 error of
the time-averaged profile relative to its peak: Newtonian Poiseuille in 3D (n = 4.096 h⁻³) and
2D (16 h⁻²), W = 5 h; split-force Papanastasiou Poiseuille at Bn = 1 in 3D and 2D (W = 5 h) and
at Bn = 10 in 3D (W = 10 h, from the Newtonian profile). The correction is exact in the
continuum for every one of them (``terms.viscous.local_spin``), so what it changes is
discretisation error. Writes nothing.
"""
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "validation"))
import test_sph_flows as flows  # noqa: E402

from suspsim.scene import scene_from_dict  # noqa: E402


def newtonian(dim):
    density, height, g = (flows.DENSITY_3D if dim == 3 else flows.DENSITY_2D_POISEUILLE), 10.0, 0.01
    mu = 1.25 * density
    t_visc = density * (height / 2) ** 2 / mu
    return flows.poiseuille_error("newtonian", {"mu": mu}, g, dim, density, height, 3 * t_visc,
                                  t_visc)


CASES = {
    "newtonian 3D, W = 5 h": lambda: newtonian(3),
    "newtonian 2D, W = 5 h": lambda: newtonian(2),
    "Bn = 1 3D, W = 5 h": lambda: flows.bingham_poiseuille_error(1.0, 3, 10.0, 0.8 * 5.12,
                                                                 0.2 * 5.12),
    "Bn = 1 2D, W = 5 h": lambda: flows.bingham_poiseuille_error(1.0, 2, 10.0, 0.8 * 5.12,
                                                                 0.2 * 5.12, lateral=8.0),
    "Bn = 10 3D, W = 10 h": lambda: flows.bingham_poiseuille_error(
        10.0, 3, 20.0, 12.0, 4.0, lateral=3.75, newtonian_start=True),
}


def main() -> None:
    for spin in (False, True):
        def with_spin(scene, spin=spin):
            numerics = {**scene.get("numerics", {}), "spin_correction": spin}
            return scene_from_dict({**scene, "numerics": numerics})
        flows.scene_from_dict = with_spin
        for name, run in CASES.items():
            t0 = time.perf_counter()
            error = run()
            print(f"spin_correction={str(spin).lower():5s} {name:22s} L2/peak {error:.4f} "
                  f"({time.perf_counter() - t0:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
