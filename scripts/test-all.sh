#!/usr/bin/env bash
# The README's test command: every Rust test (unit, integration, doc tests), then the Python
# package built, installed into a virtual environment and tested with pytest
# (scripts/test-python.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test
# cargo test built the command line for its integration tests: the Python tests compare with it
BONDMECH_CLI="$PWD/target/debug/bondmech" ./scripts/test-python.sh
