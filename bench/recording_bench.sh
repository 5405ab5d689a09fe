#!/usr/bin/env bash
# What recording costs (issues 25 and 34): the same virtual-time run unrecorded, recorded into a
# plain trace and into a .trace.gz, side by side in alternating runs, for a C client (one-byte NOP
# messages: bench/preload_roundtrips.c; its trace is a few repeat lines) and a polling Python
# client (python3-spidev: a Move, then 100 000 polls of GetStatus and GetParam(ABS_POS), one
# xfer2 call per byte as most drivers do; the position changes, so the trace is mostly frames)
# under the preload, and a firmware program (bench/recording_poll: an Arduino sketch polling two
# daisy-chained L6470s with GetStatus for 57 s of virtual time, a few repeat lines of 999 999
# repetitions; L6470EMU_TRACE as for any firmware program). Prints each run's
# CPU time (user + system, to the microsecond, best of RUNS), the time per frame and the ratio recorded/unrecorded
# (goal: at most 1.25), then the .gz recording's size against `gzip -6` of the plain one
# (goal: at most 1.2x). With valgrind installed it then counts the instructions per frame of
# each client unrecorded and recorded (cachegrind, startup subtracted): the same on every run and
# under any load, where CPU time also carries what the code's placement does to the caches (a
# tight C loop moved 1.1x to 1.4x by it before the message path was placed side by side: README,
# § Performance). L6470EMU_BENCH_NO_VALGRIND=1 skips the counts.
# Usage: bench/recording_bench.sh [BUILD_DIR] [RUNS]
set -euo pipefail
build=${1:-build}
runs=${2:-3}
build=$(cd "$build" && pwd)
client=$build/bench/l6470emu_preload_roundtrips
preload=$build/libl6470emu-preload.so
firmware=$build/bench/l6470emu_recording_poll
python=/usr/bin/python3
for f in "$client" "$preload" "$firmware"; do
  [ -e "$f" ] || { echo "recording_bench: $f is missing; build the l6470emu_benchmarks target" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
chain="bus=0 cs=0 chips=L6470 mode=3; time=virtual"
c_frames=2000000
py_polls=100000
cat >"$work/poll.py" <<'EOF'
import sys
import spidev
s = spidev.SpiDev(); s.open(0, 0); s.mode = 3
x = lambda *bs: [s.xfer2([b])[0] for b in bs]
x(0x41, 0x01, 0x00, 0x00)  # Move forward 65536 microsteps: the polls see it run
for _ in range(int(sys.argv[1])):
    x(0xD0, 0, 0)
    x(0x21, 0, 0, 0)  # GetParam(ABS_POS): a new position in most polls, so few repeat lines
EOF

# cpu_seconds OUT_TRACE COMMAND...: user+system seconds of one run (OUT_TRACE "" = unrecorded),
# from the kernel's accounting of the child to the microsecond (wait4), not /usr/bin/time's 10 ms.
cpu_seconds() {
  local trace=$1; shift
  rm -f "$trace"
  local env=(L6470EMU_CHAIN="$chain" LD_PRELOAD="$preload")
  [ "$1" = "$firmware" ] && env=()  # a firmware program: its own board, no preload
  [ -n "$trace" ] && env+=(L6470EMU_TRACE="$trace")
  "$python" - "${env[@]}" -- "$@" <<'PY'
import os, sys
args = sys.argv[1:]
cut = args.index("--")
env = dict(os.environ, **dict(a.split("=", 1) for a in args[:cut]))
env.pop("L6470EMU_BENCH_NO_VALGRIND", None)  # the benchmark's own switch: the preload would warn of it
null = os.open(os.devnull, os.O_WRONLY)
pid = os.fork()
if pid == 0:
    os.dup2(null, 1)
    os.execvpe(args[cut + 1], args[cut + 1:], env)
_, status, usage = os.wait4(pid, 0)
if status != 0:
    sys.exit(f"recording_bench: {' '.join(args[cut + 1:])} failed (status {status})")
print(f"{usage.ru_utime + usage.ru_stime:.6f}")
PY
}

best() { sort -g | head -1; }

# bench NAME FRAMES COMMAND...
bench() {
  local name=$1 frames=$2; shift 2
  local plain=() gz=() none=()
  for ((i = 0; i < runs; ++i)); do
    none+=("$(cpu_seconds "" "$@")")
    plain+=("$(cpu_seconds "$work/$name.trace" "$@")")
    gz+=("$(cpu_seconds "$work/$name.trace.gz" "$@")")
  done
  local n p g
  n=$(printf '%s\n' "${none[@]}" | best)
  p=$(printf '%s\n' "${plain[@]}" | best)
  g=$(printf '%s\n' "${gz[@]}" | best)
  awk -v name="$name" -v f="$frames" -v n="$n" -v p="$p" -v g="$g" 'BEGIN {
    printf "%-28s %9d frames  unrecorded %7.4f s (%6.0f ns/frame)\n", name, f, n, n * 1e9 / f
    printf "%-28s %9s         plain      %7.4f s (%6.0f ns/frame)  ratio %.2f\n", "", "", p, p * 1e9 / f, p / n
    printf "%-28s %9s         .gz        %7.4f s (%6.0f ns/frame)  ratio %.2f\n", "", "", g, g * 1e9 / f, g / n
  }'
  # The .gz against gzip -6 of the plain recording, and of its own text (the same events, but
  # with the closed repeat lines a gzip recording writes at its flush points).
  local plain_size gz_size ref own
  plain_size=$(stat -c %s "$work/$name.trace")
  gz_size=$(stat -c %s "$work/$name.trace.gz")
  ref=$(gzip -6 -c "$work/$name.trace" | wc -c)
  own=$(gzip -dc "$work/$name.trace.gz" | gzip -6 | wc -c)
  awk -v name="$name" -v p="$plain_size" -v g="$gz_size" -v r="$ref" -v o="$own" 'BEGIN {
    printf "%-28s sizes: plain %d B, .gz %d B; gzip -6 of the plain %d B (.gz / it = %.2f), of the .gz'"'"'s own text %d B (.gz / it = %.2f)\n", "", p, g, r, g / r, o, g / o
  }'
}

echo "recording cost, virtual time, best of $runs alternating runs (load: $(cut -d' ' -f1-3 /proc/loadavg))"
bench "C client (NOP messages)" "$c_frames" "$client" /dev/spidev0.0 "$c_frames"
if "$python" -c 'import spidev' 2>/dev/null; then
  bench "Python client (GetStatus)" "$((py_polls * 7 + 4))" "$python" "$work/poll.py" "$py_polls"
else
  echo "Python client: skipped ($python has no spidev module; Debian: python3-spidev)"
fi
# count_frames TRACE: the frames of a plain trace: a frame line is one, a repeat line its group
# times its count (an open line: "repeat K frames every Pus times N"; closed: "repeat K frames N times").
count_frames() {
  awk '
    $2 == "frame" { n += 1 }
    $2 == "repeat" && $5 == "every" { n += $3 * $NF }
    $2 == "repeat" && $5 != "every" { n += $3 * $5 }
    END { print n }' "$1"
}
fw_frames=$(L6470EMU_TRACE="$work/count.trace" "$firmware" >/dev/null && count_frames "$work/count.trace")
bench "Firmware (Arduino GetStatus)" "${fw_frames:-0}" "$firmware"

# instructions NAME FRAMES BASE_ARG FULL_ARG COMMAND... (the frame count argument last): the
# instructions per frame, unrecorded and recorded, each run once with BASE_ARG and once with
# FULL_ARG so that the start-up (Python's own, the board's) drops out.
count_instructions() {
  local trace=$1 arg=$2; shift 2
  rm -f "$trace"
  local env=(L6470EMU_CHAIN="$chain" LD_PRELOAD="$preload")
  [ -n "$trace" ] && env+=(L6470EMU_TRACE="$trace")
  env "${env[@]}" valgrind --tool=cachegrind --cache-sim=no --branch-sim=no --cachegrind-out-file=/dev/null \
    "$@" "$arg" 2>&1 >/dev/null | awk '/I *refs:/ { gsub(",", "", $NF); print $NF }' | tail -1
}
instructions() {
  local name=$1 frames=$2 base=$3 full=$4; shift 4
  local n0 n1 p0 p1
  n0=$(count_instructions "" "$base" "$@")
  n1=$(count_instructions "" "$full" "$@")
  p0=$(count_instructions "$work/i.trace" "$base" "$@")
  p1=$(count_instructions "$work/i.trace" "$full" "$@")
  awk -v name="$name" -v f="$frames" -v n0="$n0" -v n1="$n1" -v p0="$p0" -v p1="$p1" 'BEGIN {
    n = (n1 - n0) / f; p = (p1 - p0) / f
    printf "%-28s %9d frames  unrecorded %7.0f instructions/frame, recorded %7.0f: ratio %.2f\n", name, f, n, p, p / n
  }'
}
if [ -n "${L6470EMU_BENCH_NO_VALGRIND:-}" ]; then
  exit 0
elif ! command -v valgrind >/dev/null; then
  echo "instruction counts: skipped (no valgrind; Debian: valgrind)"
  exit 0
fi
echo "instructions per frame (valgrind cachegrind, start-up subtracted; independent of load):"
instructions "C client (NOP messages)" 100000 0 100000 "$client" /dev/spidev0.0
if "$python" -c 'import spidev' 2>/dev/null; then
  instructions "Python client (GetStatus)" 35000 0 5000 "$python" "$work/poll.py"
fi
# The firmware program stopped at 1 s and at 3 s of virtual time (limit=), its own board otherwise.
fw_count() {
  local trace=$1 limit=$2
  rm -f "$trace"
  local env=(L6470EMU_CHAIN="chips=2xL6470 cs_pin=D10 limit=$limit")
  [ -n "$trace" ] && env+=(L6470EMU_TRACE="$trace")
  env "${env[@]}" valgrind --tool=cachegrind --cache-sim=no --branch-sim=no --cachegrind-out-file=/dev/null \
    "$firmware" 2>&1 >/dev/null | awk '/I *refs:/ { gsub(",", "", $NF); print $NF }' | tail -1
}
fw_n0=$(fw_count "" 1s)
fw_n1=$(fw_count "" 3s)
fw_p0=$(fw_count "$work/f1.trace" 1s)
fw_f0=$(count_frames "$work/f1.trace")
fw_p1=$(fw_count "$work/f3.trace" 3s)
fw_f1=$(count_frames "$work/f3.trace")
fw_g0=$(fw_count "$work/f1.trace.gz" 1s)
fw_g1=$(fw_count "$work/f3.trace.gz" 3s)
awk -v name="Firmware (Arduino GetStatus)" -v f="$((fw_f1 - fw_f0))" -v n0="$fw_n0" -v n1="$fw_n1" -v p0="$fw_p0" \
    -v p1="$fw_p1" -v g0="$fw_g0" -v g1="$fw_g1" 'BEGIN {
  n = (n1 - n0) / f; p = (p1 - p0) / f; g = (g1 - g0) / f
  printf "%-28s %9d frames  unrecorded %7.0f instructions/frame, plain %7.0f: ratio %.2f, .gz %7.0f: ratio %.2f\n", name, f, n, p, p / n, g, g / n
}'
