# Issue 7: the speed-against-error study. Each validation case (suspsim.convergence.cases) runs
# at its defaults and at the configured values of its numerical axes; each configuration's error
# against the exact reference and its cost are gathered per case, then plotted (error against
# CPU time with the Pareto front) and tabulated (the cheapest configuration per target error).
from suspsim.convergence.cases import get_case
from suspsim.convergence.study import configuration_id, configurations

SPEED_ERROR = config["speed_error"]
SPEED_ERROR_DIR = RESULTS / "speed_error"
CODE["speed_error"] = code_version("suspsim.stages.speed_error")
CODE["speed_error_report"] = code_version("suspsim.stages.speed_error",
                                          "suspsim.plotting.pareto")


def _speed_error_configurations():
    """{case: {configuration id: overrides}}; a bad case or axis stops the workflow here."""
    out = {}
    for name, values in SPEED_ERROR["cases"].items():
        try:
            overrides = configurations(get_case(name), values or {}, SPEED_ERROR["sweep"])
        except SuspsimError as err:
            raise WorkflowError(f"config speed_error.cases.{name}: {err}")
        out[name] = {configuration_id(o): o for o in overrides}
    return out


SPEED_ERROR_CONFIGURATIONS = _speed_error_configurations()


def speed_error_outputs():
    if not SPEED_ERROR_CONFIGURATIONS:
        return []
    return [f"{SPEED_ERROR_DIR}/{case}.nc" for case in SPEED_ERROR_CONFIGURATIONS] + [
        f"{SPEED_ERROR_DIR}/pareto.png", f"{SPEED_ERROR_DIR}/cost_table.md"]


STUDY_OUTPUTS.append(speed_error_outputs)


def speed_error_overrides(wildcards):
    return SPEED_ERROR_CONFIGURATIONS[wildcards.case][wildcards.configuration]


def speed_error_records(wildcards):
    return [f"{SPEED_ERROR_DIR}/runs/{wildcards.case}/{configuration}.nc"
            for configuration in SPEED_ERROR_CONFIGURATIONS[wildcards.case]]


rule speed_error_measure:
    output:
        record=f"{SPEED_ERROR_DIR}/runs/{{case}}/{{configuration}}.nc",
    log:
        LOGS + "/speed_error_measure/{case}/{configuration}.log",
    benchmark:
        LOGS + "/benchmarks/speed_error_measure/{case}/{configuration}.tsv"
    wildcard_constraints:
        case=r"[a-z0-9_.]+",
        configuration=r"[A-Za-z0-9_.+-]+",
    threads: SPEED_ERROR["threads"]
    params:
        overrides=speed_error_overrides,
        code=CODE["speed_error"],
    script:
        "../scripts/speed_error_measure.py"


rule speed_error_gather:
    input:
        records=speed_error_records,
    output:
        case=f"{SPEED_ERROR_DIR}/{{case}}.nc",
    log:
        LOGS + "/speed_error_gather/{case}.log",
    benchmark:
        LOGS + "/benchmarks/speed_error_gather/{case}.tsv"
    wildcard_constraints:
        case=r"[a-z0-9_.]+",
    params:
        code=CODE["speed_error"],
    script:
        "../scripts/speed_error_gather.py"


rule speed_error_report:
    input:
        cases=[f"{SPEED_ERROR_DIR}/{case}.nc" for case in SPEED_ERROR_CONFIGURATIONS],
    output:
        figure=report(
            f"{SPEED_ERROR_DIR}/pareto.png",
            caption="../report/speed_error_report.rst",
            category="Speed against error",
        ),
        table=f"{SPEED_ERROR_DIR}/cost_table.md",
    log:
        LOGS + "/speed_error_report/report.log",
    benchmark:
        LOGS + "/benchmarks/speed_error_report/report.tsv"
    params:
        code=CODE["speed_error_report"],
    script:
        "../scripts/speed_error_report.py"
