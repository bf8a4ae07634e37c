#!/usr/bin/env bash
# Builds the Reference-FMUs' C fmusim (v0.0.39, vendored in tests/fmusim/, see its
# README.md) into ${CARGO_TARGET_DIR:-target}/fmusim/fmusim, for tests/test_fmi3_fmusim.py.
# Skips the build when that binary was built from the same sources and flags.
#
# Needs a C compiler and Debian's libxml2-dev, zlib1g-dev and libminizip-dev (installed
# here when missing, as root or through sudo). Built without SUNDIALS CVODE (no_cvode.c):
# Debian 12's libsundials-dev is 6.4.1, fmusim v0.0.39 is written against 7.x, and the
# Co-Simulation runs need no ODE solver.
set -euo pipefail
self="$(cd "$(dirname "$0")" && pwd)/$(basename "$0")"
cd "$(dirname "$self")/.."

vendored=tests/fmusim
out="${CARGO_TARGET_DIR:-target}/fmusim"
# Upstream's sources draw GCC warnings (incompatible pointer types, an error from GCC 14 on).
CFLAGS=(-O2 -w -Wno-incompatible-pointer-types -DFMUSIM_VERSION='"v0.0.39"')
LIBS=(-lxml2 -lminizip -lz -ldl -lm)

# The sources, this script, the flags and the compiler decide the binary.
inputs() {
    (cd "$vendored" && find . -type f -print0 | LC_ALL=C sort -z | xargs -0 sha256sum)
    sha256sum "$self"
    echo "${CFLAGS[*]} ${LIBS[*]} $(cc -dumpfullversion 2>/dev/null || true)"
}
stamp="$(inputs | sha256sum | cut -d' ' -f1)"
if [ -x "$out/fmusim" ] && [ "$(cat "$out/stamp" 2>/dev/null)" = "$stamp" ]; then
    echo "fmusim: up to date ($out/fmusim)"
    exit 0
fi

# Debian's headers and libraries, those missing only (libxml2-dev and zlib1g-dev come
# with the machine image; libminizip-dev does not).
pkgs=()
[ -f /usr/include/libxml2/libxml/parser.h ] || pkgs+=(libxml2-dev)
[ -f /usr/include/zlib.h ] || pkgs+=(zlib1g-dev)
[ -f /usr/include/minizip/unzip.h ] || pkgs+=(libminizip-dev)
if [ "${#pkgs[@]}" -gt 0 ]; then
    sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
    apt=($sudo env DEBIAN_FRONTEND=noninteractive apt-get)
    # apt-get update only where the install fails (package lists missing or stale).
    "${apt[@]}" install -y -qq "${pkgs[@]}" >/dev/null 2>&1 || {
        "${apt[@]}" update -qq
        "${apt[@]}" install -y -qq "${pkgs[@]}" >/dev/null
    }
fi

# A fresh copy, compiled in one call.
rm -rf "$out"
mkdir -p "$out/src"
cp -R "$vendored/fmusim" "$vendored/include" "$vendored/src" "$vendored/no_cvode.c" "$out/src/"
(
    cd "$out/src"
    cc "${CFLAGS[@]}" -Ifmusim -Iinclude -I/usr/include/libxml2 -I/usr/include/minizip \
        fmusim/*.c src/*.c no_cvode.c -o ../fmusim "${LIBS[@]}"
)
echo "$stamp" >"$out/stamp"
echo "fmusim: built $out/fmusim ($("$out/fmusim" --version))"
