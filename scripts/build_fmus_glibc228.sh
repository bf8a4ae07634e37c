#!/usr/bin/env bash
# The one build of the FMUs: the shared library, the packer (build_fmus) and the case
# runner (wheelflat_case) built against the glibc 2.28 baseline (docs/guide/fmus.md,
# "Where the FMUs run") by cargo-zigbuild with zig, both from PyPI (pinned below, into
# target/ziglang); fmu/*.fmu, the C header and fmu/systems packed from that library;
# then objdump -T checks that neither the library nor the runner needs a glibc symbol
# version above 2.28. The README's main command (python/wheelflat_fmus.py, build_fmus),
# the test command and the wheel (python/setup.py) all build through here. cargo's
# progress goes to stderr, the packer's list to stdout.
#   bash scripts/build_fmus_glibc228.sh [OUT_DIR]
set -euo pipefail
# A relative OUT_DIR is the caller's, resolved before moving to the repository.
out="${1:-$(dirname "$0")/../fmu}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
cd "$(dirname "$0")/.."
# $CARGO_TARGET_DIR, when set, relative to the repository (as python/wheelflat_fmus.py reads it).
target_dir="${CARGO_TARGET_DIR:-target}"
baseline=2.28
# zig and cargo-zigbuild in the build folder (not .venv, which the test command fills
# meanwhile), installed again when the pins change.
tools="$target_dir/ziglang"
pins="cargo-zigbuild==0.24.0 ziglang==0.17.1"
if [ "$(cat "$tools/pins" 2>/dev/null)" != "$pins" ]; then
    echo "build_fmus_glibc228.sh: installing $pins (PyPI) into $tools" >&2
    rm -rf "$tools"
    # shellcheck disable=SC2086
    python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore --target "$tools" $pins
    echo "$pins" >"$tools/pins"
fi
command -v objdump >/dev/null || { echo "error: objdump (binutils) is needed to check the glibc baseline" >&2; exit 1; }
export PATH="$(cd "$tools/ziglang" && pwd):$(cd "$tools/bin" && pwd):$PATH"
triple=x86_64-unknown-linux-gnu
built="$target_dir/$triple/release"
[ -e "$built/libwheelflat.so" ] || echo "build_fmus_glibc228.sh: first build of the FMUs' library, packer and case runner (cargo-zigbuild; about two minutes on 2 cores, cargo's progress follows)" >&2
cargo zigbuild --release --lib --bin build_fmus --bin wheelflat_case --target "$triple.$baseline"
# The packer packs the library beside it (target/x86_64-unknown-linux-gnu/release/).
WHEELFLAT_FMU_LIBRARY="$built/libwheelflat.so" "$built/build_fmus" "$out"
for f in "$built/libwheelflat.so" "$built/wheelflat_case"; do
    newest=$(objdump -T "$f" | grep -o 'GLIBC_[0-9][0-9.]*' | sort -uV | tail -1)
    echo "$f: newest glibc symbol version needed: $newest"
    if [ "$(printf '%s\n' "$newest" "GLIBC_$baseline" | sort -V | tail -1)" != "GLIBC_$baseline" ]; then
        echo "error: $f needs $newest, above the $baseline baseline" >&2
        exit 1
    fi
done
