#!/usr/bin/env bash
# Reproduces every number and plot of the README's "Performance" section (about 20 minutes on
# 2 cores): the matched-error benchmarks, the GGL error-test measurement, and both sweeps.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo bench --bench mechanisms | tee docs/perf/mechanisms.txt
cargo bench --bench ggl_error_test | tee docs/perf/ggl_error_test.txt
cargo build --release --bin bondmech
mkdir -p docs/perf/double_pendulum docs/perf/slider_crank
./target/release/bondmech sweep scenes/double_pendulum.json --repeats 3 --t-end 1 \
  --out docs/perf/double_pendulum | tee docs/perf/double_pendulum/table.txt
# the slider-crank turns ~14 times a second: its GGL reference at rtol 1e-13 needs over a
# million steps per second of motion, so the sweep covers its first quarter second
./target/release/bondmech sweep scenes/slider_crank.json --repeats 3 --t-end 0.25 \
  --out docs/perf/slider_crank | tee docs/perf/slider_crank/table.txt
