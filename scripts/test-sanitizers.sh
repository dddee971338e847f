#!/usr/bin/env bash
# The test suite built with sanitizers (CPU only: no CUDA, no CGAL cross-checks, no MPI), as CI's
# later passes (docs/reliability.md):
#   scripts/test-sanitizers.sh [address [BUILD_DIR]]  AddressSanitizer and UndefinedBehaviorSanitizer
#     over the whole suite: a memory error or undefined behaviour anywhere the tests reach fails it.
#     Leak checks are off: plugin libraries and their loader state are kept alive on purpose until
#     the process ends (docs/architecture.md "Plugins").
#   scripts/test-sanitizers.sh thread [BUILD_DIR]     ThreadSanitizer over the tests of the CPU
#     stepper's threads (the pool, the phases over ranges, the kept lists' parallel build, the pair
#     events over contact ranges); only gem_tests is built: the rest of the suite is single-threaded.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mode="${1:-address}"
case "$mode" in
  address) sanitizers="address,undefined"; extra="-fno-sanitize-recover=undefined" ;;
  thread) sanitizers="thread"; extra="" ;;
  *) echo "usage: $0 [address|thread] [BUILD_DIR]" >&2; exit 2 ;;
esac
build="${2:-$here/build-$([ "$mode" = address ] && echo asan || echo tsan)}"
"$here/scripts/setup.sh" "$here/build" gem >/dev/null  # installs the packages (and builds gem, cheap once built)
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGEM_DISABLE_CUDA=ON -DGEM_BUILD_CGAL_TESTS=OFF \
  -DGEM_DISABLE_MPI=ON "-DCMAKE_CXX_FLAGS=-fsanitize=$sanitizers -fno-omit-frame-pointer $extra" \
  "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=$sanitizers" "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=$sanitizers" \
  "-DCMAKE_MODULE_LINKER_FLAGS=-fsanitize=$sanitizers" >/dev/null
if [ "$mode" = address ]; then
  cmake --build "$build" --parallel "$(nproc)"
  cd "$build"
  ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 ctest -j"$(nproc)" --output-on-failure --timeout 300
else
  cmake --build "$build" --parallel "$(nproc)" --target gem_tests
  # halt_on_error: the first race ends the run with a failing status.
  TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" "$build/tests/gem_tests" --gtest_filter='Threads.*:ThreadPool.*:Broadphase.KeptList*'
fi
