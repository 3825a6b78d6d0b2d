# Stage 1: fit a constitutive law to the matrix fluid's flow curve.


rule fit_matrix:
    input:
        matrix=matrix_file,
    output:
        fit=f"{RESULTS}/{{material}}/fit.json",
        figure=report(
            f"{RESULTS}/{{material}}/fit.png",
            caption="../report/fit_matrix.rst",
            category="Matrix fluid",
            subcategory="{material}",
        ),
    log:
        LOGS + "/fit_matrix/{material}.log",
    benchmark:
        LOGS + "/benchmarks/fit_matrix/{material}.tsv"
    params:
        law=fit_law,
        sample=fit_sample,
        criterion=config["fit"]["criterion"],
        candidates=config["fit"]["candidates"],
        code=CODE["fit_matrix"],
    script:
        "../scripts/fit_matrix.py"
