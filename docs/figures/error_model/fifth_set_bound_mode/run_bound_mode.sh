#!/bin/sh
# The fifth held-out set (run_holdout_blind_5.sh) in the bound mode (--no-verify: one run of the
# inflated-bound pick), for comparison with the verified mode; run after the verified pass, with
# the same model and comparison. From the repository root:
# sh docs/figures/error_model/fifth_set_bound_mode/run_bound_mode.sh > docs/figures/error_model/fifth_set_bound_mode/run_bound_mode.log 2>&1
PY=${PYTHON:-python}
D=docs/figures/error_model/fifth_set_bound_mode
for spec in couette_papanastasiou_bn6_2d:0.05 couette_papanastasiou_bn6_2d:0.02 \
            poiseuille_bingham8_3d:0.1 poiseuille_bingham8_3d:0.07 \
            poiseuille_newtonian_re1_2d:0.05 poiseuille_newtonian_re1_2d:0.02; do
  case=${spec%%:*}; tol=${spec##*:}
  $PY -m suspsim.convergence.holdout $case $tol $D/holdout_${case}_${tol}.nc 12 --bound
done
