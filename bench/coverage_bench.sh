#!/usr/bin/env bash
# The cost of interface coverage (docs/coverage.md) on the preload benchmark's clients: each
# client runs under libl6470emu-preload.so in virtual time without and with L6470EMU_COVERAGE,
# alternately, ROUNDS times; the best run of each is kept and their ratio printed (goal <= 1.10x).
# Clients: the C client of bench/preload_bench.sh sending NOPs and polling GetStatus, and Debian's
# python3-spidev polling GetStatus (bench/preload_poll.py) when it is installed.
# Usage: bench/coverage_bench.sh [BUILD_DIR] [ROUNDS]   (a Release build is best)
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
rounds=${2:-5}
client=$build/bench/l6470emu_preload_roundtrips
preload=$build/libl6470emu-preload.so
python_client=$(cd "$(dirname "$0")" && pwd)/preload_poll.py
for f in "$client" "$preload"; do
  [ -e "$f" ] || { echo "coverage_bench: $f is missing; build the l6470emu_benchmarks target" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export L6470EMU_LOG=off

# Prints one run's CPU nanoseconds per round trip (the client times its own loop and prints its
# count; CPU time is what a busy machine disturbs least).
once() {  # once COVERAGE(0|1) CLIENT ARGS...
  local with=$1; shift
  local env=(env L6470EMU_CHAIN="bus=0 cs=0 chips=L6470; time=virtual" LD_PRELOAD="$preload")
  [ "$with" = 1 ] && { rm -f "$work/c.json"; env+=(L6470EMU_COVERAGE="$work/c.json"); }
  "${env[@]}" "$@" | awk '{ printf "%.1f\n", $5 / $1 * 1e9 }'  # CPU ns per round trip
}

measure() {  # measure NAME CLIENT ARGS...
  local name=$1; shift
  local off=1e12 on=1e12 t
  for _ in $(seq "$rounds"); do
    t=$(once 0 "$@"); off=$(awk -v a="$t" -v b="$off" 'BEGIN { print (a < b ? a : b) }')
    t=$(once 1 "$@"); on=$(awk -v a="$t" -v b="$on" 'BEGIN { print (a < b ? a : b) }')
  done
  awk -v n="$name" -v a="$off" -v b="$on" 'BEGIN { printf "%-40s %12.1f %12.1f %8.3fx\n", n, a, b, b / a }'
}

echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) (before the runs); best of $rounds alternating runs"
printf '%-40s %12s %12s %9s\n' "client (CPU ns per round trip)" "without" "with" "cost"
measure "C, NOP frames" "$client" /dev/spidev0.0 1000000 nop
measure "C, GetStatus polled" "$client" /dev/spidev0.0 1500000 getstatus
if /usr/bin/python3 -c "import spidev" 2>/dev/null; then
  measure "Python + python3-spidev, GetStatus polled" /usr/bin/python3 "$python_client" /dev/spidev0.0 300000
else
  echo "Python + python3-spidev: not installed, skipped"
fi
echo "goal: cost <= 1.10x"
echo "machine load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
