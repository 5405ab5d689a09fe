#!/usr/bin/env bash
# ctest entry of a VM test: builds the VM files (once, into BUILD/vm) and runs GUEST_SCRIPT in
# the VM. Exits 77 (skipped, with the reason printed) when this machine cannot run the VM.
# Usage: run-test.sh SOURCE_DIR BUILD_DIR GUEST_SCRIPT
set -euo pipefail
source_dir=$1 build_dir=$2 script=$3
skip() { echo "SKIPPED: $*"; exit 77; }
[ "$(id -u)" -eq 0 ] || skip "the VM tests run as root (QEMU shares the host's root over 9p)"
command -v qemu-system-x86_64 >/dev/null || skip "qemu-system-x86_64 missing (scripts/setup.sh installs qemu-system-x86)"
[ -x /bin/busybox ] || skip "/bin/busybox missing (package busybox-static)"
t0=$(date +%s%N)
"$source_dir/tests/vm/build-vm.sh" "$build_dir/vm"
echo "run-test: VM files ready in $(( ($(date +%s%N) - t0) / 1000000 )) ms (kernel $(cat "$build_dir/vm/kernel-version"))"
export L6470EMU_BUILD=$build_dir L6470EMU_SOURCE=$source_dir
exec "$source_dir/tests/vm/run-vm.sh" "$build_dir/vm" /bin/sh "$script"
