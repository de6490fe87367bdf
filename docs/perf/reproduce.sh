#!/bin/sh
# Reproduces every number and plot of the README's "Performance" section (about 15 minutes on
# 2 cores): the matched-error benchmarks, the GGL error-test measurement, and both sweeps.
set -e
cd "$(dirname "$0")/../.."
cargo bench --bench mechanisms | tee docs/perf/mechanisms.txt
cargo bench --bench ggl_error_test | tee docs/perf/ggl_error_test.txt
cargo build --release --bin bondmech
for s in double_pendulum slider_crank; do
  mkdir -p "docs/perf/$s"
  ./target/release/bondmech sweep "scenes/$s.json" --repeats 3 --t-end 1 --out "docs/perf/$s" | tee "docs/perf/$s/table.txt"
done
