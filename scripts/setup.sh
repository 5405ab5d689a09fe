#!/usr/bin/env bash
# Installs the Debian packages the project needs (only the missing ones, with one
# `apt-get update` first) and builds the project. Usage: scripts/setup.sh [BUILD_DIR [CMAKE_ARGS...]]
# BUILD_TARGETS="a b" builds only those targets (the demo needs the preload library alone).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build pkg-config
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libfmt-dev nlohmann-json3-dev
  zlib1g-dev gcc python3 python3-spidev python3-libgpiod gpiod libgpiod-dev umockdev
  sigrok-cli clang libclang-rt-14-dev lld
  python3-dev pybind11-dev python3-pybind11 python3-pytest python3-pytest-xdist python3-numpy python3-matplotlib help2man man-db dpkg-dev lintian
  libfuse3-dev qemu-system-x86 busybox-static cpio kmod
  libyaml-cpp-dev spi-tools golang-go
  lcov
  python3-sphinx python3-myst-parser python3-breathe doxygen chromium chromium-driver python3-selenium
  libjs-dygraphs
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing missing Debian packages: ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -q
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

build_dir=${1:-build}
shift || true
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null
targets=()
for t in ${BUILD_TARGETS:-}; do targets+=(--target "$t"); done
cmake --build "$build_dir" -j"$(nproc)" "${targets[@]}"
