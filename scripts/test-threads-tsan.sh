#!/usr/bin/env bash
# The tests of the CPU stepper's threads (the pool, the phases split over ranges, the kept lists'
# parallel build, the pair events over contact ranges) built with ThreadSanitizer, as CI's third
# pass: a data race in any of them fails it (docs/reliability.md). Only gem_tests is built, and
# only the threaded tests run: the rest of the suite is single-threaded and the ASan pass has it.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$here/build-tsan}"
"$here/scripts/setup.sh" "$here/build" gem >/dev/null  # installs the packages (and builds gem, cheap once built)
flags="-fsanitize=thread -fno-omit-frame-pointer"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGEM_DISABLE_CUDA=ON -DGEM_BUILD_CGAL_TESTS=OFF \
  -DGEM_DISABLE_MPI=ON "-DCMAKE_CXX_FLAGS=$flags" "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=thread" \
  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread" "-DCMAKE_MODULE_LINKER_FLAGS=-fsanitize=thread" >/dev/null
cmake --build "$build" --parallel "$(nproc)" --target gem_tests
# halt_on_error: the first race ends the run with a failing status.
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" "$build/tests/gem_tests" \
  --gtest_filter='Threads.*:ThreadPool.*:Broadphase.KeptList*'
