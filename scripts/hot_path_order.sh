#!/usr/bin/env bash
# Regenerates linux/preload/hot_path.order: the functions of libl6470emu-preload.so that every SPI
# message runs through, which the link places side by side (gold's --section-ordering-file) so
# that they share the processor's instruction cache instead of evicting each other. Without it a
# change anywhere in the library moves a tight client's time per message by 10-40 % with the same
# instructions (docs/reference/performance.md).
#
# It runs the benchmark clients under valgrind's callgrind: the C client (NOP messages and
# GetStatus polls; unrecorded, recorded into a plain trace and into a .trace.gz) and, when
# python3-spidev is there, the polling Python client recorded. A function of the library that
# runs about once per message or more in any of them is on the list, sorted by name (stable diffs).
# Run it after renaming or adding functions on the message path; tests/linux/hot_path_order_test.sh
# fails when the list names a function the library no longer has.
# Usage: scripts/hot_path_order.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
client=$build/bench/l6470emu_preload_roundtrips
preload=$build/libl6470emu-preload.so
python=/usr/bin/python3
out=$root/linux/preload/hot_path.order
for f in "$client" "$preload"; do
  [ -e "$f" ] || { echo "hot_path_order: $f is missing; build the l6470emu_benchmarks target" >&2; exit 1; }
done
command -v valgrind >/dev/null || { echo "hot_path_order: needs valgrind (Debian: valgrind)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
chain="bus=0 cs=0 chips=L6470 mode=3; time=virtual"
messages=20000

# profile NAME TRACE COMMAND...: a callgrind profile of COMMAND under the preload library.
profile() {
  local name=$1 trace=$2; shift 2
  local env=(L6470EMU_CHAIN="$chain" LD_PRELOAD="$preload")
  [ -n "$trace" ] && env+=(L6470EMU_TRACE="$work/$trace")
  env "${env[@]}" valgrind --tool=callgrind --demangle=no --compress-strings=no --compress-pos=no \
    --callgrind-out-file="$work/$name.out" "$@" >/dev/null 2>&1
}
for mode in nop getstatus; do
  profile "$mode.none" "" "$client" /dev/spidev0.0 "$messages" "$mode"
  profile "$mode.plain" "r.trace" "$client" /dev/spidev0.0 "$messages" "$mode"
  profile "$mode.gz" "r.trace.gz" "$client" /dev/spidev0.0 "$messages" "$mode"
done
if "$python" -c 'import spidev' 2>/dev/null; then
  cat >"$work/poll.py" <<'EOF'
import sys
import spidev
s = spidev.SpiDev(); s.open(0, 0); s.mode = 3
x = lambda *bs: [s.xfer2([b])[0] for b in bs]
x(0x41, 0x01, 0x00, 0x00)
for _ in range(int(sys.argv[1])):
    x(0xD0, 0, 0)
    x(0x21, 0, 0, 0)
EOF
  # 7 messages per poll: a function run once per message runs 7 times per poll.
  profile "python.plain" "p.trace" "$python" "$work/poll.py" "$((messages / 7))"
fi

"$python" - "$work" "$messages" "$out" <<'EOF'
import glob, os, sys
work, messages, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
hot = set()
for path in glob.glob(os.path.join(work, "*.out")):
    calls, obj_of = {}, {}
    ob = cob = cfn = cfn_ob = None
    for line in open(path, errors="replace"):
        if line.startswith("ob="):
            ob = line[3:].strip()
        elif line.startswith("fn="):
            obj_of.setdefault(line[3:].strip(), ob)
        elif line.startswith("cob="):
            cob = line[4:].strip()
        elif line.startswith("cfn="):
            cfn, cfn_ob, cob = line[4:].strip(), cob or ob, None
        elif line.startswith("calls="):
            calls[cfn] = calls.get(cfn, 0) + int(line[6:].split()[0])
            obj_of.setdefault(cfn, cfn_ob)
    for fn, n in calls.items():
        # Once per message, give or take the first few (a run starts with its second frame).
        if 10 * n >= 9 * messages and (obj_of.get(fn) or "").endswith("libl6470emu-preload.so"):
            hot.add(fn)
if len(hot) < 20:
    sys.exit(f"hot_path_order: only {len(hot)} functions found; did the clients run?")
# A complete-object constructor or destructor (C1, D1) is often the base-object one (C2, D2)
# under a second name, in the section named after that one.
import re
for fn in list(hot):
    for a, b in (("C1E", "C2E"), ("D1E", "D2E")):
        m = re.match(r"(_ZN.*\d[A-Za-z_]\w*)" + a + "(.*)$", fn)
        if m:
            hot.add(m.group(1) + b + m.group(2))
with open(out, "w") as f:
    f.write("# The message path of libl6470emu-preload.so, placed together by the link: written by\n")
    f.write("# scripts/hot_path_order.sh (which says why); do not edit by hand.\n")
    for fn in sorted(hot):
        f.write(f".text.{fn}\n")
print(f"hot_path_order: {len(hot)} functions to {os.path.relpath(out)}")
EOF
