#!/bin/sh
# Held-out validation of --tolerance (suspsim.convergence.holdout) on cases the error model was
# not fitted on. Run from the repository root: sh docs/figures/error_model/run_holdout.sh
PY=${PYTHON:-python}
D=docs/figures/error_model
for spec in couette_papanastasiou_bn99_3d:0.05 couette_papanastasiou_bn99_3d:0.02 \
            poiseuille_newtonian_2d:0.1 poiseuille_newtonian_2d:0.05 \
            poiseuille_bingham10_3d:0.1 poiseuille_bingham10_3d:0.05; do
  case=${spec%%:*}; tol=${spec##*:}
  $PY -m suspsim.convergence.holdout $case $tol $D/holdout_${case}_${tol}.nc 6
done
