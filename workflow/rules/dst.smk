# The dst study (seed 002, issue 5): one stress-controlled DST run per volume fraction x
# non-locality x imposed stress (suspsim.stages.dst), gathered into results/dst/flow_curves.nc,
# and its figures; and the channel flows of Fig. 7-8, one run per set x driving force
# (suspsim.stages.dst_channel), gathered into results/dst/channel.nc with their figures.
from suspsim.stages.dst import band_points, find_point, point_scene, study_points
from suspsim.stages.dst_channel import channel_jobs, find_channel_job


DST = config["dst"]
DST_DIR = RESULTS / "dst"
DST_POINTS = study_points(DST)
DST_BANDS = band_points(DST)
DST_CHANNEL = channel_jobs(DST)
CODE_DST = {
    "simulate": code_version("suspsim.stages.dst"),
    "channel": code_version("suspsim.stages.dst_channel"),
    "channel_gather": code_version("suspsim.stages.dst_channel_gather"),
    "gather": code_version("suspsim.stages.dst_gather"),
    "figures": code_version("suspsim.stages.dst_figures"),
}


def _dst_run(point, folder="runs"):
    return (f"{DST_DIR}/{folder}/phi-{number_tag(point.phi)}_nonlocality-"
            f"{point.nonlocality.name}_stress-{point.index:02d}.nc")


def dst_run_files(wildcards):
    """Every run file of the study, in study-point order (the order gather expects)."""
    return [_dst_run(point) for point in DST_POINTS]


def dst_band_files(wildcards):
    """The band runs, in band_points order."""
    return [_dst_run(point, "bands") for point in DST_BANDS]


def dst_scene(wildcards):
    """The DST scene (a dict) of one point: every setting of the run, so a change re-runs it."""
    return point_scene(DST, find_point(DST, float(wildcards.phi), wildcards.nonlocality,
                                       int(wildcards.index)))


def dst_band_scene(wildcards):
    """The DST scene of one band run (the band lattice and run lengths)."""
    return point_scene(DST, find_point(DST, float(wildcards.phi), wildcards.nonlocality,
                                       int(wildcards.index), band=True), band=True)


def _channel_run(job):
    return f"{DST_DIR}/channel/{job.name}_force-{job.index:02d}.nc"


def dst_channel_files(wildcards):
    """The channel run files, set by set in force order (what gather_dst_channel expects)."""
    return [_channel_run(job) for job in DST_CHANNEL]


def dst_channel_job(wildcards):
    """One channel run's settings (a dict): a change re-runs it."""
    job = find_channel_job(DST, wildcards.set, int(wildcards.index))
    return {"force_ratio": job.force_ratio, **job.sweep}


def dst_outputs():
    """The study's final files; none without volume fractions or channel sets."""
    names = []
    if DST_POINTS:
        names += ["flow_curves.nc", "flow_curves.png", "particles.png", "splitting.png",
                  "bands.png"]
    if DST_CHANNEL:
        names += ["channel.nc", "channel_profiles.png", "channel_flow.png"]
    return [str(DST_DIR / name) for name in names]


STUDY_OUTPUTS.append(dst_outputs)


rule simulate_dst_point:
    output:
        run=f"{DST_DIR}/runs/phi-{{phi}}_nonlocality-{{nonlocality}}_stress-{{index}}.nc",
    log:
        LOGS + "/simulate_dst_point/phi-{phi}_nonlocality-{nonlocality}_stress-{index}.log",
    benchmark:
        LOGS + "/benchmarks/simulate_dst_point/phi-{phi}_nonlocality-{nonlocality}_stress-{index}.tsv"
    wildcard_constraints:
        nonlocality=r"[A-Za-z0-9-]+",
        index=r"[0-9]+",
    threads: DST["threads"]
    params:
        scene=dst_scene,
        code=CODE_DST["simulate"],
    script:
        "../scripts/simulate_dst_point.py"


# The band runs: the same job on the band lattice (one point, a few non-localities).
use rule simulate_dst_point as simulate_dst_band with:
    output:
        run=f"{DST_DIR}/bands/phi-{{phi}}_nonlocality-{{nonlocality}}_stress-{{index}}.nc",
    log:
        LOGS + "/simulate_dst_band/phi-{phi}_nonlocality-{nonlocality}_stress-{index}.log",
    benchmark:
        LOGS + "/benchmarks/simulate_dst_band/phi-{phi}_nonlocality-{nonlocality}_stress-{index}.tsv"
    params:
        scene=dst_band_scene,
        code=CODE_DST["simulate"],


rule gather_dst:
    input:
        runs=dst_run_files,
        bands=dst_band_files,
    output:
        flow_curves=f"{DST_DIR}/flow_curves.nc",
    log:
        LOGS + "/gather_dst/gather_dst.log",
    benchmark:
        LOGS + "/benchmarks/gather_dst/gather_dst.tsv"
    params:
        settings=DST,
        code=CODE_DST["gather"],
    script:
        "../scripts/gather_dst.py"


rule plot_dst:
    input:
        flow_curves=f"{DST_DIR}/flow_curves.nc",
    output:
        flow_curves=report(
            f"{DST_DIR}/flow_curves.png",
            caption="../report/dst_flow_curves.rst",
            category="Discontinuous shear thickening",
        ),
        particles=report(
            f"{DST_DIR}/particles.png",
            caption="../report/dst_particles.rst",
            category="Discontinuous shear thickening",
        ),
        splitting=report(
            f"{DST_DIR}/splitting.png",
            caption="../report/dst_splitting.rst",
            category="Discontinuous shear thickening",
        ),
        bands=report(
            f"{DST_DIR}/bands.png",
            caption="../report/dst_bands.rst",
            category="Discontinuous shear thickening",
        ),
    log:
        LOGS + "/plot_dst/plot_dst.log",
    benchmark:
        LOGS + "/benchmarks/plot_dst/plot_dst.tsv"
    params:
        figure=DST["figure"],
        code=CODE_DST["figures"],
    script:
        "../scripts/plot_dst.py"


rule simulate_dst_channel:
    output:
        run=f"{DST_DIR}/channel/{{set}}_force-{{index}}.nc",
    log:
        LOGS + "/simulate_dst_channel/{set}_force-{index}.log",
    benchmark:
        LOGS + "/benchmarks/simulate_dst_channel/{set}_force-{index}.tsv"
    wildcard_constraints:
        set=r"[A-Za-z0-9-]+",
        index=r"[0-9]+",
    threads: DST["threads"]
    params:
        job=dst_channel_job,
        code=CODE_DST["channel"],
    script:
        "../scripts/simulate_dst_channel.py"


rule gather_dst_channel:
    input:
        runs=dst_channel_files,
    output:
        channel=f"{DST_DIR}/channel.nc",
    log:
        LOGS + "/gather_dst_channel/gather_dst_channel.log",
    benchmark:
        LOGS + "/benchmarks/gather_dst_channel/gather_dst_channel.tsv"
    params:
        sets=[job.name for job in DST_CHANNEL],
        code=CODE_DST["channel_gather"],
    script:
        "../scripts/gather_dst_channel.py"


rule plot_dst_channel:
    input:
        channel=f"{DST_DIR}/channel.nc",
    output:
        profiles=report(
            f"{DST_DIR}/channel_profiles.png",
            caption="../report/dst_channel_profiles.rst",
            category="Discontinuous shear thickening",
        ),
        flow=report(
            f"{DST_DIR}/channel_flow.png",
            caption="../report/dst_channel_flow.rst",
            category="Discontinuous shear thickening",
        ),
    log:
        LOGS + "/plot_dst_channel/plot_dst_channel.log",
    benchmark:
        LOGS + "/benchmarks/plot_dst_channel/plot_dst_channel.tsv"
    params:
        profile_forces=DST.get("channel", {}).get("profile_forces", []),
        code=CODE_DST["channel_gather"],
    script:
        "../scripts/plot_dst_channel.py"
