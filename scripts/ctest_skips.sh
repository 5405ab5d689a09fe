#!/usr/bin/env bash
# Prints every test the last ctest run in BUILD_DIR skipped, with the reason it gave: the
# GoogleTest tests that called GTEST_SKIP (inside a shard, ctest reports the shard as passed) and
# the ctest tests that exited with their skip status (they print "SKIPPED: reason").
# Usage: scripts/ctest_skips.sh BUILD_DIR   (exit 0; 2 when BUILD_DIR holds no ctest log)
set -euo pipefail
log=${1:?usage: scripts/ctest_skips.sh BUILD_DIR}/Testing/Temporary/LastTest.log
if [ ! -f "$log" ]; then
  echo "ctest_skips: no ctest log in $1 (run ctest there first)" >&2
  exit 2
fi
awk '
  # A ctest test starts with "N/M Testing: NAME" and its output ends with "<end of output>".
  /^[0-9]+\/[0-9]+ Testing: / { test = $0; sub(/^[0-9]+\/[0-9]+ Testing: /, "", test); reason = ""; in_skip = 0; next }
  /^\[ RUN      \] / { running = $4; in_skip = 0; reason = ""; next }
  /: Skipped$/ { in_skip = 1; reason = ""; next }
  /^\[  SKIPPED \] / {
    name = $4
    if (name != running) next  # the summary at the end of a program lists them again
    running = ""
    printf "  %s (%s): %s\n", name, test, (reason == "" ? "no reason given" : reason); n++
    in_skip = 0; reason = ""; next
  }
  /^SKIPPED: / { r = $0; sub(/^SKIPPED: /, "", r); printf "  %s: %s\n", test, r; n++; next }
  in_skip { reason = (reason == "" ? $0 : reason " " $0); next }
  END { if (n) printf "%d skipped, with their reasons above\n", n; else print "no test skipped" }
' "$log"
