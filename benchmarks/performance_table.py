"""The README's performance tables in one command: speed per scene and thread count, and the
scaling with the number of particles (not run by CI).

    .venv/bin/python benchmarks/performance_table.py [--steps 300] [--threads 1 2]
        [--particles 8000 32768 262144 1000000] [--scaling-steps 100] [--json FILE]

Each measurement is a fresh ``suspsim bench --json`` process (compilation is cached, so only
the first run of a session compiles), one after the other, so that nothing else of this script
shares the cores. Prints two Markdown tables:

1. particle-steps/s of every ``suspsim bench`` scene (32,768-particle box) on each thread
   count, with each suspension scene's cost per particle-step relative to the fluid scene of
   its matrix;
2. particle-steps/s and bytes per particle of ``fluid-papanastasiou`` for each box size
   ``--particles`` (k³ lattice sites, side k/1.6 h) on each thread count, and the spread
   max/min − 1 of the throughput over the sizes from 32,768 up.

The load average before and after is printed: the numbers mean something only on an otherwise
idle machine. ``--json FILE`` keeps every run's JSON line.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

SCENES = ("fluid-newtonian", "fluid-newtonian-unnormalised", "fluid-papanastasiou",
          "suspension-newtonian", "suspension-papanastasiou", "dst-2d")
SUSPSIM = Path(sys.executable).with_name("suspsim")


def bench(scene: str, threads: int, steps: int, particles: int) -> dict:
    """One ``suspsim bench`` run in its own process; its JSON result."""
    proc = subprocess.run([str(SUSPSIM), "-q", "bench", "--scene", scene, "--threads",
                           str(threads), "--steps", str(steps), "--particles", str(particles),
                           "--json"], capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        sys.exit(f"suspsim bench --scene {scene} --threads {threads} --particles {particles} "
                 f"failed ({proc.returncode}): {proc.stderr.strip()[-500:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def speed_table(runs: dict, threads: list[int]) -> str:
    """Markdown: M particle-steps/s per scene and thread count; each suspension's cost per
    particle-step relative to the fluid scene of its matrix (suspension-X / fluid-X)."""
    head = "| scene | particles | " + " | ".join(f"{t} thread{'s' * (t > 1)}" for t in threads)
    lines = [head + " | cost per particle-step / the fluid of its matrix |",
             "|---|---|" + "---|" * len(threads) + "---|"]
    for scene in SCENES:
        rates = [runs[scene, t]["particle_steps_per_s"] for t in threads]
        relative = ""
        if scene.startswith("suspension-"):
            fluid = scene.replace("suspension-", "fluid-", 1)
            base = [runs[fluid, t]["particle_steps_per_s"] for t in threads]
            relative = " / ".join(f"{b / r:.2f}" for b, r in zip(base, rates)) + f" ({fluid})"
        lines.append(f"| {scene} | {runs[scene, threads[0]]['n_particles']:,} | "
                     + " | ".join(f"{r / 1e6:.2f} M" for r in rates) + f" | {relative} |")
    return "\n".join(lines)


def scaling_table(runs: dict, threads: list[int], sizes: list[int]) -> str:
    """Markdown: M particle-steps/s and bytes per particle against N; the spread from 32k up."""
    head = "| particles | box side [h] | " + " | ".join(
        f"{t} thread{'s' * (t > 1)}" for t in threads) + (
        f" | bytes/particle ({' / '.join(map(str, threads))} threads) |")
    lines = [head, "|---|---|" + "---|" * len(threads) + "---|"]
    for n in sizes:
        k = round(n ** (1 / 3))
        lines.append(f"| {n:,} | {k / 1.6:g} | "
                     + " | ".join(f"{runs[n, t]['particle_steps_per_s'] / 1e6:.2f} M"
                                  for t in threads)
                     + " | " + " / ".join(f"{runs[n, t]['bytes_per_particle']:.0f}"
                                          for t in threads) + " |")
    spread = []
    for t in threads:
        rates = [runs[n, t]["particle_steps_per_s"] for n in sizes if n >= 32768]
        if len(rates) > 1:
            spread.append(f"{t} thread{'s' * (t > 1)} {max(rates) / min(rates) - 1:.0%}")
    return "\n".join(lines) + ("\n\nspread max/min − 1 from 32,768 up: " + ", ".join(spread)
                               if spread else "")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=300, help="timed steps per scene run")
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--particles", type=int, nargs="+",
                        default=[8000, 32768, 262144, 1000000])
    parser.add_argument("--scaling-steps", type=int, default=100,
                        help="timed steps per scaling run")
    parser.add_argument("--json", type=Path, help="write every run's JSON line here")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()}", flush=True)
    speed, scaling, lines = {}, {}, []
    for t in args.threads:
        for scene in SCENES:
            speed[scene, t] = bench(scene, t, args.steps, 32768)
            lines.append(speed[scene, t])
            print(f"  {scene}, {t} thread(s): "
                  f"{speed[scene, t]['particle_steps_per_s'] / 1e6:.2f} M", flush=True)
        for n in args.particles:
            scaling[n, t] = bench("fluid-papanastasiou", t, args.scaling_steps, n)
            lines.append(scaling[n, t])
            print(f"  {n} particles, {t} thread(s): "
                  f"{scaling[n, t]['particle_steps_per_s'] / 1e6:.2f} M", flush=True)
    print(f"load average after: {os.getloadavg()}\n")
    print(speed_table(speed, args.threads) + "\n")
    print(scaling_table(scaling, args.threads, args.particles))
    if args.json:
        args.json.write_text("".join(json.dumps(line) + "\n" for line in lines))


if __name__ == "__main__":
    main()
