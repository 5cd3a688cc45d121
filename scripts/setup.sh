#!/usr/bin/env bash
# Installs what is missing (Debian bookworm packages only; apt is skipped when everything is
# there) and builds linetrack. Idempotent. Usage: scripts/setup.sh [BUILD_DIR [CMAKE_ARGS...]]
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  cmake ninja-build g++ pkg-config
  libvisp-dev visp-images-data
  libopencv-dev libopencv-contrib-dev
  libeigen3-dev
  libaravis-dev libusb-1.0-0-dev aravis-tools
  googletest libgtest-dev
  libcli11-dev nlohmann-json3-dev libspdlog-dev libyaml-cpp-dev
  ros-core libroscpp-dev librosbag-dev libtf2-ros-dev libtf2-geometry-msgs-dev
  libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libstd-srvs-dev libdiagnostic-msgs-dev
  libimage-transport-dev libcv-bridge-dev libdiagnostic-updater-dev
  libassimp-dev
  clang libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  if [[ $(id -u) -ne 0 ]]; then
    echo "setup: run as root (or with sudo) to install packages" >&2
    exit 2
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

build_dir=${1:-build}
shift || true
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build_dir" -j "$(nproc)"
