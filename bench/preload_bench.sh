#!/usr/bin/env bash
# SPI_IOC_MESSAGE round trips per second through libl6470emu-preload.so, in process and through
# `l6470emu serve`, side by side with the same client under umockdev-run (Debian's umockdev)
# replaying the same exchange, reported as ratios. Usage: bench/preload_bench.sh [BUILD_DIR]
# (a Release build is best: cmake -DCMAKE_BUILD_TYPE=Release; the goals are 500 000/s in
# process and 50 000/s through the daemon). Emulator speed is measured in virtual time: on the
# wall clock every message takes its bus time, as on a real bus (printed too, for scale).
set -euo pipefail
build=${1:-build}
build=$(cd "$build" && pwd)
client=$build/bench/l6470emu_preload_roundtrips
preload=$build/libl6470emu-preload.so
emu=$build/l6470emu
for f in "$client" "$preload" "$emu"; do
  [ -x "$f" ] || [ -f "$f" ] || { echo "preload_bench: $f is missing; build the l6470emu_benchmarks target" >&2; exit 1; }
done
work=$(mktemp -d)
daemon_pid=
cleanup() {
  [ -n "$daemon_pid" ] && kill "$daemon_pid" 2>/dev/null && wait "$daemon_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

in_process_n=2000000
daemon_n=300000
umockdev_n=20000

run() {  # prints the best of three runs' round trips per wall-clock second (the last argument is N)
  # Timed from outside: under time=virtual the client's own clock is the board's.
  local best=0 r t0 t1 n=${*: -1}
  for _ in 1 2 3; do
    t0=$(date +%s.%N)
    "$@" >/dev/null
    t1=$(date +%s.%N)
    r=$(awk -v n="$n" -v a="$t0" -v b="$t1" 'BEGIN { printf "%.0f", n / (b - a) }')
    [ "$r" -gt "$best" ] && best=$r
  done
  echo "$best"
}

export L6470EMU_LOG=off
in_process=$(L6470EMU_CHAIN="bus=0 cs=0 chips=L6470; time=virtual" LD_PRELOAD=$preload run "$client" /dev/spidev0.0 $in_process_n)
wall=$(L6470EMU_CHAIN="bus=0 cs=0 chips=L6470" LD_PRELOAD=$preload run "$client" /dev/spidev0.0 200000)

"$emu" serve --chain "bus=0 cs=0 chips=L6470" --virtual-time --socket "$work/emu.sock" --log off >"$work/serve.log" 2>&1 &
daemon_pid=$!
for _ in $(seq 100); do grep -q "listening" "$work/serve.log" 2>/dev/null && break; sleep 0.05; done
daemon=$(L6470EMU_SOCKET=$work/emu.sock LD_PRELOAD=$preload run "$client" /dev/spidev0.0 $daemon_n)

umockdev="n/a"
if command -v umockdev-run >/dev/null; then
  cat >"$work/spidev.umockdev" <<'DEV'
P: /devices/platform/l6470emu/spi_master/spi0/spi0.0/spidev/spidev0.0
N: spidev0.0
E: DEVNAME=/dev/spidev0.0
E: MAJOR=153
E: MINOR=0
E: SUBSYSTEM=spidev
A: dev=153:0
DEV
  { echo "@DEV /dev/spidev0.0 (SPI)"; for _ in $(seq $umockdev_n); do printf 'TW 00\n R 00\n'; done; } >"$work/replay.ioctl"
  # umockdev replays the recording once per run, so each run gets a fresh umockdev-run.
  umockdev=$(run umockdev-run -d "$work/spidev.umockdev" -i "/dev/spidev0.0=$work/replay.ioctl" -- \
    "$client" /dev/spidev0.0 $umockdev_n)
fi

printf '%-44s %14s %12s %10s\n' "SPI_IOC_MESSAGE(1) round trips" "per second" "goal" "x umockdev"
ratio() { [ "$umockdev" = "n/a" ] && echo "n/a" || awk -v a="$1" -v b="$umockdev" 'BEGIN { printf "%.0fx", a / b }'; }
printf '%-44s %14.0f %12s %10s\n' "preload, emulator in process (virtual time)" "$in_process" ">= 500000" "$(ratio "$in_process")"
printf '%-44s %14.0f %12s %10s\n' "preload -> serve --virtual-time (Unix socket)" "$daemon" ">= 50000" "$(ratio "$daemon")"
printf '%-44s %14.0f %12s %10s\n' "preload, in process, wall clock (bus-bound)" "$wall" "-" "$(ratio "$wall")"
if [ "$umockdev" = "n/a" ]; then
  printf '%-44s %14s\n' "umockdev-run replay (umockdev not installed)" "n/a"
else
  printf '%-44s %14.0f %12s %10s\n' "umockdev-run replaying the same exchange" "$umockdev" "-" "1x"
fi
