#!/usr/bin/env bash
# The per-step cost of IDA on the dae formulation from a callgrind profile of one `bondmech run`
# (instructions, inclusive, by the SUNDIALS entry points each part goes through):
#   valgrind --tool=callgrind --callgrind-out-file=cg.out target/release/bondmech run \
#     benches/scenes/peers_double_pendulum.json --rtol 1e-9 --atol 1e-11 --out /dev/null --summary s.json
#   docs/perf/dae_breakdown.sh cg.out STEPS
# usage: breakdown.sh callgrind.out steps
f=$1; steps=$2
inc=$(callgrind_annotate --inclusive=yes --threshold=100 "$f" 2>/dev/null)
get() { echo "$inc" | grep -F "$1" | head -1 | awk '{gsub(",","",$1); print $1}'; }
solve=$(get ':IDASolve ')
res=$(get 'ida::residual_trampoline ')
jac=$(get 'ida::jacobian_trampoline '); [ -z "$jac" ] && jac=$(get 'ida::sparse_jacobian_trampoline ')
setup=$(get ':SUNLinSolSetup ')
lsolve=$(get ':SUNLinSolSolve ')
vec=0; for fn in N_VLinearCombination N_VLinearSum N_VScale N_VWrmsNorm N_VWrmsNormMask N_VLinearSumVectorArray N_VScaleVectorArray N_VConst N_VAbs N_VInv N_VAddConst N_VProd N_VDiv N_VMaxNorm N_VCompare N_VMin N_VScaleAddMulti N_VDotProd; do v=$(get ":$fn "); vec=$((vec + ${v:-0})); done
zero=$(get ':SUNMatZero_Dense '); zero=${zero:-$(get ':SUNMatZero_Sparse ')}
jac=$(( ${jac:-0} + ${zero:-0} ))
own=$((solve - res - jac - setup - lsolve - vec))
printf "%-28s %12s %10s %8s\n" part instructions "per step" share
for p in "residual:$res" "Jacobian (eval+zero):$jac" "factorisation (LS setup):$setup" "solve (LS solve):$lsolve" "IDA vector work (N_V*):$vec" "IDA/SUNDIALS own code:$own" "IDASolve total:$solve"; do
  name=${p%%:*}; n=${p##*:}
  printf "%-28s %12d %10.0f %7.1f%%\n" "$name" "$n" "$(echo "$n/$steps" | bc -l)" "$(echo "100*$n/$solve" | bc -l)"
done
