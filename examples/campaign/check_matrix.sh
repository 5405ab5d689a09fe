#!/bin/sh
# Runs the example's campaign and compares each rerun's verdict with expected.txt
# ("FAULT POINT VERDICT" lines). Usage: check_matrix.sh L6470EMU DRIVER EXPECTED PYTHON
set -u
l6470emu=$1 driver=$2 expected=$3 python=$4
dir=$(mktemp -d) || exit 2
trap 'rm -rf "$dir"' EXIT
"$l6470emu" campaign --chain chips=L6470 --faults ocd,thermal_warning,thermal_bridge_shutdown,uvlo,sw_close,stby_pulse \
  --json "$dir/campaign.json" -- "$driver" >"$dir/out.txt" 2>&1
status=$?
cat "$dir/out.txt"
# Silent failures are in the matrix: the campaign says so with its status.
[ "$status" -eq 1 ] || { echo "campaign exit $status, expected 1"; exit 1; }
"$python" -c '
import json, sys
report = json.load(open(sys.argv[1]))
seen = ["%s %s %s" % (r["fault"], r["point"]["name"], r["verdict"]) for r in report["reruns"]]
want = [l.strip() for l in open(sys.argv[2]) if l.strip() and not l.startswith("#")]
if seen != want:
    print("the matrix differs from expected.txt:")
    for line in sorted(set(seen) ^ set(want)): print(("  seen " if line in seen else "  want ") + line)
    sys.exit(1)
print("matrix as expected: %d reruns" % len(seen))
' "$dir/campaign.json" "$expected"
