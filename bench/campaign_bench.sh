#!/usr/bin/env bash
# What a fault campaign costs (issue 32): `l6470emu campaign` of a C driver and of a Python
# driver (python3-spidev) of about 10 s of virtual time each (bench/campaign_workload.c, .py),
# every fault at every point of the default phases, -j (the number of CPUs). Prints the clean
# run's wall time, the campaign's wall time, its reruns per second and the speed-up over
# running the same reruns as plain `l6470emu run`s of their scenarios one after another
# (reruns x clean run's time / jobs). Numbers only, no verdict (goals: C >= 200 reruns/s,
# Python >= 100 reruns/s on 2 cores). Usage: bench/campaign_bench.sh [BUILD_DIR] [RUNS]
set -euo pipefail
build=${1:-build}
runs=${2:-3}
build=$(cd "$build" && pwd)
l6470emu=$build/l6470emu
driver=$build/bench/l6470emu_campaign_workload
here=$(cd "$(dirname "$0")" && pwd)
for f in "$l6470emu" "$driver"; do
  [ -e "$f" ] || { echo "campaign_bench: $f is missing; build the l6470emu_benchmarks target" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
jobs=$(nproc)
now() { date +%s.%N; }
echo "commit $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo '?'), load average $(cut -d' ' -f1-3 /proc/loadavg) on $jobs CPUs"
bench() {
  local name=$1
  shift
  local best_clean=999 best=999 reruns=0 t0 t1
  for ((i = 0; i < runs; ++i)); do
    t0=$(now)
    "$l6470emu" run --chain "chips=L6470" -- "$@" >/dev/null 2>&1
    t1=$(now)
    best_clean=$(echo "$t1 - $t0" | bc -l | awk -v b="$best_clean" '{print ($1 < b ? $1 : b)}')
    t0=$(now)
    "$l6470emu" campaign --chain "chips=L6470" -j "$jobs" --json "$work/c.json" -- "$@" >/dev/null 2>&1 || true
    t1=$(now)
    best=$(echo "$t1 - $t0" | bc -l | awk -v b="$best" '{print ($1 < b ? $1 : b)}')
    reruns=$(/usr/bin/python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["reruns"]))' "$work/c.json")
  done
  awk -v n="$name" -v c="$best_clean" -v t="$best" -v r="$reruns" -v j="$jobs" 'BEGIN {
    printf "%-22s clean run %7.3f s   campaign %7.3f s for %d reruns: %7.1f reruns/s, %.2fx plain reruns (%d at a time)\n",
           n, c, t, r, r / t, (r * c / j) / t, j }'
}
bench "C driver" "$driver"
bench "Python driver" /usr/bin/python3 "$here/campaign_workload.py"
