#!/usr/bin/env bash
# Installs the Debian packages bifilar needs (only those missing), then configures and builds.
# Usage: scripts/setup.sh [BUILD_DIR [TARGET...]]   (default: build, every target)
#   scripts/setup.sh build bifilar      # the program alone (what scripts/run_sample.sh needs)
# Extra CMake options: BIFILAR_CMAKE_ARGS="-DBIFILAR_WERROR=ON -DBIFILAR_DATA_DIR=..." (split on
# spaces; scripts/test.sh uses it).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
shift || true
targets=()
for t in "$@"; do targets+=(--target "$t"); done
packages=(cmake g++ make pkg-config libeigen3-dev libsundials-dev libceres-dev libnlopt-cxx-dev
          libyaml-cpp-dev libcli11-dev libplplot-dev plplot-driver-cairo libfast-float-dev
          nlohmann-json3-dev zlib1g-dev libgtest-dev libgmock-dev libbenchmark-dev libre2-dev
          pybind11-dev python3-dev python3-numpy python3-pytest
          liburdfdom-dev libsdformat-dev libmujoco-dev
          python3-pip python3-setuptools python3-wheel python3-venv
          libcpp-httplib-dev libasio-dev libwebsocketpp-dev libboost-dev libboost-math-dev
          mypy clang-format)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
read -r -a extra <<< "${BIFILAR_CMAKE_ARGS:-}"
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release "${extra[@]}" >/dev/null
cmake --build "$build" -j"$(nproc)" "${targets[@]}"
