"""Grid sweeps of a validation case for the error model (:mod:`.error_model`): every combination
of the listed settings, measured with :func:`~.measure.run_or_failure` and stored as one
netCDF Dataset (:func:`~.study.case_dataset`, cost = CPU time of one thread [s]); a
configuration that blows up is kept with NaN measurements and its message in ``failure``.

Command (one case per call, each recorded in the file's ``command`` attribute)::

    python -m suspsim.convergence.sweep CASE '{"resolution": [1.6, 2.4], "width": [2.5, 5]}' OUT.nc
"""
from __future__ import annotations

import json
import logging
import os
import sys
from typing import Any, Mapping, Sequence

import xarray as xr

from suspsim.convergence.cases import get_case
from suspsim.convergence.measure import run_or_failure
from suspsim.convergence.study import case_dataset, configurations
from suspsim.io.atomic import atomic_path
from suspsim.io.provenance import provenance


def grid_sweep(case_name: str, values: Mapping[str, Sequence[Any]], out: str | os.PathLike, *,
               threads: int = 1, command: str = "") -> xr.Dataset:
    """Run every combination of ``values`` for ``case_name`` and write the Dataset to ``out``."""
    case = get_case(case_name)
    records = []
    for overrides in configurations(case, values, sweep="grid"):
        records.append(run_or_failure(case, overrides, threads=threads))
    ds = case_dataset(case, records)
    ds.attrs.update(sweep="grid", values=json.dumps(dict(values)), command=command,
                    **provenance())
    with atomic_path(out) as tmp:
        ds.to_netcdf(tmp)
    return ds


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 1
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s")
    command = "python -m suspsim.convergence.sweep " + " ".join(
        f"'{a}'" if " " in a else a for a in argv)
    grid_sweep(argv[0], json.loads(argv[1]), argv[2], command=command)
    return 0


if __name__ == "__main__":
    sys.exit(main())
