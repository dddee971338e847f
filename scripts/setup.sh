#!/usr/bin/env bash
# Installs what GEM needs from Debian's packages (only what is missing) and configures + builds it.
# Usage: scripts/setup.sh [BUILD_DIR [TARGET ...]]   (default: build, every target)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${1:-$here/build}"
shift || true
targets=("$@")

# chromium and libcairo2-dev: tests/viewer_test.cpp opens gem view's page in headless chromium and
# reads its screenshots with Cairo.
packages=(cmake ninja-build g++ pkg-config libeigen3-dev libboost-dev libboost-filesystem-dev
          libtomlplusplus-dev libfmt-dev libcgal-dev libgmp-dev libmpfr-dev libgtest-dev libgmock-dev
          libcli11-dev libpugixml-dev nlohmann-json3-dev zlib1g-dev libopenmpi-dev openmpi-bin clang-format
          chromium libcairo2-dev ffmpeg fonts-dejavu-core)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "gem setup: installing ${missing[*]}"
  sudo_cmd=""; [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

cuda_args=()
if [ -x /usr/local/cuda/bin/nvcc ] && [ "${GEM_CUDA:-auto}" != "off" ]; then
  cuda_args=(-DCMAKE_CUDA_COMPILER=/usr/local/cuda/bin/nvcc)
fi
cmake -S "$here" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${cuda_args[@]}" >/dev/null
if ((${#targets[@]})); then
  cmake --build "$build_dir" --parallel "$(nproc)" --target "${targets[@]}"
else
  cmake --build "$build_dir" --parallel "$(nproc)"
fi
