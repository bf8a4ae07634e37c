#!/usr/bin/env bash
# The FMUs on an older Linux: packs them against the glibc 2.28 baseline
# (scripts/build_fmus_glibc228.sh), makes a Debian 11 (bullseye, glibc 2.31) root file
# system with debootstrap from Debian's packages in a folder of its own, and runs
# CoupledSystem there through its C interface with that system's Python
# (tests/old_glibc/harness.py, standard library only); the peak must equal the host's
# bit for bit. Needs root and Debian's package servers; about 1.5 minutes of debootstrap
# the first time, seconds after.
#   bash scripts/test_old_glibc.sh [WORK_DIR]     (kept, so a second run reuses the root)
set -euo pipefail
# A relative WORK_DIR is the caller's, resolved before moving to the repository.
work="${1:-$(mktemp -d)}"
mkdir -p "$work"
work="$(cd "$work" && pwd)"
cd "$(dirname "$0")/.."
bash scripts/build_fmus_glibc228.sh "$work/fmu"
root="$work/bullseye"
if [ ! -x "$root/usr/bin/python3" ]; then
    command -v debootstrap >/dev/null || { apt-get update -qq && apt-get install -y -qq debootstrap; }
    debootstrap --variant=minbase --include=python3 bullseye "$root" http://deb.debian.org/debian >/dev/null
fi
rm -rf "$root/fmu" && mkdir -p "$root/fmu"
python3 -m zipfile -e "$work/fmu/CoupledSystem.fmu" "$root/fmu"
cp tests/old_glibc/harness.py "$root/harness.py"
host=$(python3 tests/old_glibc/harness.py "$root/fmu" 0.06)
old=$(chroot "$root" /usr/bin/python3 /harness.py /fmu 0.06)
echo "host:      $host"
echo "Debian 11: $old"
[ "${host%% glibc*}" = "${old%% glibc*}" ] || { echo "error: the peaks differ" >&2; exit 1; }
echo "the FMU loads and steps on Debian 11 with the same peak"
