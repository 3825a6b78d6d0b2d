# Stage 2b: one random packing per material x volume fraction > 0 x seed, read by its runs.


# Cached between workflows (snakemake --cache, with SNAKEMAKE_OUTPUT_CACHE set): a packing
# depends only on its params (wildcards are not part of the cache hash, so every setting is a
# param), so studies sharing a box, particle settings, phi and seed share one packing file.
# The cache forbids benchmark:, hence none here.
rule pack:
    output:
        packing=f"{RESULTS}/{{material}}/packings/phi-{{phi}}_seed-{{seed}}.nc",
    log:
        LOGS + "/pack/{material}/phi-{phi}_seed-{seed}.log",
    cache: True
    params:
        volume_fraction=run_volume_fraction,
        seed=run_seed,
        box=SIMULATION["box"],
        particles=pack_particles,
        code=CODE["pack"],
    script:
        "../scripts/pack.py"
