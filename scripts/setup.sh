#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine for igi: installs the Debian packages igi builds and tests
# with, then configures and builds everything into build/bin/. Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev nlohmann-json3-dev libfmt-dev libspdlog-dev libcli11-dev libtbb-dev
  libopenimageio-dev openimageio-tools libopenexr-dev libassimp-dev
  libopencv-dev libopencv-contrib-dev libceres-dev libembree-dev libraw-dev
  libaravis-dev aravis-tools libusb-1.0-0-dev
  colmap libgtest-dev libgmock-dev
  python3-dev python3-pybind11 pybind11-dev python3-numpy python3-pytest python3-opencv
  python3-matplotlib  # import igi, and the plots of docs/python.md
  chromium  # igi-run report test (headless)
)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${#missing[@]} Debian package(s): ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

BUILD_TYPE="${IGI_BUILD_TYPE:-Release}"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE"
cmake --build build --parallel "$(nproc)"
echo "setup: built $(ls build/bin | wc -l) executable(s) into build/bin/"
