# The flows study (seed 000 Figs. 1 and 2, issue 6): the Couette start-up of a Papanastasiou
# fluid (one job) and split-force Poiseuille channels, one job per Bingham number
# (suspsim.stages.flows), gathered into results/flows/flows.nc with one figure per part.
from suspsim.stages.flows import find_poiseuille_job, poiseuille_jobs, startup_job


FLOWS = config["flows"]
FLOWS_DIR = RESULTS / "flows"
FLOWS_STARTUP = startup_job(FLOWS)
FLOWS_POISEUILLE = poiseuille_jobs(FLOWS)
CODE_FLOWS = {
    "simulate": code_version("suspsim.stages.flows"),
    "gather": code_version("suspsim.stages.flows_gather"),
    "figures": code_version("suspsim.stages.flows_figures"),
}
#: The figures of the parts the config runs, as report outputs of plot_flows.
FLOWS_FIGURES = {
    name: report(f"{FLOWS_DIR}/{name}.png", caption=f"../report/flows_{name}.rst",
                 category="Seed 000 flows")
    for name, present in (("startup", FLOWS_STARTUP is not None),
                          ("poiseuille", bool(FLOWS_POISEUILLE)))
    if present
}


def flows_startup_file(wildcards):
    """The start-up run file, or none when the config lists no strains."""
    return [] if FLOWS_STARTUP is None else f"{FLOWS_DIR}/runs/startup.nc"


def flows_poiseuille_files(wildcards):
    """The channel run files in the config's Bingham order (the figure's)."""
    return [f"{FLOWS_DIR}/runs/poiseuille_bn-{number_tag(job['bingham'])}.nc"
            for job in FLOWS_POISEUILLE]


def flows_poiseuille_job(wildcards):
    """One channel run's settings (a dict): a change re-runs it."""
    return find_poiseuille_job(FLOWS, float(wildcards.bingham))


def flows_outputs():
    """The study's final files; none when neither part lists a run."""
    if not FLOWS_FIGURES:
        return []
    return [str(FLOWS_DIR / "flows.nc"), *(str(FLOWS_DIR / f"{n}.png") for n in FLOWS_FIGURES)]


STUDY_OUTPUTS.append(flows_outputs)


rule simulate_startup:
    output:
        run=f"{FLOWS_DIR}/runs/startup.nc",
    log:
        LOGS + "/simulate_startup/startup.log",
    benchmark:
        LOGS + "/benchmarks/simulate_startup/startup.tsv"
    threads: FLOWS["threads"]
    params:
        job=FLOWS_STARTUP,
        code=CODE_FLOWS["simulate"],
    script:
        "../scripts/simulate_flows.py"


rule simulate_poiseuille:
    output:
        run=f"{FLOWS_DIR}/runs/poiseuille_bn-{{bingham}}.nc",
    log:
        LOGS + "/simulate_poiseuille/bn-{bingham}.log",
    benchmark:
        LOGS + "/benchmarks/simulate_poiseuille/bn-{bingham}.tsv"
    wildcard_constraints:
        bingham=r"[0-9.e+-]+",
    threads: FLOWS["threads"]
    params:
        job=flows_poiseuille_job,
        code=CODE_FLOWS["simulate"],
    script:
        "../scripts/simulate_flows.py"


rule gather_flows:
    input:
        startup=flows_startup_file,
        poiseuille=flows_poiseuille_files,
    output:
        flows=f"{FLOWS_DIR}/flows.nc",
    log:
        LOGS + "/gather_flows/gather_flows.log",
    benchmark:
        LOGS + "/benchmarks/gather_flows/gather_flows.tsv"
    params:
        code=CODE_FLOWS["gather"],
    script:
        "../scripts/gather_flows.py"


rule plot_flows:
    input:
        flows=f"{FLOWS_DIR}/flows.nc",
    output:
        **FLOWS_FIGURES,
    log:
        LOGS + "/plot_flows/plot_flows.log",
    benchmark:
        LOGS + "/benchmarks/plot_flows/plot_flows.tsv"
    params:
        code=CODE_FLOWS["figures"],
    script:
        "../scripts/plot_flows.py"
