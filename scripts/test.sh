#!/usr/bin/env bash
# The project's test command (README.md); CI runs it through .ci/run.
# Needs only Rust, Python 3.11 with pip and a C compiler; Python packages go into .venv.
set -euo pipefail
cd "$(dirname "$0")/.."

# The independent importer's test (the fmi crate, run last) builds from the start at the
# lowest priority, on what time the rest leaves. bindgen inside it needs libclang (the
# PyPI package, into the build folder) and the C compiler's own headers.
clang="${CARGO_TARGET_DIR:-target}/libclang"
[ -d "$clang/clang/native" ] || python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore --target "$clang" "libclang==18.1.1"
export LIBCLANG_PATH="$(cd "$clang/clang/native" && pwd)"
export BINDGEN_EXTRA_CLANG_ARGS="-I$(cc -print-file-name=include)"
fmi_log="$(mktemp)"
nice -n 19 cargo test --no-run --manifest-path tests/fmi_import/Cargo.toml >"$fmi_log" 2>&1 &
fmi_build=$!

echo "== Rust: format, lints, engine and FMI-layer tests"
cargo fmt --check
cargo clippy --all-targets -- -D warnings
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --quiet
cargo build --release
# The examples are not built here: clippy above checks them, and the guide's commands
# that run one (tests/test_docs.py) build it.
cargo test --release --lib --bins --tests

echo "   (${SECONDS} s so far)"
echo "== FMUs: pack fmu/*.fmu, the C header and fmu/systems, the library against the glibc 2.28 baseline"
# The one build of the FMUs, the README's main command's and the wheel's: cargo-zigbuild
# against glibc 2.28 (objdump -T checked; tests/test_fmu_build.py checks what the main
# command leaves), while .venv (python/requirements.txt) is set up beside it (pip works
# on one core, the build on both).
venv_log="$(mktemp)"
python3 python/wheelflat_fmus.py >"$venv_log" 2>&1 &
venv_setup=$!
bash scripts/build_fmus_glibc228.sh fmu
venv_rc=0
wait "$venv_setup" || venv_rc=$?
cat "$venv_log"
[ "$venv_rc" -eq 0 ] || exit "$venv_rc"

echo "   (${SECONDS} s so far)"
echo "== Python: .venv with fmpy, libcosimpy and ecospy, then the FMU tests"
# ecospy's library needs oneTBB (Debian's libtbb12); CI runs as root with Debian's registries.
if ! ldconfig -p | grep libtbb.so.12 >/dev/null; then
    sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq libtbb12
fi
python3 python/wheelflat_fmus.py
# The Reference-FMUs' C fmusim v0.0.39 (tests/fmusim/, Debian's libminizip-dev) for
# test_fmi3_fmusim.py: about 6 s from scratch, nothing when built.
bash scripts/build_fmusim.sh
# test_fmi3.py: the FMI 3.0 FMUs (fmu/fmi3/) in fmpy against the FMI 2.0 ones, bit for bit.
# test_masters.py: the shipped fmu/systems/ in libcosim and ecos against CoupledSystem.
# test_fmi3_masters.py: the FMI 3.0 FMUs (fmu/fmi3/) in ecos against FMI 2.0 (issue 43; libcosim loads no FMI 3.0).
# test_importers.py: the guide's recipes for the importers that stop at a warning (C fmusim,
# OMSimulator), the FMUs called as those call them (1 s).
# test_fmi3_fmusim.py: fmu/fmi3/ CoupledSystem and TrackContact in C fmusim against fmpy,
# to the 16 digits fmusim prints (1 s).
# test_docs.py: the commands of README.md and docs/guide/ run (or matched to the test
# that runs them) and the documentation's links. One process: test_fmu_build.py's main
# command and test_docs.py's guide scripts pack fmu/ again, which the others read (two
# pytest-xdist workers took 2.5 min off, but one of five runs lost a study command to an
# abort at its exit, to be found).
.venv/bin/python -m pytest -q tests/test_fmu_build.py tests/test_fmu_descriptions.py tests/test_fmu_states.py tests/test_fmu_unload.py tests/test_fmu_coupling.py tests/test_fmu_derivatives.py tests/test_fmi3.py tests/test_study_runs.py tests/test_study_cases.py tests/test_study_summary.py tests/test_masters.py tests/test_fmi3_masters.py tests/test_importers.py tests/test_fmi3_fmusim.py tests/test_docs.py tests/test_supports.py tests/test_accelerations.py tests/test_irregularities.py tests/test_random_track.py tests/test_spectra.py tests/test_wagon.py tests/test_two_axle.py tests/test_numpy_track.py tests/test_figures.py tests/test_regression_kit.py tests/test_partner_bogie.py tests/test_partner_bogie3.py tests/test_receptance.py
fmi_rc=0
wait "$fmi_build" || fmi_rc=$?
cat "$fmi_log"
[ "$fmi_rc" -eq 0 ] || exit "$fmi_rc"

echo "   (${SECONDS} s so far)"
echo "== Rust: the FMUs through an independent importer (the fmi crate)"
cargo test --manifest-path tests/fmi_import/Cargo.toml
echo "== done in ${SECONDS} s"
