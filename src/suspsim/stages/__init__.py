"""Pipeline stages: one function per stage, called by both the CLI and the Snakemake scripts."""
