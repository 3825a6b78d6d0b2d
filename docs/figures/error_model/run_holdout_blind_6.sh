#!/bin/sh
# Sixth blind held-out validation of --tolerance (issue 7): the verified picker of the fifth
# pass, unchanged (a variant that asks every error term to shrink after a miss was tried
# offline and refused more: 98 of 116 within 2x against 101). Four cases and two tolerances
# each, fixed and committed before any run of these cases. The model is the packaged fit of
# 2026-12-03 (error_model.json, not refitted). Run once, from the repository root:
# sh docs/figures/error_model/run_holdout_blind_6.sh > docs/figures/error_model/run_holdout_blind_6.log 2>&1
#
# No case below is in a training grid (run_sweeps*.sh, docs/figures/speed_error) or in an earlier
# held-out pass. Tolerances follow the earlier passes' rule, not the model: 5 % and 2 % for a
# viscosity or a Newtonian profile, 10 % and 7 % for a Bingham profile. Checked with the model
# only (no run): every tolerance has a first attempt.
# - couette_papanastasiou_bn45_2d: 2D rate-dependent Couette at Bn = 45, above every 2D Bn
#   (trained 9.9; held out 3, 6 and 20).
# - poiseuille_bingham2.5_3d: a Bingham channel at Bn = 2.5, between the trained 2 and 3 (the
#   first attempt is the cheapest candidate at both tolerances).
# - poiseuille_bingham9_3d: a Bingham channel at Bn = 9, between the held-out 8 (where the
#   fifth pass failed on cost) and the trained 10.
# - poiseuille_newtonian_re0.5_3d: the 3D Newtonian channel at Re = 0.5, between the held-out
#   0.25 and the trained 1.
#
# Run on 2026-12-05 with a cap of 12 comparisons; the 3D channel at 2 % had more candidates below
# its threshold, so it was re-run with a cap of 40 (sixth_set_full_comparison/, the same
# attempts): W = 5 h at C = 0.05 meets 2 % (1.997 %) in 0.40 s. The default cap is now 40.
PY=${PYTHON:-python}
D=docs/figures/error_model
for spec in couette_papanastasiou_bn45_2d:0.05 couette_papanastasiou_bn45_2d:0.02 \
            poiseuille_bingham2.5_3d:0.1 poiseuille_bingham2.5_3d:0.07 \
            poiseuille_bingham9_3d:0.1 poiseuille_bingham9_3d:0.07 \
            poiseuille_newtonian_re0.5_3d:0.05 poiseuille_newtonian_re0.5_3d:0.02; do
  case=${spec%%:*}; tol=${spec##*:}
  $PY -m suspsim.convergence.holdout $case $tol $D/holdout_${case}_${tol}.nc 12
done
