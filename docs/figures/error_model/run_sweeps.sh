#!/bin/sh
# Grid sweeps near the cheap end that the error model (suspsim.convergence.error_model) is
# fitted on beside docs/figures/speed_error/*.nc; training cases only. Run from the repository
# root: sh docs/figures/error_model/run_sweeps.sh
set -e
PY=${PYTHON:-python}
D=docs/figures/error_model
$PY -m suspsim.convergence.sweep couette_newtonian_2d '{"resolution": [2.5, 3.0, 4.0], "wi_target": [0.001, 0.003, 0.01], "side": [5.0, 10.0]}' $D/grid_couette_newtonian_2d.nc
$PY -m suspsim.convergence.sweep couette_papanastasiou_bn9.9_3d '{"resolution": [1.6, 2.4], "wi_target": [0.001, 0.01], "dt_coefficient": [0.05, 0.2, 0.4], "side": [5.0]}' $D/grid_couette_papanastasiou_bn9.9_3d.nc
$PY -m suspsim.convergence.sweep poiseuille_bingham1_3d '{"dt_coefficient": [0.2, 0.3, 0.4, 0.6], "width": [3.75, 5.0, 7.5]}' $D/grid_poiseuille_bingham1_3d.nc
$PY -m suspsim.convergence.sweep couette_newtonian_3d '{"resolution": [1.6, 2.4, 3.2], "wi_target": [0.001, 0.003, 0.01], "side": [5.0]}' $D/grid_couette_newtonian_3d.nc
$PY -m suspsim.convergence.sweep poiseuille_newtonian_3d '{"resolution": [1.6, 2.4], "width": [2.5, 3.75, 5.0, 7.5], "wi_target": [0.001, 0.01]}' $D/grid_poiseuille_newtonian_3d.nc
$PY -m suspsim.convergence.sweep poiseuille_bingham1_3d '{"resolution": [2.4], "dt_coefficient": [0.3], "width": [5.0]}' $D/grid_poiseuille_bingham1_3d_q2.4.nc
