#!/usr/bin/env bash
# The README's two commands (docs/guide/install.md):
#   scripts/quickstart.sh demo   set up (Debian packages, build) and run the demo
#   scripts/quickstart.sh test   set up and run the whole test suite (gcc), build the documentation
#                                site and open it in headless Chromium, then the suite again under
#                                ASan+UBSan (clang), then a bounded fuzz pass of every input parser
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-}
case "$what" in
  demo)
    # An unmodified Python program (Debian's python3-spidev and python3-libgpiod) drives three
    # emulated L6470s through /dev/spidev0.0 and /dev/gpiochip0, provided by the preload library:
    # the only target the demo builds (the test command builds the rest).
    BUILD_TARGETS=l6470emu-preload scripts/setup.sh build
    L6470EMU_CHAIN="bus=0 cs=0 chips=3xL6470" LD_PRELOAD="$PWD/build/libl6470emu-preload.so" \
      exec /usr/bin/python3 scripts/demo_preload.py "${@:2}"
    ;;
  test)
    # Each stage prints how long it took, and the whole run its total (the goal: 15 minutes on a
    # quiet 2-core machine; CI stops at 90).
    started=$SECONDS
    stage() {
      local name=$1 t=$SECONDS
      shift
      echo "== $name =="
      "$@"
      echo "== $name: $((SECONDS - t)) s (total $((SECONDS - started)) s) =="
    }
    # The library at -O2 with line tables (-g1: backtraces name files and lines; -g's full debug
    # information adds a third to the build), the tests' own code at -O0 (their time is spent in
    # the library), and each test program run in shards (tests/CMakeLists.txt: the same tests,
    # without a process per test). Every skipped test is listed with its reason after each run.
    release_flags="-O2 -g1 -DNDEBUG"
    stage "set up and build (RelWithDebInfo)" scripts/setup.sh build -DL6470EMU_TEST_SHARDS=ON \
      -DL6470EMU_TEST_CODE_OPTIONS=-O0 "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$release_flags" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$release_flags"
    # One more test at a time than CPUs: a good part of the suite waits on the host's clock (the
    # VM's single CPU, moves in wall time, daemons coming up), and with only one test per CPU a
    # third of the CPU time went unused (2 cores: 122 s at -j2, 96 s at -j3, 92 s at -j4).
    tests() {
      local dir=$1
      shift
      ctest --test-dir "$dir" --output-on-failure -j"$(($(nproc) + 1))" "$@"
      scripts/ctest_skips.sh "$dir"
    }
    # With them, the documentation site (docs/build_site.py: Sphinx, warnings as errors, every
    # internal link checked), then opened in headless Chromium: ctest's `docs` test
    # (tests/docs/docs_test.py); the package test waits for it and checks the site in the .deb.
    stage "tests and the documentation site (RelWithDebInfo)" tests build
    # The headline figures, so that a regression shows in every run's log. Numbers only: no
    # pass/fail on timing (machines are noisy; --no-verdicts leaves out "met" / "NOT MET");
    # bench/compare.sh REV compares two revisions side by side. About 30 s of CPU to build
    # (the model's libraries at -O3, ccache when present) and 2 s to run.
    headline() {
      local launcher=()
      command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
      cmake -S . -B build-bench -G Ninja -DCMAKE_BUILD_TYPE=Release -DL6470EMU_TESTS=OFF "${launcher[@]}" >/dev/null
      cmake --build build-bench -j"$(nproc)" --target l6470emu_bench >/dev/null
      echo "commit $(git rev-parse --short HEAD 2>/dev/null || echo '?'), load average $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) CPUs"
      build-bench/bench/l6470emu_bench --no-verdicts 0.1
    }
    stage "headline benchmark (Release, 0.1 s per figure, printed only)" headline
    # The sanitized tree is built by clang (the normal one by gcc): the whole project builds with
    # both compilers at no extra stage, and clang's UBSan also checks float-to-integer overflow.
    # One tree serves the tests and the fuzzers: its libraries carry libFuzzer's coverage
    # (L6470EMU_FUZZ) and the harnesses are built beside the tests. Debug (-O0, line tables), but
    # the chip model's core at -O1 (CMakeLists.txt); linked by lld, four times faster than ld.bfd
    # at these programs with their sanitizer runtimes.
    stage "build with AddressSanitizer + UndefinedBehaviorSanitizer (clang), tests and fuzzers" \
      scripts/setup.sh build-asan -DL6470EMU_SANITIZE=ON -DL6470EMU_FUZZ=ON -DL6470EMU_TEST_SHARDS=ON \
      -DCMAKE_BUILD_TYPE=Debug -DL6470EMU_BENCH=OFF -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
      -DCMAKE_CXX_FLAGS_DEBUG=-gline-tables-only -DCMAKE_C_FLAGS_DEBUG=-gline-tables-only \
      -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_MODULE_LINKER_FLAGS=-fuse-ld=lld
    sanitized_tests() {
      # The VM's kernel and initramfs do not depend on the tree: the ones the first tree's VM test
      # made serve here too (tests/vm/build-vm.sh checks their stamp and rebuilds when stale).
      if [ -f build/vm/stamp ] && [ ! -e build-asan/vm ]; then cp -a build/vm build-asan/vm; fi
      ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
        tests build-asan -LE '^docs$'  # the site: built once, above
    }
    stage "tests under AddressSanitizer + UndefinedBehaviorSanitizer" sanitized_tests
    stage "bounded fuzz pass (libFuzzer + ASan/UBSan, every harness 12 s, $(nproc) at a time)" \
      env L6470EMU_FUZZ_TREE=build-asan scripts/fuzz.sh 12
    ;;
  *)
    echo "usage: scripts/quickstart.sh demo|test" >&2
    exit 2
    ;;
esac
