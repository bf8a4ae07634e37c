#!/usr/bin/env bash
# Packs fmu/*.fmu with the shared library built against glibc 2.28 (RHEL 8, Debian 10's
# 2.28, Ubuntu 20.04's 2.31 and later load it), by cargo-zigbuild (crates.io) with zig
# (the PyPI package ziglang, in target/ziglang); then checks with objdump -T that no glibc symbol
# version above 2.28 is needed. The normal `cargo build` and `build_fmus` are untouched.
#   bash scripts/build_fmus_glibc228.sh [OUT_DIR]
set -euo pipefail
# A relative OUT_DIR is the caller's, resolved before moving to the repository.
out="${1:-$(dirname "$0")/../fmu}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
cd "$(dirname "$0")/.."
# zig in the build folder (not .venv, which the test command fills meanwhile).
zig="${CARGO_TARGET_DIR:-target}/ziglang"
[ -x "$zig/ziglang/zig" ] || python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore --target "$zig" "ziglang==0.17.1"
export PATH="$(cd "$zig/ziglang" && pwd):$HOME/.cargo/bin:$PATH"
command -v cargo-zigbuild >/dev/null || cargo install --locked -q cargo-zigbuild
target=x86_64-unknown-linux-gnu
cargo zigbuild --release --quiet --lib --target "$target.2.28"
cargo build --release --quiet --bin build_fmus
lib="${CARGO_TARGET_DIR:-target}/$target/release/libwheelflat.so"
WHEELFLAT_FMU_LIBRARY="$lib" "${CARGO_TARGET_DIR:-target}/release/build_fmus" "$out"
newest=$(objdump -T "$lib" | grep -o 'GLIBC_[0-9.]*' | sort -uV | tail -1)
echo "newest glibc symbol version needed: $newest"
if [ "$(printf '%s\n' "$newest" GLIBC_2.28 | sort -V | tail -1)" != GLIBC_2.28 ]; then
    echo "error: $lib needs $newest, above the 2.28 baseline" >&2
    exit 1
fi
