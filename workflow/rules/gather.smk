# Stage 4: gather each material's runs into summary.nc (phi, shear_rate, seed) and plot it.


rule gather:
    input:
        fit=f"{RESULTS}/{{material}}/fit.json",
        runs=run_files,
    output:
        summary=f"{RESULTS}/{{material}}/summary.nc",
    log:
        LOGS + "/gather/{material}.log",
    benchmark:
        LOGS + "/benchmarks/gather/{material}.tsv"
    params:
        code=CODE["gather"],
    script:
        "../scripts/gather.py"


rule plot_summary:
    input:
        summary=f"{RESULTS}/{{material}}/summary.nc",
        fit=f"{RESULTS}/{{material}}/fit.json",
        matrix=matrix_file,
        estimate=f"{RESULTS}/{{material}}/homogenisation.nc",
    output:
        figure=report(
            f"{RESULTS}/{{material}}/summary.png",
            caption="../report/plot_summary.rst",
            category="Suspension predictions",
            subcategory="{material}",
        ),
    log:
        LOGS + "/plot_summary/{material}.log",
    benchmark:
        LOGS + "/benchmarks/plot_summary/{material}.tsv"
    params:
        sample=fit_sample,
        code=CODE["plot_summary"],
    script:
        "../scripts/plot_summary.py"
