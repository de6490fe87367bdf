#!/usr/bin/env bash
# The default formulation measured "the hard way" (issue 25): the cpu_seconds of the summary of
# single `bondmech run` processes (integration and output rows only; no --formulation: the
# scene's default), median of 5 processes, at rtol 1e-6 … 1e-10 (atol = rtol/100), on the two
# problems of ../shared/docs/peers.md (benches/scenes/peers_*.json). The errors at those
# tolerances (deterministic: the same solves) and the limit (the minimal-coordinate model on
# CVODE BDF, timed in a hot loop of repeated solves in one process) come from
# `cargo bench --bench dae_speed`.
# Usage: dae_hard_way.sh [extra run flags...]
set -euo pipefail
cd "$(dirname "$0")/../.."
[ -n "${SKIP_BUILD:-}" ] || nice -n 10 cargo build --release --bin bondmech
summary=$(mktemp)
for scene in peers_double_pendulum peers_slider_crank; do
  for e in 6 7 8 9 10; do
    rtol="1e-$e"
    atol="1e-$((e + 2))"
    cpus=()
    for _ in 1 2 3 4 5; do
      ./target/release/bondmech run "benches/scenes/$scene.json" \
        --rtol "$rtol" --atol "$atol" "$@" --out /dev/null --summary "$summary"
      cpus+=("$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['cpu_seconds'])" "$summary")")
    done
    median=$(printf '%s\n' "${cpus[@]}" | sort -g | sed -n 3p)
    info=$(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['formulation'], d['solver'], d['steps'], 'steps')" "$summary")
    echo "$scene rtol $rtol: median cpu_seconds $median ($info)"
  done
done
rm -f "$summary"
