"""Stage 1: a rheometer file of the matrix fluid in, a fitted constitutive law out."""
from __future__ import annotations

import logging
import os
from typing import Sequence

from ..errors import InputError
from ..io.atomic import save_figure, write_json
from ..rheology.fitting import DEFAULT_CANDIDATES, FitResult, fit_flow_curve
from ..rheology.laws import LAW_SPECS
from ..rheology.readers import list_samples, read_flow_curve

log = logging.getLogger(__name__)


def fit_matrix_file(path: str | os.PathLike, *, law: str = "auto", sample: str | None = None,
                    candidates: Sequence[str] = DEFAULT_CANDIDATES, criterion: str = "bic",
                    out_json: str | os.PathLike | None = None,
                    out_plot: str | os.PathLike | None = None) -> FitResult:
    """Read a flow curve, fit ``law`` (or choose one with ``"auto"``) and write the results.

    Parameters
    ----------
    path : rheometer export (any format :func:`suspsim.rheology.readers.read_flow_curve` reads).
    law : a name from :data:`~suspsim.rheology.laws.LAW_SPECS` or ``"auto"``.
    sample : the sample to fit; required when the file holds more than one.
    candidates, criterion : the laws ``auto`` compares and the information criterion.
    out_json : fit report (SI units), written atomically.
    out_plot : figure of data and fitted law (PNG, PDF or SVG by suffix), written atomically.

    Raises
    ------
    InputError : unreadable file, ambiguous or unknown sample, unknown law, too few points.
    """
    if law != "auto" and law not in LAW_SPECS:
        raise InputError(path, f"unknown law {law!r}; choose auto or one of {', '.join(LAW_SPECS)}")
    if sample is None:
        samples = list_samples(path)
        if len(samples) > 1:
            raise InputError(path, f"the file holds {len(samples)} samples "
                             f"({', '.join(samples)}); choose one with --sample")
    data = read_flow_curve(path, sample=sample)
    source = str(path) + (f" [sample {data['sample'].iloc[0]}]" if sample else "")
    try:
        result = fit_flow_curve(data["shear_rate"].to_numpy(), data["shear_stress"].to_numpy(),
                                law=law, candidates=tuple(candidates), criterion=criterion,
                                source=source)
    except ValueError as err:
        raise InputError(path, str(err)) from None
    log.info("fitted %s to %d points of %s: rms log10 residual %.3g", result.law,
             result.n_points, source, result.rms_log_residual)
    if out_plot is not None:
        from ..plotting.flow_curve import plot_fit

        save_figure(plot_fit(data["shear_rate"].to_numpy(), data["shear_stress"].to_numpy(),
                             result), out_plot)
    if out_json is not None:
        write_json(out_json, result.to_dict())
    return result


def format_fit_table(result: FitResult) -> str:
    """A plain-text table of the fitted parameters with units and standard errors."""
    units = {p.name: p.unit for p in LAW_SPECS[result.law].parameters}
    rows = [f"law: {result.law}   source: {result.source}",
            f"points: {result.n_points}   shear rate: {result.shear_rate_range[0]:.3g} – "
            f"{result.shear_rate_range[1]:.3g} 1/s   rms log10 residual: {result.rms_log_residual:.4f}",
            f"{'parameter':<10} {'value':>12} {'std. error':>12}  unit"]
    for name, value in result.params.items():
        err = result.stderr.get(name)
        err_text = "fixed" if name in result.fixed else ("—" if err is None else f"{err:12.4g}")
        rows.append(f"{name:<10} {value:12.5g} {err_text:>12}  {units.get(name, '')}")
    rows.extend(f"note: {note}" for note in result.notes)
    return "\n".join(rows)
