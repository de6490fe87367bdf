#!/usr/bin/env bash
# Installs the Debian packages bondmech needs, only when they are missing:
#   libsundials-dev (SUNDIALS 6.4: IDA, CVODE), libclang-dev (bindgen), pkg-config, graphviz (SVG drawings)
#   and, when `python3` cannot make a virtual environment with pip (the Python package's tests,
#   scripts/test-python.sh), python3 python3-venv python3-pip
# then runs scripts/check-deps.sh, which verifies the SUNDIALS 6.x headers and libclang are really
# usable before cargo starts (sundials-sys would otherwise silently build its vendored 7.x).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
pkgs=(libsundials-dev libclang-dev pkg-config graphviz)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
  missing+=(python3 python3-venv python3-pip)
fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
"$here/check-deps.sh"
