#!/usr/bin/env bash
# The test suite built with AddressSanitizer and UndefinedBehaviorSanitizer (CPU only: no CUDA, no
# CGAL cross-checks, no MPI), as CI's second pass: a memory error or undefined behaviour anywhere the
# tests reach fails it. Leak checks are off: plugin libraries and their loader state are kept alive
# on purpose until the process ends (docs/architecture.md "Plugins").
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$here/build-asan}"
"$here/scripts/setup.sh" "$here/build" gem >/dev/null  # installs the packages (and builds gem, cheap once built)
flags="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGEM_DISABLE_CUDA=ON -DGEM_BUILD_CGAL_TESTS=OFF \
  -DGEM_DISABLE_MPI=ON "-DCMAKE_CXX_FLAGS=$flags" "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=address,undefined" \
  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" "-DCMAKE_MODULE_LINKER_FLAGS=-fsanitize=address,undefined" >/dev/null
cmake --build "$build" --parallel "$(nproc)"
cd "$build"
ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 ctest -j"$(nproc)" --output-on-failure --timeout 300
