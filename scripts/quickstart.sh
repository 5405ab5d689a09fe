#!/usr/bin/env bash
# The README's two commands:
#   scripts/quickstart.sh demo   set up (Debian packages, build) and run the demo
#   scripts/quickstart.sh test   set up and run the whole test suite, then again under ASan+UBSan,
#                                then a bounded fuzz pass of every input parser
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-}
case "$what" in
  demo)
    # An unmodified Python program (Debian's python3-spidev and python3-libgpiod) drives three
    # emulated L6470s through /dev/spidev0.0 and /dev/gpiochip0, provided by the preload library.
    scripts/setup.sh build
    L6470EMU_CHAIN="bus=0 cs=0 chips=3xL6470" LD_PRELOAD="$PWD/build/libl6470emu-preload.so" \
      exec /usr/bin/python3 scripts/demo_preload.py "${@:2}"
    ;;
  test)
    # Each stage prints how long it took, and the whole run its total (CI's budget: 45 minutes).
    started=$SECONDS
    stage() {
      local name=$1 t=$SECONDS
      shift
      echo "== $name =="
      "$@"
      echo "== $name: $((SECONDS - t)) s (total $((SECONDS - started)) s) =="
    }
    stage "set up and build (RelWithDebInfo)" scripts/setup.sh build
    stage "tests (RelWithDebInfo)" ctest --test-dir build --output-on-failure -j"$(nproc)"
    stage "build with AddressSanitizer + UndefinedBehaviorSanitizer" \
      scripts/setup.sh build-asan -DL6470EMU_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug
    stage "tests under AddressSanitizer + UndefinedBehaviorSanitizer" env \
      ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      ctest --test-dir build-asan --output-on-failure -j"$(nproc)"
    stage "bounded fuzz pass (libFuzzer + ASan/UBSan, 10 harnesses x 45 s)" scripts/fuzz.sh 45
    ;;
  *)
    echo "usage: scripts/quickstart.sh demo|test" >&2
    exit 2
    ;;
esac
