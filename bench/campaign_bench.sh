#!/usr/bin/env bash
# What a fault campaign costs (issue 32): `l6470emu campaign` of a C driver and of a Python
# driver (python3-spidev) of about 10 s of virtual time each (bench/campaign_workload.c, .py),
# every fault at every point of the default phases, -j (the number of CPUs), with snapshots (the
# default: each rerun forked from one more clean run at its injection tick) and without
# (--snapshots no: each rerun a whole `l6470emu run`), in alternating runs. Prints the clean
# run's wall time, each campaign's wall time (best of RUNS), its reruns per second, the speed-up
# over running the same reruns as plain `l6470emu run`s of their scenarios one after another
# (reruns x clean run's time / jobs) and that of snapshots over none. Numbers only, no verdict
# (goals: C >= 200 reruns/s, Python >= 100 reruns/s on 2 cores).
# Usage: bench/campaign_bench.sh [BUILD_DIR] [RUNS]
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
  local best_clean=999 best_yes=999 best_no=999 reruns=0 t0 t1 mode
  for ((i = 0; i < runs; ++i)); do
    t0=$(now)
    "$l6470emu" run --chain "chips=L6470" -- "$@" >/dev/null 2>&1
    t1=$(now)
    best_clean=$(echo "$t1 - $t0" | bc -l | awk -v b="$best_clean" '{print ($1 < b ? $1 : b)}')
    for mode in yes no; do
      rm -f "$work/c.json"
      t0=$(now)
      status=0
      "$l6470emu" campaign --chain "chips=L6470" -j "$jobs" --snapshots "$mode" --json "$work/c.json" -- "$@" >/dev/null 2>"$work/err" || status=$?
      t1=$(now)
      # A campaign that did not run its reruns (status other than 0 or 1, an incomplete report) is no figure.
      if [ "$status" -gt 1 ] || ! /usr/bin/python3 -c 'import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))["complete"] else 1)' "$work/c.json" 2>/dev/null; then
        echo "campaign_bench: $name, snapshots $mode: exit $status, not counted: $(tail -1 "$work/err")" >&2
        continue
      fi
      if [ "$mode" = yes ]; then
        best_yes=$(echo "$t1 - $t0" | bc -l | awk -v b="$best_yes" '{print ($1 < b ? $1 : b)}')
      else
        best_no=$(echo "$t1 - $t0" | bc -l | awk -v b="$best_no" '{print ($1 < b ? $1 : b)}')
      fi
    done
    reruns=$(/usr/bin/python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["reruns"]))' "$work/c.json")
  done
  awk -v n="$name" -v c="$best_clean" -v y="$best_yes" -v t="$best_no" -v r="$reruns" -v j="$jobs" 'BEGIN {
    printf "%-15s clean run %6.3f s; %d reruns, %d at a time:\n", n, c, r, j
    printf "  snapshots     campaign %7.3f s: %7.1f reruns/s, %5.2fx plain reruns\n", y, r / y, (r * c / j) / y
    printf "  no snapshots  campaign %7.3f s: %7.1f reruns/s, %5.2fx plain reruns\n", t, r / t, (r * c / j) / t
    printf "  snapshots are %.2fx faster\n", t / y }'
}
bench "C driver" "$driver"
bench "Python driver" /usr/bin/python3 "$here/campaign_workload.py"
