# Validation of the configuration and the material sheets, and the helpers the rules use.
import math
import sys
from pathlib import Path

import yaml
from snakemake.utils import validate

from suspsim.errors import SuspsimError
from suspsim.io.provenance import code_version
from suspsim.rheology.readers import read_flow_curve
from suspsim.scene_rules import lattice_mismatch
from suspsim.stages.pack import CONTACT_KEYS, particle_settings


validate(config, "../schemas/config.schema.yaml")

DATA = Path(config["data_dir"])
RESULTS = Path(config["results_dir"])
# A study with its own results folder (results/<name>) logs to logs/<name>/: two studies of one
# material never overwrite each other's logs and benchmarks.
LOGS = "logs" if RESULTS == Path("results") else f"logs/{RESULTS.name}"


wildcard_constraints:
    material=r"[A-Za-z0-9_.-]+",
    phi=r"[0-9.e+-]+",
    rate=r"[0-9.e+-]+",
    seed=r"[0-9]+",

# Fingerprints of the package code each stage runs: a param, so editing the (editable-installed)
# package re-runs exactly the stages whose code changed.
CODE = {
    "fit_matrix": code_version("suspsim.stages.fit"),
    "predict_homogenisation": code_version("suspsim.stages.homogenisation"),
    "pack": code_version("suspsim.stages.pack"),
    "simulate": code_version("suspsim.stages.simulate"),
    "gather": code_version("suspsim.stages.gather"),
    "plot_summary": code_version("suspsim.stages.summary_figure", "suspsim.plotting.summary"),
}
SIMULATION = config["simulation"]
RESOLUTION = {key: SIMULATION[key] for key in ("box", "number_density", "strain", "transient",
                                               "reynolds", "jitter")}
# A box that holds no whole lattice would stop every simulate job after the packings are made.
_LATTICE_PROBLEM = config["material_study"] and lattice_mismatch(
    3, [SIMULATION["box"]] * 3, SIMULATION["number_density"])
if _LATTICE_PROBLEM:
    raise WorkflowError(f"config simulation.box = {SIMULATION['box']:g}: {_LATTICE_PROBLEM}")


def _discover_materials():
    """Every folder of data_dir with exactly one matrix.<ext> file, or the configured subset."""
    found = {}
    for folder in sorted(p for p in DATA.iterdir() if p.is_dir()) if DATA.is_dir() else ():
        files = sorted(f for f in folder.glob("matrix.*") if f.is_file())
        if len(files) > 1:
            raise WorkflowError(f"{folder}: several matrix files ({', '.join(f.name for f in files)}); "
                                "keep exactly one")
        if files:
            found[folder.name] = files[0]
    wanted = config["materials"] or list(found)
    missing = [m for m in wanted if m not in found]
    if missing:
        raise WorkflowError(f"config materials {missing} have no {DATA}/<material>/matrix.<ext> file")
    return {m: found[m] for m in wanted}


def _load_material_sheet(material):
    path = DATA / material / "material.yaml"
    sheet = {}
    if path.exists():
        with open(path, encoding="utf-8") as fh:
            sheet = yaml.safe_load(fh) or {}
        try:
            validate(sheet, "../schemas/material.schema.yaml")
        except WorkflowError as err:
            raise WorkflowError(f"{path}: {err}")
    sheet.setdefault("matrix", {})
    sheet["matrix"].setdefault("sample", None)
    sheet["matrix"].setdefault("law", None)
    sheet.setdefault("particles", {})
    return sheet


MATRIX_FILES = _discover_materials()
MATERIALS = {m: _load_material_sheet(m) for m in MATRIX_FILES}
PARTICLES = {m: particle_settings(SIMULATION["inclusions"], MATERIALS[m]["particles"]).to_dict()
             for m in MATERIALS}


def matrix_file(wildcards):
    return str(MATRIX_FILES[wildcards.material])


def fit_law(wildcards):
    return MATERIALS[wildcards.material]["matrix"]["law"] or config["fit"]["law"]


def fit_sample(wildcards):
    return MATERIALS[wildcards.material]["matrix"]["sample"]


def volume_fractions(wildcards):
    return MATERIALS[wildcards.material].get("volume_fractions") or config["homogenisation"]["volume_fractions"]


def number_tag(value):
    """A number as it appears in a file name: the short form when it is exact, else repr."""
    short = f"{value:g}"
    return short if float(short) == float(value) else repr(float(value))


def _rounded(value, digits=2):
    return round(value, digits - 1 - math.floor(math.log10(value)))


def _default_rates(material):
    """rate_count rates at the centres of equal log-intervals of the measured range.

    An unreadable matrix file gives none: its fit job fails with the reader's message, and the
    material's gather, which needs the fit, never runs.
    """
    try:
        data = read_flow_curve(MATRIX_FILES[material],
                               sample=MATERIALS[material]["matrix"]["sample"])
    except SuspsimError as err:
        print(f"no default shear rates for {material}: {err}", file=sys.stderr)
        return []
    low, high = math.log10(data["shear_rate"].min()), math.log10(data["shear_rate"].max())
    count = SIMULATION["rate_count"]
    return [_rounded(10 ** (low + (i + 0.5) * (high - low) / count)) for i in range(count)]


SHEAR_RATES = {m: SIMULATION["shear_rates"] or _default_rates(m) for m in MATERIALS}


def run_files(wildcards):
    """Every run file of a material: volume fractions x shear rates x seeds."""
    return [f"{RESULTS}/{wildcards.material}/runs/phi-{number_tag(phi)}_rate-{number_tag(rate)}"
            f"_seed-{seed}.nc"
            for phi in SIMULATION["volume_fractions"]
            for rate in SHEAR_RATES[wildcards.material]
            for seed in SIMULATION["seeds"]]


def run_packing(wildcards):
    """The packing file a run at phi > 0 reads; none for the matrix alone."""
    if float(wildcards.phi) == 0:
        return []
    return f"{RESULTS}/{wildcards.material}/packings/phi-{wildcards.phi}_seed-{wildcards.seed}.nc"


def run_particles(wildcards):
    """The material's inclusion settings for a run at phi > 0 (None at phi = 0, so that
    changing them leaves the matrix runs alone)."""
    return PARTICLES[wildcards.material] if float(wildcards.phi) > 0 else None


def pack_particles(wildcards):
    """The material's particle settings that shape its packings (the physical radius and the
    contacts' friction do not)."""
    return {k: v for k, v in PARTICLES[wildcards.material].items()
            if k != "physical_radius" and k not in CONTACT_KEYS}


def run_shear_rate(wildcards):
    return float(wildcards.rate)


def run_volume_fraction(wildcards):
    return float(wildcards.phi)


def run_seed(wildcards):
    return int(wildcards.seed)


#: Functions returning the final outputs of the optional studies (dst, ...); each stage file of
#: such a study appends its own, so rule all asks for them without knowing the study.
STUDY_OUTPUTS = []


def all_outputs():
    """The material pipeline's final files (when material_study) and every optional study's."""
    names = ("fit.json", "fit.png", "homogenisation.nc", "homogenisation.png", "summary.nc",
             "summary.png")
    outputs = []
    if config["material_study"]:
        outputs += [str(RESULTS / m / name) for m in MATERIALS for name in names]
    for study_outputs in STUDY_OUTPUTS:
        outputs += study_outputs()
    return outputs
