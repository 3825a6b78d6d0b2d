"""Start-up figure and its error measure on a dataset built from the 1D reference alone."""
import io

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from suspsim.plotting.startup import plot_startup
from suspsim.reference.couette_startup import bin_means, cell_centres, couette_startup
from suspsim.rheology.laws import papanastasiou
from suspsim.validation.startup import papanastasiou_parameters, profile_error

SIDE, BINS, CELLS = 5.0, 8, 80


def fake_startup(offset):
    """The dataset layout of ``papanastasiou_startup`` with 'SPH' = reference + ``offset`` V."""
    rate, params = papanastasiou_parameters(0.1, 4.096)
    strains = np.array([0.05, 0.2, 1.0])
    fine = couette_startup(papanastasiou(**params), 4.096, SIDE, rate * SIDE, strains / rate,
                           cells=CELLS)
    reference = bin_means(fine, BINS)
    return xr.Dataset(
        {"velocity": (("strain", "y"), reference + offset * rate * SIDE),
         "reference_velocity": (("strain", "y"), reference),
         "reference_velocity_fine": (("strain", "y_fine"), fine)},
        coords={"strain": strains, "y": (np.arange(BINS) + 0.5) * SIDE / BINS,
                "y_fine": cell_centres(SIDE, CELLS)},
        attrs={"box_side": SIDE, "shear_rate": rate, "bingham_number": 0.1,
               "number_density": 4.096})


def test_profile_error_is_the_largest_bin_difference_over_gamma_dot_l():
    np.testing.assert_allclose(profile_error(fake_startup(0.0)).values, 0.0)
    np.testing.assert_allclose(profile_error(fake_startup(0.02)).values, 0.02)


def test_plot_startup_draws_markers_and_lines_per_strain():
    data = fake_startup(0.01)
    fig = plot_startup(data)
    assert isinstance(fig, Figure) and len(fig.axes) == 1
    ax = fig.axes[0]
    # The steady line, then a reference line and a marker set per strain.
    assert len(ax.get_lines()) == 1 + 2 * data.sizes["strain"]
    markers = ax.get_lines()[2]
    np.testing.assert_allclose(markers.get_xdata(), data["y"].values / SIDE - 0.5)
    assert np.all(np.abs(markers.get_ydata()) <= 0.5)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[1] == "γ̇t = 0.05: max |Δv|/(γ̇L) = 0.010"
    fig.savefig(io.BytesIO(), format="png")

    own = Figure()
    axis = own.subplots()
    assert plot_startup(data, ax=axis) is own


@pytest.mark.parametrize("bingham", [0.1, 1.0])
def test_parameters_give_the_bingham_and_particle_reynolds_numbers(bingham):
    rate, params = papanastasiou_parameters(bingham, 4.096)
    assert params["mu_0"] / (params["M"] * params["mu_pl"] * rate) == pytest.approx(bingham)
    law = papanastasiou(**params)
    assert 4.096 * rate / float(law.viscosity(rate)) == pytest.approx(0.1)
