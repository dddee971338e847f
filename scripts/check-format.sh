#!/usr/bin/env bash
# Fails, naming the files, when a C++ or CUDA source of the tree differs from what clang-format
# makes of it with the root's .clang-format (docs/architecture.md "Style"). Fix: clang-format -i FILE.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.cu' '*.cuh' 2>/dev/null || find framework events broadphase geometry bench plugins tests \( -name '*.cpp' -o -name '*.hpp' -o -name '*.cu' -o -name '*.cuh' \))
clang-format --dry-run -Werror "${files[@]}"
echo "check-format: ${#files[@]} files formatted as .clang-format says"
