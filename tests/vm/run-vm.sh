#!/usr/bin/env bash
# Runs one command inside the test VM (QEMU TCG, Debian's stock kernel, the host's root
# read-only over 9p) and exits with its exit code. Usage: run-vm.sh VM_DIR COMMAND...
# VM_DIR is what build-vm.sh wrote. The command runs as root in the guest with the host's
# paths (a checkout or build under /tmp or /run too: they are bound over the guest's tmpfs);
# /tmp/vmwork is a directory shared with the host (kept on failure when L6470EMU_VM_KEEP=1).
# Exit 124 when the VM did not finish within L6470EMU_VM_TIMEOUT s (300). L6470EMU_VM_SMP sets
# the guest's CPUs (default 1), L6470EMU_VM_ICOUNT its clock (below).
set -euo pipefail
vm=${1:?usage: run-vm.sh VM_DIR COMMAND...}
shift
[ $# -gt 0 ] || { echo "usage: run-vm.sh VM_DIR COMMAND..." >&2; exit 2; }
for f in vmlinuz initramfs.cpio.gz; do
  [ -f "$vm/$f" ] || { echo "run-vm: $vm/$f is missing (run tests/vm/build-vm.sh $vm)" >&2; exit 2; }
done
command -v qemu-system-x86_64 >/dev/null || { echo "run-vm: qemu-system-x86_64 is missing (package qemu-system-x86)" >&2; exit 2; }
work=$(mktemp -d /tmp/l6470emu-vm.XXXXXX)
cleanup() { [ "${L6470EMU_VM_KEEP:-0}" = 1 ] && echo "run-vm: kept $work" || rm -rf "$work"; }
trap cleanup EXIT
{
  printf 'cd %q\n' "$PWD"
  for v in L6470EMU_BUILD L6470EMU_SOURCE; do
    [ -n "${!v:-}" ] && printf 'export %s=%q\n' "$v" "${!v}"
  done
  printf '%q ' "$@"
  echo
} > "$work/command"
# The directories the command reads that the guest's tmpfs on /tmp and /run would hide: the
# working directory, the checkout and the build (tests/vm/init.sh binds them back), outermost first.
for d in "$PWD" "${L6470EMU_SOURCE:-}" "${L6470EMU_BUILD:-}"; do
  [ -n "$d" ] && [ -d "$d" ] || continue
  d=$(cd "$d" && pwd -P)
  case "$d" in /tmp|/tmp/*|/run|/run/*) echo "$d" ;; esac
done | sort -u | awk 'NR == 1 || index($0, last "/") != 1 { print; last = $0 }' > "$work/keep"
start=$(date +%s%N)
set +e
# The guest's time must not follow the host's load (docs/linux.md, "Kernel nodes"): one virtual
# CPU (L6470EMU_VM_SMP), and a guest clock that counts executed instructions, 2^N ns each
# (L6470EMU_VM_ICOUNT=N, default 0; "off" = the host's clock), skipping idle time.
icount=()
[ "${L6470EMU_VM_ICOUNT:-0}" != off ] && icount=(-icount "shift=${L6470EMU_VM_ICOUNT:-0},sleep=off")
timeout "${L6470EMU_VM_TIMEOUT:-300}" qemu-system-x86_64 -accel tcg -m 1024 -smp "${L6470EMU_VM_SMP:-1}" "${icount[@]}" \
  -nographic -no-reboot -nic none \
  -kernel "$vm/vmlinuz" -initrd "$vm/initramfs.cpio.gz" \
  -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
  -virtfs "local,path=$work,mount_tag=work,security_model=none,multidevs=remap" \
  -append "console=ttyS0 quiet loglevel=3 panic=-1" </dev/null | tr -d '\r'
qemu=${PIPESTATUS[0]}
set -e
elapsed_ms=$((($(date +%s%N) - start) / 1000000))
printf 'run-vm: %d.%d s in the VM\n' $((elapsed_ms / 1000)) $((elapsed_ms % 1000 / 100))
if [ "$qemu" = 124 ]; then echo "run-vm: the VM did not finish in ${L6470EMU_VM_TIMEOUT:-300} s" >&2; exit 124; fi
[ -f "$work/exit-code" ] || { echo "run-vm: the command did not complete in the VM (qemu exit $qemu)" >&2; exit 1; }
exit "$(cat "$work/exit-code")"
