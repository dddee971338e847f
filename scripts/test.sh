#!/usr/bin/env bash
# Installs what is missing, builds GEM with its tests and runs the whole suite (ctest -j2).
# CUDA tests are skipped, visibly, where no GPU exists.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$here/scripts/setup.sh" "$here/build"
cd "$here/build"
ctest -j"$(nproc)" --output-on-failure --timeout 120
