# The bingham_suspension study (seed 000 Fig. 3, issues 4 and 6): spheres in a Papanastasiou
# matrix over the rate x = M gdot, one packing per seed shared by a Newtonian run (g) and one
# run per x (suspsim.stages.bingham_suspension), gathered into
# results/bingham_suspension/suspension.nc against the Chateau-Ovarlez-Trung estimate, with fig3.png.
from suspsim.stages.bingham_suspension import case_name, find_job, study_settings


BINGHAM = config["bingham_suspension"]
BINGHAM_SETTINGS = study_settings(BINGHAM)
BINGHAM_DIR = RESULTS / "bingham_suspension"
CODE_BINGHAM = {
    "simulate": code_version("suspsim.stages.bingham_suspension"),
    "gather": code_version("suspsim.stages.bingham_suspension_gather"),
    "figures": code_version("suspsim.stages.bingham_suspension_figures"),
}


def bingham_run_file(rate, seed):
    """The run file of rate x (None: the Newtonian reference) and seed."""
    return f"{BINGHAM_DIR}/runs/{case_name(rate, number_tag)}_seed-{seed}.nc"


def bingham_newtonian_files(wildcards):
    """The Newtonian run of every seed, in the config's seed order."""
    return [bingham_run_file(None, seed) for seed in BINGHAM_SETTINGS["seeds"]]


def bingham_rate_files(wildcards):
    """The Papanastasiou runs, rate-major in the config's orders (the gather's)."""
    return [bingham_run_file(rate, seed) for rate in BINGHAM_SETTINGS["rates"]
            for seed in BINGHAM_SETTINGS["seeds"]]


def bingham_job(wildcards):
    """One run's settings (a dict): a change re-runs it."""
    return find_job(BINGHAM, wildcards.case, int(wildcards.seed))


def bingham_outputs():
    """The study's final files; none without rates."""
    if not BINGHAM_SETTINGS["rates"]:
        return []
    return [str(BINGHAM_DIR / "suspension.nc"), str(BINGHAM_DIR / "fig3.png")]


STUDY_OUTPUTS.append(bingham_outputs)


rule pack_bingham_suspension:
    output:
        packing=f"{BINGHAM_DIR}/packings/seed-{{seed}}.nc",
    log:
        LOGS + "/pack_bingham_suspension/seed-{seed}.log",
    benchmark:
        LOGS + "/benchmarks/pack_bingham_suspension/seed-{seed}.tsv"
    params:
        settings={key: BINGHAM_SETTINGS[key] for key in ("volume_fraction", "radius", "box")},
        seed=run_seed,
        code=CODE_BINGHAM["simulate"],
    script:
        "../scripts/pack_bingham_suspension.py"


rule simulate_bingham_suspension:
    input:
        packing=f"{BINGHAM_DIR}/packings/seed-{{seed}}.nc",
    output:
        run=f"{BINGHAM_DIR}/runs/{{case}}_seed-{{seed}}.nc",
    log:
        LOGS + "/simulate_bingham_suspension/{case}_seed-{seed}.log",
    benchmark:
        LOGS + "/benchmarks/simulate_bingham_suspension/{case}_seed-{seed}.tsv"
    wildcard_constraints:
        case=r"newtonian|x-[0-9.e+-]+",
    threads: BINGHAM["threads"]
    params:
        job=bingham_job,
        code=CODE_BINGHAM["simulate"],
    script:
        "../scripts/simulate_bingham_suspension.py"


rule gather_bingham_suspension:
    input:
        newtonian=bingham_newtonian_files,
        runs=bingham_rate_files,
    output:
        suspension=f"{BINGHAM_DIR}/suspension.nc",
    log:
        LOGS + "/gather_bingham_suspension/gather_bingham_suspension.log",
    benchmark:
        LOGS + "/benchmarks/gather_bingham_suspension/gather_bingham_suspension.tsv"
    params:
        block={key: value for key, value in BINGHAM_SETTINGS.items() if key != "threads"},
        code=CODE_BINGHAM["gather"],
    script:
        "../scripts/gather_bingham_suspension.py"


rule plot_bingham_suspension:
    input:
        suspension=f"{BINGHAM_DIR}/suspension.nc",
    output:
        figure=report(f"{BINGHAM_DIR}/fig3.png", caption="../report/bingham_suspension.rst",
                      category="Seed 000 suspension"),
    log:
        LOGS + "/plot_bingham_suspension/plot_bingham_suspension.log",
    benchmark:
        LOGS + "/benchmarks/plot_bingham_suspension/plot_bingham_suspension.tsv"
    params:
        code=CODE_BINGHAM["figures"],
    script:
        "../scripts/plot_bingham_suspension.py"
