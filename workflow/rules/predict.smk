# Stage 2a: the homogenisation estimate of the suspension viscosity, from the matrix fit alone.


rule predict_homogenisation:
    input:
        fit=f"{RESULTS}/{{material}}/fit.json",
    output:
        estimate=f"{RESULTS}/{{material}}/homogenisation.nc",
        figure=report(
            f"{RESULTS}/{{material}}/homogenisation.png",
            caption="../report/predict_homogenisation.rst",
            category="Suspension predictions",
            subcategory="{material}",
        ),
    log:
        LOGS + "/predict_homogenisation/{material}.log",
    benchmark:
        LOGS + "/benchmarks/predict_homogenisation/{material}.tsv"
    params:
        volume_fractions=volume_fractions,
        phi_max=config["homogenisation"]["phi_max"],
        code=CODE["predict_homogenisation"],
    script:
        "../scripts/predict_homogenisation.py"
