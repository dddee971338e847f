#!/usr/bin/env bash
# Fuzzes one of GEM's readers of untrusted files with libFuzzer (docs/reliability.md "Fuzzing"):
#   scripts/fuzz.sh TARGET MINUTES        TARGET: scenario | ice | sweep | summary_json | impacts_csv
# Builds the targets with Debian's clang (libFuzzer, AddressSanitizer, UndefinedBehaviorSanitizer)
# in build-fuzz/, starts from the seed corpus tests/fuzz/corpus/TARGET (copied: the corpus the run
# grows stays in build-fuzz/corpus/TARGET), and writes what it finds to build-fuzz/artifacts/TARGET/.
# The last lines of build-fuzz/fuzz-TARGET.log give the executions, the coverage and the crashes.
# A crash input replays without libFuzzer: build-dev/tests/gem_fuzz_replay_TARGET FILE.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
target="${1:-}"
minutes="${2:-}"
case "$target" in scenario|ice|sweep|summary_json|impacts_csv) ;; *)
  echo "usage: scripts/fuzz.sh TARGET MINUTES (TARGET: scenario, ice, sweep, summary_json, impacts_csv)" >&2; exit 2 ;;
esac
[[ "$minutes" =~ ^[0-9]+$ ]] && [ "$minutes" -ge 1 ] || { echo "scripts/fuzz.sh: MINUTES must be a whole number >= 1" >&2; exit 2; }
# The libraries of the normal build come from scripts/setup.sh (run it once first); clang here.
if ! command -v clang++ >/dev/null; then
  echo "scripts/fuzz.sh: installing clang"
  sudo_cmd=""; [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq && $sudo_cmd apt-get install -y -qq --no-install-recommends clang >/dev/null
fi
build="$root/build-fuzz"
flags="-g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fsanitize=fuzzer-no-link -fno-sanitize-recover=undefined"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" -DGEM_FUZZ=ON -DGEM_DISABLE_CUDA=ON -DGEM_BUILD_CGAL_TESTS=OFF >/dev/null
cmake --build "$build" --target "gem_fuzz_$target"
corpus="$build/corpus/$target"
artifacts="$build/artifacts/$target"
mkdir -p "$corpus" "$artifacts"
cp -n "$root/tests/fuzz/corpus/$target/"* "$corpus/" 2>/dev/null || true
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
log="$build/fuzz-$target.log"
echo "fuzzing $target for $minutes min; log: $log"
set +e
"$build/tests/gem_fuzz_$target" -max_total_time=$((minutes * 60)) -timeout=60 -rss_limit_mb=4096 -print_final_stats=1 \
  -artifact_prefix="$artifacts/" "$corpus" > "$log" 2>&1
status=$?
set -e
grep -E "^#[0-9]+.*(DONE|pulse)|stat::number_of_executed_units|stat::peak_rss_mb|cov:|ERROR|SUMMARY" "$log" | tail -6
echo "exit $status; findings in $artifacts: $(ls "$artifacts" | wc -l)"
exit $status
