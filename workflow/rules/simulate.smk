# Stage 3: one SPH simulation per material x volume fraction x shear rate x seed (SPEC 2.7, 7);
# at phi > 0 on the packing of its phi and seed (rule pack).


rule simulate:
    input:
        fit=f"{RESULTS}/{{material}}/fit.json",
        packing=run_packing,
    output:
        run=f"{RESULTS}/{{material}}/runs/phi-{{phi}}_rate-{{rate}}_seed-{{seed}}.nc",
    log:
        LOGS + "/simulate/{material}/phi-{phi}_rate-{rate}_seed-{seed}.log",
    benchmark:
        LOGS + "/benchmarks/simulate/{material}/phi-{phi}_rate-{rate}_seed-{seed}.tsv"
    threads: SIMULATION["threads"]
    # Densest first: runs with more bodies take longest (phi = 0.2 about six times phi = 0 in the
    # default study), so starting them first lets the short ones fill the other cores at the end
    # instead of one long run finishing alone.
    priority: lambda wildcards: float(wildcards.phi)
    params:
        shear_rate=run_shear_rate,
        volume_fraction=run_volume_fraction,
        seed=run_seed,
        resolution=RESOLUTION,
        numerics=SIMULATION["numerics"],
        particles=run_particles,
        code=CODE["simulate"],
    script:
        "../scripts/simulate.py"
