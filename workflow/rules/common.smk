# Validation of the configuration and the material sheets, and the helpers the rules use.
from pathlib import Path

import yaml
from snakemake.utils import validate


validate(config, "../schemas/config.schema.yaml")

DATA = Path(config["data_dir"])
RESULTS = Path(config["results_dir"])


wildcard_constraints:
    material=r"[A-Za-z0-9_.-]+",


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
    return sheet


MATRIX_FILES = _discover_materials()
MATERIALS = {m: _load_material_sheet(m) for m in MATRIX_FILES}


def matrix_file(wildcards):
    return str(MATRIX_FILES[wildcards.material])


def fit_law(wildcards):
    return MATERIALS[wildcards.material]["matrix"]["law"] or config["fit"]["law"]


def fit_sample(wildcards):
    return MATERIALS[wildcards.material]["matrix"]["sample"]


def volume_fractions(wildcards):
    return MATERIALS[wildcards.material].get("volume_fractions") or config["homogenisation"]["volume_fractions"]


def all_outputs():
    names = ("fit.json", "fit.png", "homogenisation.nc", "homogenisation.png")
    return [str(RESULTS / m / name) for m in MATERIALS for name in names]
