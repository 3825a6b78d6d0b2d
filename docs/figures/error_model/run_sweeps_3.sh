#!/bin/sh
# Third set of training sweeps (after the second held-out pass): a Bingham channel at Bn = 5,
# between the training Bn = 3 and the held-out Bn = 10, swept in the time-step coefficient to
# test whether the time-step error grows with the plug fraction. Run from the repository root:
# sh docs/figures/error_model/run_sweeps_3.sh
set -e
PY=${PYTHON:-python}
D=docs/figures/error_model
$PY -m suspsim.convergence.sweep poiseuille_bingham5_3d '{"dt_coefficient": [0.4, 0.2, 0.1, 0.05], "width": [7.5, 10.0]}' $D/grid_poiseuille_bingham5_3d.nc
# The Bn = 3 channel of run_sweeps_2.sh was measured at C = 0.4 only: the same widths at C = 0.1
$PY -m suspsim.convergence.sweep poiseuille_bingham3_3d '{"dt_coefficient": [0.1], "width": [7.5, 10.0]}' $D/grid_poiseuille_bingham3_3d_c0.1.nc
