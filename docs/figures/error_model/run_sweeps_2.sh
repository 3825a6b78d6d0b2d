#!/bin/sh
# Second set of training sweeps (after the first held-out pass, see the report): a Bingham
# channel at Bn = 3 (a second Bingham number for the training set) and the 2D channel near its
# cheap end. Run from the repository root: sh docs/figures/error_model/run_sweeps_2.sh
set -e
PY=${PYTHON:-python}
D=docs/figures/error_model
$PY -m suspsim.convergence.sweep poiseuille_newtonian_2d '{"resolution": [2.5, 3.0], "width": [2.5, 3.75, 5.0], "dt_coefficient": [0.05, 0.2]}' $D/grid_poiseuille_newtonian_2d.nc
$PY -m suspsim.convergence.sweep poiseuille_bingham3_3d '{"width": [3.75, 5.0, 7.5, 10.0], "dt_coefficient": [0.4]}' $D/grid_poiseuille_bingham3_3d.nc
$PY -m suspsim.convergence.sweep poiseuille_bingham3_3d '{"resolution": [2.4], "width": [5.0], "dt_coefficient": [0.4]}' $D/grid_poiseuille_bingham3_3d_q2.4.nc
