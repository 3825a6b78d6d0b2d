"""Make docs/figures/startup_papanastasiou.png: seed 000 Fig. 1, SPH start-up against 1D.

    python docs/figures/make_startup.py [--threads N]

Runs :func:`suspsim.validation.startup.papanastasiou_startup` at full size (3D box of 7.5 h,
n = 4.096 per h³, Bn = 0.1) and draws it with :func:`suspsim.plotting.startup.plot_startup`.
"""
import argparse
from pathlib import Path

from suspsim.io.atomic import save_figure
from suspsim.plotting.startup import plot_startup
from suspsim.validation.startup import papanastasiou_startup, profile_error

OUTPUT = Path(__file__).resolve().with_name("startup_papanastasiou.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=None,
                        help="solver threads (default: every core)")
    args = parser.parse_args()
    data = papanastasiou_startup(threads=args.threads)
    save_figure(plot_startup(data), OUTPUT)
    errors = ", ".join(f"{s:.3g}: {e:.4f}" for s, e in
                       zip(data["strain"].values, profile_error(data).values))
    print(f"{OUTPUT}: {data.attrs['n_particles']} particles, {data.attrs['wall_time_s']:.0f} s; "
          f"max |v_SPH - v_1D|/(γ̇L) by strain: {errors}")


if __name__ == "__main__":
    main()
