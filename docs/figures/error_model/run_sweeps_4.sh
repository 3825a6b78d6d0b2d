#!/bin/sh
# Fourth set of training sweeps (after the third held-out pass, before the blind one of
# run_holdout_blind.sh): the cases held out so far become training data. The 2D Newtonian
# channel (no 2D channel was in training: the model over-predicted it 2.5-4.5x) over q, width
# and time step, and the Bingham channel at Bn = 10 at the smaller steps (the third pass ran it
# at C = 0.4 only, 7.8-8.9 %; the validation measured 4.1 % at W = 10 h, C = 0.05). Run from
# the repository root:
# sh docs/figures/error_model/run_sweeps_4.sh > docs/figures/error_model/run_sweeps_4.log 2>&1
set -e
PY=${PYTHON:-python}
D=docs/figures/error_model
$PY -m suspsim.convergence.sweep poiseuille_newtonian_2d '{"resolution": [2.5, 4.0], "width": [2.5, 3.75, 7.5, 10.0], "dt_coefficient": [0.05, 0.4]}' $D/grid_poiseuille_newtonian_2d_4.nc
$PY -m suspsim.convergence.sweep poiseuille_newtonian_2d '{"resolution": [3.0, 4.0], "width": [3.75, 5.0], "wi_target": [0.003, 0.01], "dt_coefficient": [0.2]}' $D/grid_poiseuille_newtonian_2d_wi.nc
$PY -m suspsim.convergence.sweep poiseuille_bingham10_3d '{"dt_coefficient": [0.4, 0.1], "width": [5.0]}' $D/grid_poiseuille_bingham10_3d_w5.nc
$PY -m suspsim.convergence.sweep poiseuille_bingham10_3d '{"dt_coefficient": [0.2, 0.1], "width": [7.5, 10.0]}' $D/grid_poiseuille_bingham10_3d.nc
$PY -m suspsim.convergence.sweep poiseuille_bingham10_3d '{"width": [7.5]}' $D/grid_poiseuille_bingham10_3d_c0.05.nc
