#!/usr/bin/env bash
# A bounded fuzz pass: sets up (Debian packages and a clang build in build-fuzz, through
# scripts/setup.sh; or, with L6470EMU_FUZZ_TREE=DIR, the harnesses of a tree configured with
# -DL6470EMU_FUZZ=ON, as the test command's sanitized tree is), replays tests/fuzz/regressions/<harness>/ (inputs that once crashed),
# then runs every libFuzzer harness of tests/fuzz for SECONDS_PER_HARNESS seconds (default 60), as
# many at a time as there are cores (L6470EMU_FUZZ_JOBS),
# from its seed corpus tests/fuzz/corpus/<harness>/, new inputs going to a scratch directory.
# Prints each harness's executions, coverage and time. Exits non-zero when any input crashed,
# hung or ran out of memory; that input is kept in tests/fuzz/regressions/<harness>/.
# Usage: scripts/fuzz.sh [SECONDS_PER_HARNESS]
# The pass is seeded (L6470EMU_FUZZ_SEED, default 1) so that CI explores the same mutations on the
# same code: a new finding comes with a change, not with the luck of a run. Set another seed (or 0,
# libFuzzer's random one) for longer local runs.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:-60}
harnesses=(spi_chain native saleae sigrok umockdev ftrace config protocol sketch ctl_reply scenario coverage)
build=${L6470EMU_FUZZ_TREE:-build-fuzz}

if [ -n "${L6470EMU_FUZZ_TREE:-}" ]; then
  if ! grep -q '^L6470EMU_FUZZ:BOOL=ON$' "$build/CMakeCache.txt" 2>/dev/null; then
    echo "fuzz: L6470EMU_FUZZ_TREE=$build is not a build tree configured with -DL6470EMU_FUZZ=ON" >&2
    exit 2
  fi
  echo "== fuzz: the harnesses of $build"
  cmake --build "$build" -j"$(nproc)" --target fuzz
else
  echo "== fuzz: setting up $build (clang, libFuzzer, ASan + UBSan)"
  CC=clang CXX=clang++ scripts/setup.sh "$build" -DL6470EMU_FUZZ=ON -DL6470EMU_TESTS=OFF -DL6470EMU_BENCH=OFF \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g"
fi

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
logs=$build/fuzz-logs
scratch=$build/fuzz-scratch
mkdir -p "$logs"
failed=()

# 1. Inputs that crashed before must not crash now.
for h in "${harnesses[@]}"; do
  dir=tests/fuzz/regressions/$h
  [ -d "$dir" ] || continue
  inputs=("$dir"/*)
  [ -e "${inputs[0]}" ] || continue
  if "$build/tests/fuzz/fuzz_$h" -runs=1 "${inputs[@]}" >"$logs/$h.regressions.log" 2>&1; then
    echo "== fuzz: $h: ${#inputs[@]} regression inputs replayed clean"
  else
    echo "== fuzz: $h: a regression input fails again (log: $logs/$h.regressions.log):"
    grep -E "ERROR|INVARIANT|runtime error|SUMMARY|Running:" "$logs/$h.regressions.log" | tail -8 || true
    failed+=("$h (regression)")
  fi
done

# 2. The bounded pass: as many harnesses at a time as there are cores (L6470EMU_FUZZ_JOBS), each
# for SECONDS_PER_HARNESS; the rows are printed in the harnesses' order once all have run.
fuzz_one() {  # fuzz_one HARNESS: writes $logs/HARNESS.row (the table row) and .rc (its exit status)
  local h=$1 extra=() start rc=0 elapsed execs bytes cov result
  case $h in
    spi_chain) extra=(-max_len=2048) ;;  # long command sequences
    ftrace) extra=(-max_len=4096) ;;     # the seeds are 20 KB; mutants that size are slow
    native) extra=(-dict=tests/fuzz/native.dict) ;;  # the format's words, `repeat` lines and the gzip magic
  esac
  rm -rf "${scratch:?}/$h"
  mkdir -p "$scratch/$h" "tests/fuzz/regressions/$h"
  start=$(date +%s)
  "$build/tests/fuzz/fuzz_$h" -max_total_time="$seconds" -seed="${L6470EMU_FUZZ_SEED:-1}" -timeout=25 -print_final_stats=1 "${extra[@]}" \
    -artifact_prefix="tests/fuzz/regressions/$h/" "$scratch/$h" "tests/fuzz/corpus/$h" >"$logs/$h.log" 2>&1 || rc=$?
  elapsed=$(($(date +%s) - start))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$logs/$h.log" | tail -1)
  bytes=$(sed -n 's/^stat::input_bytes: *//p' "$logs/$h.log" | tail -1)
  cov=$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$logs/$h.log" | tail -1 || true)
  result=ok
  [ "$rc" -ne 0 ] && result="FAILED (exit $rc)"
  {
    printf '%-10s %12s %8s %8s %10s %5ss  %s\n' "$h" "${execs:-?}" "$(echo "$cov" | awk '{print $2}')" \
      "$(echo "$cov" | awk '{print $4}')" "$(awk -v b="${bytes:-0}" 'BEGIN{printf "%.1f", b/1e6}')" "$elapsed" "$result"
    if [ "$rc" -ne 0 ]; then
      grep -E "ERROR|INVARIANT|runtime error|SUMMARY|Test unit written" "$logs/$h.log" | tail -8 | sed 's/^/    /' || true
    fi
  } >"$logs/$h.row"
  echo "$rc" >"$logs/$h.rc"
}
jobs_at_once=${L6470EMU_FUZZ_JOBS:-$(nproc)}
running=0
for h in "${harnesses[@]}"; do
  if [ "$running" -ge "$jobs_at_once" ]; then
    wait -n || true
    running=$((running - 1))
  fi
  fuzz_one "$h" &
  running=$((running + 1))
done
wait
printf '%-10s %12s %8s %8s %10s %6s  %s\n' harness executions cov ft input_MB time result
for h in "${harnesses[@]}"; do
  cat "$logs/$h.row"
  [ "$(cat "$logs/$h.rc" 2>/dev/null || echo 1)" = 0 ] || failed+=("$h")
done

if ((${#failed[@]})); then
  echo "fuzz: FAILED: ${failed[*]} (inputs kept in tests/fuzz/regressions/<harness>/, logs in $logs/)"
  exit 1
fi
echo "fuzz: ${#harnesses[@]} harnesses, no crash"
