#!/usr/bin/env bash
# The README's test command: every Rust test (unit, integration, doc tests), then the Python
# package built, installed into a virtual environment and tested with pytest
# (scripts/test-python.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test
./scripts/test-python.sh
