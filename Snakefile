# suspsim study workflow: the table of contents. Each stage lives in workflow/rules/.
from snakemake.utils import min_version

min_version("8.0")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/fit.smk"
include: "workflow/rules/predict.smk"
include: "workflow/rules/pack.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/gather.smk"
include: "workflow/rules/speed_error.smk"
include: "workflow/rules/dst.smk"
include: "workflow/rules/flows.smk"
include: "workflow/rules/bingham_suspension.smk"


rule all:
    input:
        all_outputs(),
    default_target: True
