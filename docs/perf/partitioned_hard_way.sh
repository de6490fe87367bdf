#!/usr/bin/env bash
# The partitioned formulation measured "the hard way" (issue 14): the cpu_seconds of the summary
# of single `bondmech run` processes (integration and output rows only), median of 5 processes,
# at rtol 1e-6 … 1e-10 (atol = rtol/100). The errors at those tolerances (deterministic: the
# same solves) and the limit (the minimal-coordinate model on CVODE BDF, timed in a hot loop of
# repeated solves in one process) come from `cargo bench --bench partitioned_speed`.
# Usage: partitioned_hard_way.sh [auto|adams|bdf|erk]   (solve.integrator, default auto)
set -euo pipefail
cd "$(dirname "$0")/../.."
integrator="${1:-auto}"
[ -n "${SKIP_BUILD:-}" ] || nice -n 10 cargo build --release --bin bondmech
summary=$(mktemp)
for scene in double_pendulum slider_crank; do
  for e in 6 7 8 9 10; do
    rtol="1e-$e"
    atol="1e-$((e + 2))"
    cpus=()
    for _ in 1 2 3 4 5; do
      ./target/release/bondmech run "scenes/$scene.json" --formulation partitioned \
        --rtol "$rtol" --atol "$atol" --set "solve.integrator=\"$integrator\"" \
        --out /dev/null --summary "$summary"
      cpus+=("$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['cpu_seconds'])" "$summary")")
    done
    median=$(printf '%s\n' "${cpus[@]}" | sort -g | sed -n 3p)
    integ=$(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['integrator'], d['steps'])" "$summary")
    echo "$scene rtol $rtol: median cpu_seconds $median ($integ)"
  done
done
rm -f "$summary"
