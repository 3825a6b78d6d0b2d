"""Squeeze-force figure on a dataset of the layout of ``validation.squeeze.squeeze_study``."""
import numpy as np
import xarray as xr
from matplotlib.collections import PolyCollection

from suspsim.plotting.squeeze import plot_squeeze


def fake_squeeze(shifts):
    """Ratios 1 at every gap, each phase k at 0.8 + 0.4 k/(P − 1) (P = len(shifts))."""
    gap = np.geomspace(0.06, 4.0, 10)
    ones = ("gap", np.ones(gap.size))
    phases = np.linspace(0.8, 1.2, len(shifts))[:, None] * np.ones(gap.size)
    return xr.Dataset(
        {name: ones for name in ("force", "force_error", "theory_force_nominal",
                                 "theory_force", "ratio_nominal", "ratio_combined")}
        | {"phase_ratio_nominal": (("phase", "gap"), phases)},
        coords={"gap": gap, "phase": np.asarray(shifts, dtype=float)},
        attrs={"radius": 2.5, "speed": 0.005, "viscosity": 1.0,
               "hydrodynamic_radius_ratio": 1.05, "cutoff_gap": 0.2})


def test_the_phase_band_spans_the_phases_of_a_pooled_run():
    bottom = plot_squeeze(fake_squeeze([0.0, 0.2, 0.4])).axes[1]
    bands = [c for c in bottom.collections if isinstance(c, PolyCollection)]
    assert len(bands) == 1
    y = bands[0].get_paths()[0].vertices[:, 1]
    assert y.min() == 0.8 and y.max() == 1.2


def test_a_single_phase_draws_no_band():
    bottom = plot_squeeze(fake_squeeze([0.0])).axes[1]
    assert not [c for c in bottom.collections if isinstance(c, PolyCollection)]
