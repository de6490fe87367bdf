#!/usr/bin/env bash
# Pre-flight check, run by scripts/install-deps.sh before cargo ever starts.
#
# sundials-sys (links = "sundials") runs its build script *before* bondmech's build.rs, and
# falls back to building its vendored SUNDIALS 7.x with cmake when bindgen cannot read the
# system headers. So the system headers and libclang are checked here, up front:
#   - $SUNDIALS_INCLUDE_DIR (default /usr/include) has idas/idas.h, cvodes/cvodes.h and
#     sundials/sundials_config.h with SUNDIALS_VERSION_MAJOR 6;
#   - a libclang shared library is where clang-sys (used by bindgen) looks for it
#     ($LIBCLANG_PATH if set, else /usr/lib*, /usr/lib*/*, /usr/lib/llvm-*/lib, /usr/local/lib*).
# Exits 1 with the exact apt-get line when anything is missing.
set -euo pipefail
hint="apt-get install libsundials-dev libclang-dev pkg-config"
fail() {
  echo "error: $1" >&2
  echo "install the system packages with:" >&2
  echo "    sudo $hint" >&2
  echo "(or point SUNDIALS_INCLUDE_DIR / SUNDIALS_LIBRARY_DIR at a SUNDIALS 6.x install," >&2
  echo " LIBCLANG_PATH at a libclang; see vendor-notes/sundials.md)" >&2
  exit 1
}

inc="${SUNDIALS_INCLUDE_DIR:-/usr/include}"
for h in idas/idas.h cvodes/cvodes.h sundials/sundials_config.h; do
  [ -f "$inc/$h" ] || fail "SUNDIALS header $inc/$h not found"
done
major=$(awk '$1 == "#define" && $2 == "SUNDIALS_VERSION_MAJOR" { print $3 }' \
  "$inc/sundials/sundials_config.h")
[ "$major" = "6" ] || \
  fail "$inc/sundials/sundials_config.h declares SUNDIALS_VERSION_MAJOR '${major:-<missing>}', bondmech needs 6"

shopt -s nullglob
if [ -n "${LIBCLANG_PATH:-}" ]; then
  dirs=("$LIBCLANG_PATH")
else
  dirs=(/usr/lib* /usr/lib*/* /usr/lib/llvm-*/lib /usr/local/lib* /usr/local/lib*/*)
fi
found=""
for d in "${dirs[@]}"; do
  for f in "$d"/libclang.so "$d"/libclang.so.* "$d"/libclang-*.so "$d"/libclang-*.so.*; do
    case "$f" in *libclang-cpp*) continue ;; esac
    [ -f "$f" ] && { found="$f"; break 2; }
  done
done
[ -n "$found" ] || fail "libclang (needed by bindgen in sundials-sys) not found in ${dirs[*]}"

echo "bondmech deps ok: SUNDIALS $(awk '$2 == "SUNDIALS_VERSION" { gsub("\"", "", $3); print $3 }' \
  "$inc/sundials/sundials_config.h") headers in $inc, libclang at $found" >&2
