#!/usr/bin/env bash
# The Python package's tests: builds and installs python/ (`pip install ./python[test]`, maturin
# + PyO3) into a virtual environment, then runs pytest on python/tests against the `bondmech`
# command line that `cargo build` makes (the tests compare the two to the last digit).
#
#   BONDMECH_CLI    the command line to compare with (default: `cargo build`'s target/debug/bondmech)
#   BONDMECH_VENV   the virtual environment (default target/python-venv; created when missing)
#   BONDMECH_PYTHON_PROFILE  Cargo profile of the extension (default: pyproject.toml's, release;
#                   CI passes `dev` to reuse the dependencies `cargo test` compiled)
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${BONDMECH_VENV:-target/python-venv}"
python="${PYTHON:-python3}"
if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
fi
venv="$(cd "$venv" && pwd)"
if [ -n "${BONDMECH_PYTHON_PROFILE:-}" ]; then
    export MATURIN_PEP517_ARGS="--profile ${BONDMECH_PYTHON_PROFILE}"
fi
start=$(date +%s)
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "./python[test]"
echo "python package built and installed in $(( $(date +%s) - start )) s (${MATURIN_PEP517_ARGS:-release profile})"
# the command line the tests compare against (`cargo test` builds it too, for its integration
# tests: scripts/test-all.sh passes that one, with the dependencies' features cargo test chose)
if [ -z "${BONDMECH_CLI:-}" ]; then
    cargo build --quiet --bin bondmech
    export BONDMECH_CLI="$PWD/target/debug/bondmech"
fi
# from the root, so that `import bondmech` is the installed package (python/bondmech has no
# compiled module)
"$venv/bin/python" -m pytest python/tests -q -p no:cacheprovider "$@"
